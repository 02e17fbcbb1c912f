//! The river kernel: the CPU reference against the procedures' defined behaviour, and both GPU kernels against
//! the CPU reference on random patches and on the special vertices (on a sample, on the basin border, no samples).

mod common;

use riverplanet::{
    gpu::bindless::Bindless,
    kernel::{
        cpu,
        gpu::{run_batch, KernelTuning, KernelVariant, RiverKernel},
        max_abs_diff, workload, KernelParams, PatchJob, RiverSample, RiverTexel,
    },
};

const N: u32 = 33;

fn params() -> KernelParams {
    KernelParams {
        influence_distance: 20.0,
        basin_depth: 0.1,
        sea_level: 0.4,
        basin_water_offset: 0.001,
    }
}

/// A straight river along +x at y = 16 with width 4, height 5, sampled every 1/6 of its width.
fn straight_river() -> Vec<RiverSample> {
    (0..=192)
        .map(|k| RiverSample::new([k as f32 / 6.0, 16.0], [1.0, 0.0], 5.0, 4.0))
        .collect()
}

#[test]
fn vertex_on_the_river_centre_gets_the_river_height() {
    let t = cpu::calculate_height([10.0, 16.0], &straight_river(), &params());
    assert!((t.terrain_height - 5.0).abs() < 1e-5, "{t:?}");
    assert_eq!(t.lerp_factor, 0.0);
    assert!(
        t.water_height > t.terrain_height,
        "water covers the river bed: {t:?}"
    );
    assert!(t.min_distance.abs() < 1e-6);
}

/// Beyond the thesis: the flow is the samples' direction downstream, at unit length where they agree (a river
/// whose derivative has length 3 flows at unit length too), and it bends with the river.
#[test]
fn the_flow_follows_the_river_downstream() {
    let p = params();
    let t = cpu::calculate_height([10.0, 17.0], &straight_river(), &p);
    assert!(
        (t.flow[0] - 1.0).abs() < 1e-6 && t.flow[1].abs() < 1e-6,
        "{t:?}"
    );
    let fast: Vec<RiverSample> = (0..=192)
        .map(|k| RiverSample::new([16.0, k as f32 / 6.0], [0.0, -3.0], 5.0, 4.0))
        .collect();
    let t = cpu::calculate_height([15.0, 10.0], &fast, &p);
    assert!(
        t.flow[0].abs() < 1e-6 && (t.flow[1] + 1.0).abs() < 1e-6,
        "{t:?}"
    );
    // A right-angle bend: halfway between the two arms the flow points between them.
    let bend: Vec<RiverSample> = straight_river()
        .into_iter()
        .filter(|s| s.position[0] <= 16.0)
        .chain(
            (1..=96).map(|k| RiverSample::new([16.0, 16.0 + k as f32 / 6.0], [0.0, 1.0], 5.0, 4.0)),
        )
        .collect();
    let t = cpu::calculate_height([17.0, 15.0], &bend, &p);
    assert!(t.flow[0] > 0.2 && t.flow[1] > 0.2, "{t:?}");
}

#[test]
fn basin_rises_cubically_to_the_banks() {
    let samples = straight_river();
    let p = params();
    let centre = cpu::calculate_height([10.0, 16.0], &samples, &p).terrain_height;
    let quarter = cpu::calculate_height([10.0, 16.5], &samples, &p).terrain_height;
    let near_bank = cpu::calculate_height([10.0, 17.9], &samples, &p).terrain_height;
    let outside = cpu::calculate_height([10.0, 19.0], &samples, &p);
    assert!(
        centre < quarter && quarter < near_bank,
        "{centre} {quarter} {near_bank}"
    );
    assert!(
        near_bank < outside.terrain_height,
        "banks lie above the basin"
    );
    assert!(
        (outside.terrain_height - (5.0 + 0.1)).abs() < 1e-4,
        "outside: height + basin depth: {outside:?}"
    );
}

#[test]
fn signed_distance_flips_across_the_river() {
    let samples = straight_river();
    let left = cpu::calculate_height([10.0, 18.5], &samples, &params());
    let right = cpu::calculate_height([10.0, 13.5], &samples, &params());
    assert!(
        left.min_distance < 0.0 && right.min_distance > 0.0,
        "{left:?} {right:?}"
    );
}

#[test]
fn lerp_factor_grows_from_bank_to_influence_distance() {
    let samples = straight_river();
    let p = params();
    let mut last = -1.0;
    for y in [19.0f32, 22.0, 26.0, 30.0, 34.0] {
        let t = cpu::calculate_height([10.0, y], &samples, &p);
        assert!(
            t.lerp_factor > last && (0.0..=1.0).contains(&t.lerp_factor),
            "{y}: {t:?}"
        );
        last = t.lerp_factor;
    }
}

