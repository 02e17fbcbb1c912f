//! `riverplanet bench kernel`: the kernel variants on identical input (Tables 9.1 and 9.2). The input is what a
//! camera descending to the default planet produces: every patch that becomes visible during the scripted flight
//! and is influenced by a river, with its samples, computed as one batch.

use std::{collections::HashSet, time::Instant};

use glam::DVec3;
use serde::Serialize;

use super::{median, path::Flight, Threads};
use crate::{
    gpu::{bindless::Bindless, Context, GpuError},
    kernel::{
        cpu, diff_by_output,
        gpu::{run_batch_into, BatchOutputs, KernelTuning, KernelVariant, RiverKernel},
        KernelParams, OutputDiff, PatchJob, RiverSample, RiverTexel,
    },
    planet::cube::PatchId,
    river::samples::{patch_samples, PatchFrame, PatchSamples},
    runtime::{
        cull::{visible_quadrants, Frustum, HeightRange},
        lod::{select, LodParams, Selected},
    },
    world::World,
};

/// Kernel time of one variant: median over repetitions, and for the GPU the end-to-end time too.
#[derive(Clone, Debug, Serialize)]
pub struct VariantTiming {
    /// The median of `runs_ms`.
    pub kernel_ms: f64,
    /// GPU only: the median with the upload, the read-back and its decoding (docs/kernel.md).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_to_end_ms: Option<f64>,
    /// Every repetition's time (the GPU's from timestamp queries).
    pub runs_ms: Vec<f64>,
}

/// The four ways the kernel runs: the CPU reference on one thread and on rayon's, the simple and the tiled GPU
/// kernel (6.6-6.7).
#[derive(Clone, Debug, Serialize)]
pub struct Variants {
    /// The CPU reference on one thread.
    pub cpu_single: VariantTiming,
    /// The CPU reference on rayon's threads.
    pub cpu_rayon: VariantTiming,
    /// The simple GPU kernel.
    pub gpu_simple: VariantTiming,
    /// The tiled GPU kernel.
    pub gpu_tiled: VariantTiming,
}

/// Per-output differences of each GPU variant to the CPU reference (the worst over the repetitions).
#[derive(Clone, Debug, Default, Serialize)]
pub struct DiffsByVariant {
    /// The simple kernel's, one per output.
    pub gpu_simple: Vec<OutputDiff>,
    /// The tiled kernel's, one per output.
    pub gpu_tiled: Vec<OutputDiff>,
}

impl DiffsByVariant {
    /// The largest difference of any output and variant.
    pub fn max(&self) -> f32 {
        self.gpu_simple
            .iter()
            .chain(&self.gpu_tiled)
            .map(|d| d.max_abs_diff)
            .fold(0.0, f32::max)
    }
}

/// The variants' times against each other.
#[derive(Clone, Debug, Serialize)]
pub struct Ratios {
    /// GPU tiled kernel time / GPU simple kernel time (the thesis: 0.82 in Table 9.1, 0.68 in Table 9.2).
    pub tiled_over_simple: f64,
    /// CPU single-threaded time / GPU tiled end-to-end time (how much faster the GPU path is).
    pub cpu_single_over_gpu_tiled_end_to_end: f64,
    /// CPU single-threaded time / GPU tiled kernel time.
    pub cpu_single_over_gpu_tiled_kernel: f64,
    /// CPU single-threaded time / CPU multi-threaded time.
    pub cpu_single_over_cpu_rayon: f64,
}

/// What `bench kernel` writes: the workload, the GPU variants' differences to the CPU reference, and every
/// variant's time.
#[derive(Clone, Debug, Serialize)]
pub struct KernelReport {
    /// The Vulkan device's name and its driver's name and version.
    pub device: String,
    /// See `device`.
    pub driver: String,
    /// The workload in words.
    pub workload: String,
    /// Whether the flight was the thesis's stress test (switch factor x10, camera x25).
    pub stress: bool,
    /// The planet's seed.
    pub seed: u32,
    /// Frames of the scripted flight whose river patches make the workload.
    pub flight_frames: u32,
    /// River patches in the workload, and their river samples in all.
    pub patches: usize,
    /// See `patches`.
    pub samples: usize,
    /// Vertex-sample pairs the procedures visit.
    pub pairs: u64,
    /// Pairs within the influence distance: the ones Procedure 3 does real work for.
    pub relevant_pairs: u64,
    /// The lowest and highest terrain height the CPU reference computed.
    pub height_range: [f32; 2],
    /// The largest difference of any GPU output to the CPU reference.
    pub max_abs_diff: f32,
    /// `max_abs_diff` relative to the height range.
    pub relative_diff: f32,
    /// The largest difference to the CPU reference per output and GPU variant, with where it is.
    pub max_abs_diff_by_output: DiffsByVariant,
    /// Runs of each variant.
    pub repetitions: usize,
    /// The GPU kernels' workgroup shapes and tile size.
    pub tuning: KernelTuning,
    /// The thread counts it ran with.
    pub threads: Threads,
    /// Each variant's time.
    pub variants: Variants,
    /// The times against each other.
    pub ratios: Ratios,
}

