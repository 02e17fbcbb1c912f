//! `riverplanet bench kernel --parent-reuse`: river data taken from the parent patch (10.2) against every patch
//! computed from scratch, on identical input: the patches of the descent to the ground whose parents already
//! have the rivers' final detail (the only ones whose even vertices the parent holds).

use std::{collections::HashMap, time::Instant};

use serde::Serialize;

use super::{
    kernel::{flight_patches, lod_params},
    median,
    path::Flight,
    Threads,
};
use crate::{
    gpu::{bindless::Bindless, Context, GpuError},
    kernel::{
        cpu,
        gpu::{run_batch_into, BatchOutputs, KernelTuning, KernelVariant, RiverKernel},
        max_abs_diff, KernelParams, ParentQuadrant, PatchJob, RiverTexel,
    },
    planet::cube::PatchId,
    river::samples::{patch_samples, PatchFrame, PatchSamples},
    runtime::lod::{select_nearest, surface_bounds},
    world::World,
};

/// Kernel times (median over repetitions) of one way of computing the batch.
#[derive(Clone, Debug, Serialize)]
pub struct ReuseTiming {
    /// The CPU reference on one thread.
    pub cpu_single_ms: f64,
    /// The simple GPU kernel (timestamp queries).
    pub gpu_simple_ms: f64,
    /// The tiled GPU kernel (timestamp queries).
    pub gpu_tiled_ms: f64,
    /// Vertices the kernel computes (the rest are copied).
    pub computed_vertices: u64,
}

/// What `bench kernel --parent-reuse` writes.
#[derive(Clone, Debug, Serialize)]
pub struct ReuseReport {
    /// The Vulkan device's name and its driver's name and version.
    pub device: String,
    /// See `device`.
    pub driver: String,
    /// The workload in words.
    pub workload: String,
    /// The planet's seed.
    pub seed: u32,
    /// Frames of the descent whose patches make the workload.
    pub flight_frames: u32,
    /// Child patches in the batch, and the parents they take data from.
    pub patches: usize,
    /// See `patches`.
    pub parents: usize,
    /// River samples given to the kernel for the batch.
    pub samples: usize,
    /// Largest difference of any output between taking data from the parent and computing from scratch (CPU
    /// reference from scratch against the CPU and both GPU kernels with reuse).
    pub max_abs_diff: f32,
    /// Runs of each way and variant.
    pub repetitions: usize,
    /// The GPU kernels' workgroup shapes and tile size.
    pub tuning: KernelTuning,
    /// The thread counts it ran with.
    pub threads: Threads,
    /// Every patch computed from its samples.
    pub from_scratch: ReuseTiming,
    /// The even vertices copied from the parent, the rest computed.
    pub from_parent: ReuseTiming,
    /// From scratch / from the parent, per variant (above 1: reuse is faster).
    pub speedup: [f64; 3],
}

/// The kernel's job for `patch`.
fn job(patch: PatchId, samples: &PatchSamples, radius: f64, n: u32) -> PatchJob<'_> {
    PatchJob {
        spacing: PatchFrame::new(patch, radius, n).spacing() as f32,
        samples: &samples.samples,
    }
}

