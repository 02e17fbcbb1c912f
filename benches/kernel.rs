//! Criterion benchmark of the river kernel: the CPU reference (single thread and rayon) and, when a Vulkan device
//! is present, the simple and tiled GPU kernels (end to end), all on the same synthetic patches. For the
//! like-for-like comparison on the planet's own patches use `riverplanet bench kernel`.

use criterion::{criterion_group, criterion_main, Criterion};
use riverplanet::{
    gpu::{bindless::Bindless, Context, ContextOptions},
    kernel::{
        cpu,
        gpu::{run_batch, KernelTuning, KernelVariant, RiverKernel},
        workload, KernelParams, PatchJob,
    },
};

fn kernel(c: &mut Criterion) {
    let params = KernelParams {
        influence_distance: 20.0,
        basin_depth: 0.1,
        sea_level: 0.4,
        basin_water_offset: 0.001,
        sample_floor: 0.25,
    };
    let n = 33;
    let patches: Vec<_> = (0..6u32)
        .flat_map(|lod| {
            workload::random_patches(lod as u64, 4, n, 64.0 / (1 << lod) as f32, &params)
        })
        .collect();
    let jobs: Vec<PatchJob> = PatchJob::from_pairs(&patches);
    let mut group = c.benchmark_group("river kernel");
    group.sample_size(10);
    group.bench_function("cpu single thread", |b| {
        b.iter(|| cpu::compute_patches(&jobs, n, &params))
    });
    group.bench_function("cpu rayon", |b| {
        b.iter(|| cpu::compute_patches_rayon(&jobs, n, &params))
    });
    let mut options = ContextOptions::from_env();
    options.validation = false;
    match Context::new(&options) {
        Ok(ctx) => {
            let mut bindless = Bindless::new(&ctx, jobs.len() as u32 + 16).expect("bindless set");
            let kernel = RiverKernel::new(&ctx, &bindless, n, KernelTuning::for_device(&ctx))
                .expect("kernel");
            for (name, variant) in [
                ("gpu simple end to end", KernelVariant::Simple),
                ("gpu tiled end to end", KernelVariant::Tiled),
            ] {
                group.bench_function(name, |b| {
                    b.iter(|| {
                        run_batch(&ctx, &mut bindless, &kernel, variant, &jobs, &params)
                            .expect("dispatch")
                    })
                });
            }
        }
        Err(e) => eprintln!("no Vulkan device, GPU kernels not measured: {e}"),
    }
    group.finish();
}

criterion_group!(benches, kernel);
criterion_main!(benches);