/// The patches and samples a scripted flight produces: every visible patch that a river influences, once, in
/// the order the flight meets them. `stress` uses the thesis's stress settings (switch factor x10, camera x25).
pub fn flight_workload(world: &World, stress: bool, frames: u32) -> Vec<(f32, Vec<RiverSample>)> {
    let flight = Flight::new(world, frames, if stress { 25.0 } else { 1.0 }, 16.0 / 9.0);
    let n = world.config.rendering.vertices;
    let params = lod_params(world, if stress { 10.0 } else { 1.0 });
    flight_patches(world, &flight, frames, &|camera| select(camera, &params))
        .into_iter()
        .map(|(patch, s)| {
            let spacing = PatchFrame::new(patch, world.planet.radius, n).spacing() as f32;
            (spacing, s.samples)
        })
        .collect()
}

/// The level-of-detail parameters of `world`, with the switch factor scaled by `switch_scale`.
pub fn lod_params(world: &World, switch_scale: f64) -> LodParams {
    let rendering = &world.config.rendering;
    LodParams::distance(
        world.planet.radius,
        rendering.level_of_detail_switch_factor as f64 * switch_scale,
        rendering.max_level_of_detail,
    )
}

/// Every visible patch of `flight`'s first `frames` frames that a river influences, once, in the order the
/// flight meets them; `select` picks the patches for a camera position.
pub fn flight_patches(
    world: &World,
    flight: &Flight,
    frames: u32,
    select: &dyn Fn(DVec3) -> Vec<Selected>,
) -> Vec<(PatchId, PatchSamples)> {
    let config = &world.config;
    let n = config.rendering.vertices;
    let radius = world.planet.radius;
    let heights = HeightRange {
        min: world.planet.stats.min_height as f64 - 1.0,
        max: world.planet.stats.max_height as f64 + config.river.basin_depth as f64 + 1.0,
    };
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for frame in 0..frames {
        let camera = flight.camera(world, frame);
        let frustum = Frustum::from_matrix(camera.clip());
        for s in select(camera.position) {
            if visible_quadrants(&s, camera.position, &frustum, radius, heights).is_none() {
                continue;
            }
            if !seen.insert(s.patch) {
                continue;
            }
            let samples = patch_samples(&world.network, &PatchFrame::new(s.patch, radius, n));
            if !samples.samples.is_empty() {
                out.push((s.patch, samples));
            }
        }
    }
    out
}

fn count_relevant_pairs(jobs: &[PatchJob], n: u32, params: &KernelParams) -> u64 {
    jobs.iter()
        .map(|job| {
            (0..n * n)
                .map(|k| {
                    let v = crate::kernel::vertex_position(k % n, k / n, job.spacing);
                    job.samples
                        .iter()
                        .filter(|s| cpu::calculate_height_by_sample(v, s, params).is_some())
                        .count() as u64
                })
                .sum::<u64>()
        })
        .sum()
}

/// Runs the four variants on the same jobs; keeps its GPU pipelines and output textures between measurements.
pub struct VariantRunner {
    bindless: Bindless,
    kernel: RiverKernel,
    outputs: BatchOutputs,
}

impl VariantRunner {
    /// A runner for batches of up to `capacity` patches of `n x n` vertices.
    pub fn new(
        ctx: &Context,
        capacity: usize,
        n: u32,
        tuning: KernelTuning,
    ) -> Result<Self, GpuError> {
        let mut bindless = Bindless::new(ctx, capacity as u32 + 16)?;
        let kernel = RiverKernel::new(ctx, &bindless, n, tuning)?;
        let outputs = BatchOutputs::new(ctx, &mut bindless, capacity, n)?;
        Ok(Self {
            bindless,
            kernel,
            outputs,
        })
    }

