//! Benchmarks that compare the kernel variants in one run on identical input (Section 9.2, Tables 9.1 and 9.2).
//! On lavapipe the "GPU" is the CPU: only ratios measured in the same run mean anything, so every report
//! records the device, `LP_NUM_THREADS`, `RAYON_NUM_THREADS` and the threads rayon actually used.

use std::time::Instant;

use serde::Serialize;

use crate::{
    config::Config,
    gpu::{bindless::Bindless, Context, GpuError},
    kernel::{
        cpu,
        gpu::{run_batch, KernelTuning, KernelVariant, RiverKernel},
        workload, KernelParams, PatchJob, RiverTexel,
    },
};

/// Kernel time of one variant: median over repetitions, and for the GPU the end-to-end time too.
#[derive(Clone, Debug, Serialize)]
pub struct VariantTiming {
    pub kernel_ms: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub end_to_end_ms: Option<f64>,
    pub runs_ms: Vec<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Variants {
    pub cpu_single: VariantTiming,
    pub cpu_rayon: VariantTiming,
    pub gpu_simple: VariantTiming,
    pub gpu_tiled: VariantTiming,
}

#[derive(Clone, Debug, Serialize)]
pub struct Ratios {
    /// GPU tiled kernel time / GPU simple kernel time (the thesis: 0.82 in Table 9.1, 0.68 in Table 9.2).
    pub tiled_over_simple: f64,
    /// CPU single-threaded time / GPU tiled end-to-end time (how much faster the GPU path is).
    pub cpu_single_over_gpu_tiled_end_to_end: f64,
    /// CPU single-threaded time / GPU tiled kernel time.
    pub cpu_single_over_gpu_tiled_kernel: f64,
    pub cpu_single_over_cpu_rayon: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct Threads {
    pub lp_num_threads: Option<String>,
    pub rayon_num_threads: Option<String>,
    pub rayon_threads_used: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct KernelReport {
    pub device: String,
    pub driver: String,
    pub workload: String,
    pub stress: bool,
    pub patches: usize,
    pub samples: usize,
    pub pairs: u64,
    /// Pairs within the influence distance: the ones Procedure 3 does real work for.
    pub relevant_pairs: u64,
    pub height_range: [f32; 2],
    pub max_abs_diff: f32,
    pub repetitions: usize,
    pub tuning: KernelTuning,
    pub threads: Threads,
    pub variants: Variants,
    pub ratios: Ratios,
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    if n == 0 {
        0.0
    } else if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

fn timing(mut runs: Vec<f64>, end_to_end: Option<Vec<f64>>) -> VariantTiming {
    let kernel_ms = median(&mut runs.clone());
    runs.shrink_to_fit();
    VariantTiming {
        kernel_ms,
        end_to_end_ms: end_to_end.map(|mut e| median(&mut e)),
        runs_ms: runs,
    }
}

fn max_abs_diff(a: &[Vec<RiverTexel>], b: &[Vec<RiverTexel>]) -> f32 {
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| {
            [
                (x.terrain_height - y.terrain_height).abs(),
                (x.lerp_factor - y.lerp_factor).abs(),
                (x.water_height - y.water_height).abs(),
                (x.min_distance - y.min_distance).abs(),
                (x.river_width - y.river_width).abs(),
            ]
            .into_iter()
            .fold(0.0f32, f32::max)
        })
        .fold(0.0, f32::max)
}

/// The synthetic kernel workload: patches at the levels of detail a camera descending to the surface selects
/// (Eq. 6.1 spacing per level), each crossed by random rivers. `stress` multiplies the patch count by the
/// thesis's stress factor (switch factor x10 refines about ten times the area per level).
pub fn kernel_workload(
    config: &Config,
    stress: bool,
    seed: u64,
) -> Vec<(f32, Vec<crate::kernel::RiverSample>)> {
    let params = KernelParams::from_config(config);
    let n = config.rendering.vertices;
    let face = 2.0 * config.planet.radius;
    let per_level = if stress { 40 } else { 4 };
    let mut patches = Vec::new();
    for lod in 0..=config.rendering.max_level_of_detail {
        let spacing = face / ((n - 1) as f32 * (1u32 << lod) as f32);
        patches.extend(workload::random_patches(
            seed ^ lod as u64,
            per_level,
            n,
            spacing,
            &params,
        ));
    }
    patches
}

fn count_relevant_pairs(jobs: &[PatchJob], n: u32, params: &KernelParams) -> u64 {
    jobs.iter()
        .map(|job| {
            let mut count = 0u64;
            for k in 0..n * n {
                let v = crate::kernel::vertex_position(k % n, k / n, job.spacing);
                count += job
                    .samples
                    .iter()
                    .filter(|s| cpu::calculate_height_by_sample(v, s, params).is_some())
                    .count() as u64;
            }
            count
        })
        .sum()
}

/// Times CPU single-thread, CPU rayon, GPU simple and GPU tiled on identical input.
pub fn kernel_bench(
    ctx: &Context,
    config: &Config,
    stress: bool,
    repetitions: usize,
    tuning: KernelTuning,
) -> Result<KernelReport, GpuError> {
    let params = KernelParams::from_config(config);
    let n = config.rendering.vertices;
    let patches = kernel_workload(config, stress, 1);
    let jobs: Vec<PatchJob> = patches
        .iter()
        .map(|(s, v)| PatchJob {
            spacing: *s,
            samples: v,
        })
        .collect();
    let samples: usize = jobs.iter().map(|j| j.samples.len()).sum();
    let pairs: u64 = jobs
        .iter()
        .map(|j| j.samples.len() as u64 * (n * n) as u64)
        .sum();
    let repetitions = repetitions.max(1);
    let relevant_pairs = count_relevant_pairs(&jobs, n, &params);

    let time = |f: &mut dyn FnMut()| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64() * 1e3
    };
    let mut reference = Vec::new();
    let cpu_single: Vec<f64> = (0..repetitions)
        .map(|_| time(&mut || reference = cpu::compute_patches(&jobs, n, &params)))
        .collect();
    let cpu_rayon: Vec<f64> = (0..repetitions)
        .map(|_| time(&mut || drop(cpu::compute_patches_rayon(&jobs, n, &params))))
        .collect();

    let mut bindless = Bindless::new(ctx, jobs.len() as u32 + 16)?;
    let kernel = RiverKernel::new(ctx, &bindless, n, tuning)?;
    let mut max_diff = 0.0f32;
    let mut gpu = |variant| -> Result<VariantTiming, GpuError> {
        run_batch(ctx, &mut bindless, &kernel, variant, &jobs, &params)?; // warm-up
        let mut kernel_ms = Vec::new();
        let mut end_to_end = Vec::new();
        for _ in 0..repetitions {
            let t = Instant::now();
            let result = run_batch(ctx, &mut bindless, &kernel, variant, &jobs, &params)?;
            end_to_end.push(t.elapsed().as_secs_f64() * 1e3);
            kernel_ms.push(result.timings.iter().map(|s| s.ms).sum());
            max_diff = max_diff.max(max_abs_diff(&reference, &result.texels));
        }
        Ok(timing(kernel_ms, Some(end_to_end)))
    };
    let gpu_simple = gpu(KernelVariant::Simple)?;
    let gpu_tiled = gpu(KernelVariant::Tiled)?;
    kernel.destroy(ctx);
    ctx.wait_idle()?;
    bindless.destroy(ctx);

    let heights = reference.iter().flatten().map(|t| t.terrain_height);
    let height_range = heights.fold([f32::MAX, f32::MIN], |[lo, hi], h| [lo.min(h), hi.max(h)]);
    let variants = Variants {
        cpu_single: timing(cpu_single, None),
        cpu_rayon: timing(cpu_rayon, None),
        gpu_simple,
        gpu_tiled,
    };
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
        workload: "synthetic: random Hermite rivers on patches of every level of detail".into(),
        stress,
        patches: jobs.len(),
        samples,
        pairs,
        relevant_pairs,
        height_range,
        max_abs_diff: max_diff,
        repetitions,
        tuning,
        threads: Threads {
            lp_num_threads: std::env::var("LP_NUM_THREADS").ok(),
            rayon_num_threads: std::env::var("RAYON_NUM_THREADS").ok(),
            rayon_threads_used: rayon::current_num_threads(),
        },
        variants,
        ratios,
    })
}