/// Runs the comparison over the first `frames` frames of the descent.
pub fn reuse_bench(
    ctx: &Context,
    world: &World,
    frames: u32,
    repetitions: usize,
    tuning: KernelTuning,
) -> Result<ReuseReport, GpuError> {
    let n = world.config.rendering.vertices;
    let radius = world.planet.radius;
    let params = KernelParams::from_config(&world.config);
    let flight = Flight::descent(world, frames, 16.0 / 9.0).ok_or_else(|| {
        GpuError::Invalid("the descent needs a river, and this planet has none".into())
    })?;
    // Children whose parent has the final detail, and those parents (each once).
    let mut parents = Vec::new();
    let mut parent_index: HashMap<PatchId, Option<usize>> = HashMap::new();
    let mut children = Vec::new();
    // The renderer's selection (nearest point of each patch), bounded by the planet's precomputed heights.
    let lod = lod_params(world, 1.0);
    let basin = world.config.river.basin_depth as f64;
    let bounds = |p| surface_bounds(&world.planet, basin, p, None);
    let select = |camera| select_nearest(camera, &lod, &bounds);
    for (patch, samples) in flight_patches(world, &flight, frames, &select) {
        let (Some(parent), Some(quadrant)) = (patch.parent(), ParentQuadrant::of(patch, n)) else {
            continue;
        };
        let index = *parent_index.entry(parent).or_insert_with(|| {
            let s = patch_samples(&world.network, &PatchFrame::new(parent, radius, n));
            s.final_detail.then(|| {
                parents.push((parent, s));
                parents.len() - 1
            })
        });
        if let Some(index) = index {
            children.push((patch, samples, index, quadrant));
        }
    }
    if children.is_empty() {
        return Err(GpuError::Invalid(format!(
            "no patch of the descent's first {frames} frames has a parent with the rivers' final detail; \
             use a deeper planet (config/earth.xml) or more --frames"
        )));
    }
    let parent_jobs: Vec<PatchJob> = parents.iter().map(|(p, s)| job(*p, s, radius, n)).collect();
    let child_jobs: Vec<PatchJob> = children
        .iter()
        .map(|(p, s, ..)| job(*p, s, radius, n))
        .collect();
    let repetitions = repetitions.max(1);
    let time = |f: &mut dyn FnMut()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64() * 1e3
    };

    let parent_cpu = cpu::compute_patches(&parent_jobs, n, &params);
    let mut scratch = Vec::new();
    let cpu_scratch: Vec<f64> = (0..repetitions)
        .map(|_| time(&mut || scratch = cpu::compute_patches(&child_jobs, n, &params)))
        .collect();
    let mut reused: Vec<Vec<RiverTexel>> = Vec::new();
    let cpu_reuse: Vec<f64> = (0..repetitions)
        .map(|_| {
            time(&mut || {
                reused = child_jobs
                    .iter()
                    .zip(&children)
                    .map(|(j, (_, _, k, q))| {
                        cpu::compute_patch_from_parent(j, &parent_cpu[*k], *q, n, &params)
                    })
                    .collect()
            })
        })
        .collect();
    let mut max_diff = max_abs_diff(&scratch, &reused);

    let mut bindless = Bindless::new(ctx, (parents.len() + children.len()) as u32 + 16)?;
    let outputs = RiverKernel::new(ctx, &bindless, n, tuning).and_then(|kernel| {
        let parent_out = BatchOutputs::new(ctx, &mut bindless, parents.len(), n)?;
        let child_out = BatchOutputs::new(ctx, &mut bindless, children.len(), n)?;
        Ok((kernel, parent_out, child_out))
    });
    let (kernel, parent_out, child_out) = outputs?;
    let inherit: Vec<_> = children
        .iter()
        .map(|(_, _, k, q)| Some((parent_out.places()[*k], *q)))
        .collect();
    let inherited = parent_out.parent_textures(&inherit);
    let mut gpu = |variant, from_parent: bool| -> Result<f64, GpuError> {
        let parents = match from_parent {
            true => (&inherit[..], &inherited[..]),
            false => (&[][..], &[][..]),
        };
        let run = || {
            run_batch_into(
                ctx,
                &bindless,
                &kernel,
                variant,
                &child_jobs,
                parents,
                &params,
                &child_out,
            )
        };
        run()?;
        let mut runs = Vec::new();
        for _ in 0..repetitions {
            let result = run()?;
            runs.push(result.timings.iter().map(|s| s.ms).sum());
            max_diff = max_diff.max(max_abs_diff(&scratch, &result.texels));
        }
        Ok(median(&runs))
    };
    let measured = run_batch_into(
        ctx,
        &bindless,
        &kernel,
        KernelVariant::Tiled,
        &parent_jobs,
        (&[], &[]),
        &params,
        &parent_out,
    )
    .and_then(|_| {
        Ok([
            gpu(KernelVariant::Simple, false)?,
            gpu(KernelVariant::Simple, true)?,
            gpu(KernelVariant::Tiled, false)?,
            gpu(KernelVariant::Tiled, true)?,
        ])
    });
    let [simple_scratch, simple_reuse, tiled_scratch, tiled_reuse] = measured?;

    let vertices = (n * n) as u64 * children.len() as u64;
    let copied = (n.div_ceil(2) * n.div_ceil(2)) as u64 * children.len() as u64;
    let from_scratch = ReuseTiming {
        cpu_single_ms: median(&cpu_scratch),
        gpu_simple_ms: simple_scratch,
        gpu_tiled_ms: tiled_scratch,
        computed_vertices: vertices,
    };
    let from_parent = ReuseTiming {
        cpu_single_ms: median(&cpu_reuse),
        gpu_simple_ms: simple_reuse,
        gpu_tiled_ms: tiled_reuse,
        computed_vertices: vertices - copied,
    };
    Ok(ReuseReport {
        device: ctx.adapter.name.clone(),
        driver: format!("{} {}", ctx.adapter.driver_name, ctx.adapter.driver_info),
        workload: format!(
            "the patches of the descent to the ground ({frames} frames, seed {}) whose parents have the rivers' \
             final detail",
            world.seed
        ),
        seed: world.seed,
        flight_frames: frames,
        patches: children.len(),
        parents: parents.len(),
        samples: child_jobs.iter().map(|j| j.samples.len()).sum(),
        max_abs_diff: max_diff,
        repetitions,
        tuning,
        threads: Threads::current(),
        speedup: [
            from_scratch.cpu_single_ms / from_parent.cpu_single_ms,
            from_scratch.gpu_simple_ms / from_parent.gpu_simple_ms,
            from_scratch.gpu_tiled_ms / from_parent.gpu_tiled_ms,
        ],
        from_scratch,
        from_parent,
    })
}

impl ReuseReport {
    /// The table the command prints.
    pub fn summary(&self) -> String {
        let t = &self.threads;
        let mut out = format!(
            "device {} | {} patches from {} parents, {} samples | LP_NUM_THREADS {}, RAYON_NUM_THREADS {}\n",
            self.device,
            self.patches,
            self.parents,
            self.samples,
            t.lp_num_threads.as_deref().unwrap_or("unset"),
            t.rayon_num_threads.as_deref().unwrap_or("unset"),
        );
        out += &format!(
            "  {:<12} {:>14} {:>14} {:>8}\n",
            "kernel ms", "from scratch", "from parent", "speedup"
        );
        let (a, b) = (&self.from_scratch, &self.from_parent);
        for (name, x, y, r) in [
            (
                "cpu single",
                a.cpu_single_ms,
                b.cpu_single_ms,
                self.speedup[0],
            ),
            (
                "gpu simple",
                a.gpu_simple_ms,
                b.gpu_simple_ms,
                self.speedup[1],
            ),
            ("gpu tiled", a.gpu_tiled_ms, b.gpu_tiled_ms, self.speedup[2]),
        ] {
            out += &format!("  {name:<12} {x:>14.3} {y:>14.3} {r:>7.2}x\n");
        }
        out += &format!(
            "  vertices computed: {} from scratch, {} from the parent | max difference {:e}\n",
            a.computed_vertices, b.computed_vertices, self.max_abs_diff
        );
        out
    }
}