    /// Times CPU single-thread, CPU rayon, GPU simple and GPU tiled; `repetitions` runs each (after one warm-up
    /// run for the GPU). Returns the timings, the CPU reference output, and the differences to it.
    pub fn measure(
        &mut self,
        ctx: &Context,
        jobs: &[PatchJob],
        params: &KernelParams,
        repetitions: usize,
        warm_up: bool,
    ) -> Result<(Variants, Vec<Vec<RiverTexel>>, DiffsByVariant), GpuError> {
        let n = self.kernel.grid_size;
        let repetitions = repetitions.max(1);
        let time = |f: &mut dyn FnMut()| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64() * 1e3
        };
        let mut reference = Vec::new();
        let cpu_single: Vec<f64> = (0..repetitions)
            .map(|_| time(&mut || reference = cpu::compute_patches(jobs, n, params)))
            .collect();
        let cpu_rayon: Vec<f64> = (0..repetitions)
            .map(|_| time(&mut || drop(cpu::compute_patches_rayon(jobs, n, params))))
            .collect();
        let gpu = |variant, diffs: &mut Vec<OutputDiff>| -> Result<VariantTiming, GpuError> {
            let run = || {
                let (bindless, outputs) = (&self.bindless, &self.outputs);
                run_batch_into(
                    ctx,
                    bindless,
                    &self.kernel,
                    variant,
                    jobs,
                    (&[], &[]),
                    params,
                    outputs,
                )
            };
            if warm_up {
                run()?;
            }
            let (mut kernel_ms, mut end_to_end) = (Vec::new(), Vec::new());
            for _ in 0..repetitions {
                let t = Instant::now();
                let result = run()?;
                end_to_end.push(t.elapsed().as_secs_f64() * 1e3);
                kernel_ms.push(result.timings.iter().map(|s| s.ms).sum());
                let these = diff_by_output(&reference, &result.texels, n);
                if diffs.is_empty() {
                    *diffs = these;
                } else {
                    for (worst, d) in diffs.iter_mut().zip(these) {
                        if d.max_abs_diff > worst.max_abs_diff {
                            *worst = d;
                        }
                    }
                }
            }
            Ok(VariantTiming {
                kernel_ms: median(&kernel_ms),
                end_to_end_ms: Some(median(&end_to_end)),
                runs_ms: kernel_ms,
            })
        };
        let mut diffs = DiffsByVariant::default();
        let gpu_simple = gpu(KernelVariant::Simple, &mut diffs.gpu_simple)?;
        let gpu_tiled = gpu(KernelVariant::Tiled, &mut diffs.gpu_tiled)?;
        let cpu = |runs: Vec<f64>| VariantTiming {
            kernel_ms: median(&runs),
            end_to_end_ms: None,
            runs_ms: runs,
        };
        let variants = Variants {
            cpu_single: cpu(cpu_single),
            cpu_rayon: cpu(cpu_rayon),
            gpu_simple,
            gpu_tiled,
        };
        Ok((variants, reference, diffs))
    }
}

/// `riverplanet bench kernel`.
pub fn kernel_bench(
    ctx: &Context,
    world: &World,
    stress: bool,
    frames: u32,
    repetitions: usize,
    tuning: KernelTuning,
) -> Result<KernelReport, GpuError> {
    let params = KernelParams::from_config(&world.config);
    let n = world.config.rendering.vertices;
    let patches = flight_workload(world, stress, frames);
    let jobs: Vec<PatchJob> = PatchJob::from_pairs(&patches);
    let mut runner = VariantRunner::new(ctx, jobs.len(), n, tuning)?;
    let measured = runner.measure(ctx, &jobs, &params, repetitions, true);
    let (variants, reference, diffs) = measured?;
    let max_abs_diff = diffs.max();
    let heights = reference.iter().flatten().map(|t| t.terrain_height);
    let height_range = heights.fold([f32::MAX, f32::MIN], |[lo, hi], h| [lo.min(h), hi.max(h)]);
    let ratios = Ratios {
        tiled_over_simple: variants.gpu_tiled.kernel_ms / variants.gpu_simple.kernel_ms,
        cpu_single_over_gpu_tiled_end_to_end: variants.cpu_single.kernel_ms
            / variants.gpu_tiled.end_to_end_ms.unwrap_or(f64::NAN),
        cpu_single_over_gpu_tiled_kernel: variants.cpu_single.kernel_ms
            / variants.gpu_tiled.kernel_ms,
        cpu_single_over_cpu_rayon: variants.cpu_single.kernel_ms / variants.cpu_rayon.kernel_ms,
    };
    Ok(KernelReport {
        device: ctx.adapter.name.clone(),
        driver: format!("{} {}", ctx.adapter.driver_name, ctx.adapter.driver_info),
        workload: format!(
            "every river patch met by the scripted flight ({frames} frames{}) over seed {}",
            if stress {
                ", stress: switch factor x10, camera x25"
            } else {
                ""
            },
            world.seed
        ),
        stress,
        seed: world.seed,
        flight_frames: frames,
        patches: jobs.len(),
        samples: jobs.iter().map(|j| j.samples.len()).sum(),
        pairs: jobs
            .iter()
            .map(|j| j.samples.len() as u64 * (n * n) as u64)
            .sum(),
        relevant_pairs: count_relevant_pairs(&jobs, n, &params),
        height_range,
        max_abs_diff,
        relative_diff: max_abs_diff / (height_range[1] - height_range[0]).max(1e-6),
        max_abs_diff_by_output: diffs,
        repetitions,
        tuning,
        threads: Threads::current(),
        variants,
        ratios,
    })
}