#[test]
fn no_relevant_sample_keeps_the_base_terrain() {
    let far = [RiverSample::new([500.0, 500.0], [1.0, 0.0], 5.0, 4.0)];
    let p = params();
    for samples in [&far[..], &[]] {
        let t = cpu::calculate_height([1.0, 1.0], samples, &p);
        assert_eq!(
            t,
            RiverTexel {
                terrain_height: 0.0,
                lerp_factor: 1.0,
                water_height: p.sea_level,
                min_distance: p.influence_distance,
                river_width: 0.0,
                flow: [0.0; 2],
            }
        );
    }
}

#[test]
fn degenerate_derivative_and_border_vertices_stay_finite() {
    let p = params();
    let zero = [RiverSample::new([5.0, 5.0], [0.0, 0.0], 3.0, 2.0)];
    // Exactly on the basin's end along the flow: projection distance = half width, river weight 0.
    let single = [RiverSample::new([5.0, 5.0], [1.0, 0.0], 3.0, 2.0)];
    for (v, s) in [
        ([5.0, 5.0], &zero),
        ([6.0, 5.0], &single),
        ([5.0, 6.0], &single),
        ([5.0, 5.0], &single),
    ] {
        let t = cpu::calculate_height(v, s, &p);
        for x in [
            t.terrain_height,
            t.lerp_factor,
            t.water_height,
            t.min_distance,
            t.river_width,
        ] {
            assert!(x.is_finite(), "{v:?} {t:?}");
        }
    }
}

#[test]
fn rayon_equals_single_threaded() {
    let p = params();
    let patches = workload::random_patches(3, 6, N, 1.0, &p);
    let jobs: Vec<PatchJob> = PatchJob::from_pairs(&patches);
    assert_eq!(
        cpu::compute_patches(&jobs, N, &p),
        cpu::compute_patches_rayon(&jobs, N, &p)
    );
}

#[test]
fn gpu_kernels_equal_the_cpu_reference() {
    let Some(ctx) = common::gpu() else { return };
    let p = params();
    let mut patches = workload::random_patches(11, 40, N, 1.0, &p);
    // Special vertices: a sample exactly on vertex (4, 4); a sample whose basin end falls on vertex (9, 4);
    // a patch with no samples; a patch whose samples are all out of reach.
    patches.push((
        1.0,
        vec![RiverSample::new([4.0, 4.0], [0.0, 1.0], 2.0, 3.0)],
    ));
    patches.push((
        1.0,
        vec![RiverSample::new([8.0, 4.0], [1.0, 0.0], 2.0, 2.0)],
    ));
    patches.push((2.0, vec![]));
    // A sample with a zero derivative (the normal line degenerates to the sample point).
    patches.push((
        1.0,
        vec![RiverSample::new([10.0, 10.0], [0.0, 0.0], 3.0, 4.0)],
    ));
    patches.push((
        0.5,
        vec![RiverSample::new([900.0, 900.0], [1.0, 1.0], 2.0, 2.0)],
    ));
    let jobs: Vec<PatchJob> = PatchJob::from_pairs(&patches);
    let reference = cpu::compute_patches(&jobs, N, &p);
    let range = reference
        .iter()
        .flatten()
        .map(|t| t.terrain_height)
        .fold((f32::MAX, f32::MIN), |(lo, hi), h| (lo.min(h), hi.max(h)));
    let tolerance = 1e-4 * (range.1 - range.0).max(1.0);

    let mut bindless = Bindless::new(ctx, 256).unwrap();
    for tuning in [
        KernelTuning::default(),
        KernelTuning {
            simple_workgroup: 128,
            tiled_block: [8, 4],
            tile_size: 32,
        },
    ] {
        let kernel = RiverKernel::new(ctx, &bindless, N, tuning).unwrap();
        let mut outputs = Vec::new();
        for variant in [KernelVariant::Simple, KernelVariant::Tiled] {
            let gpu = run_batch(ctx, &mut bindless, &kernel, variant, &jobs, &p).unwrap();
            let diff = max_abs_diff(&reference, &gpu.texels);
            assert!(
                diff <= tolerance,
                "{variant:?} {tuning:?}: max difference {diff} > {tolerance}"
            );
            assert_eq!(gpu.timings.len(), 1);
            assert!(gpu.timings[0].ms > 0.0);
            outputs.push(gpu.texels);
        }
        // Same kernel body, same summation order: the tiled kernel equals the simple one bit for bit.
        assert_eq!(
            outputs[0], outputs[1],
            "{tuning:?}: simple and tiled differ"
        );
        kernel.destroy(ctx);
    }
    ctx.wait_idle().unwrap();
    bindless.destroy(ctx);
    common::assert_no_validation_errors(ctx);
}
