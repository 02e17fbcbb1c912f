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
        sample_floor: 0.25,
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
    let t = cpu::calculate_height([10.0, 16.0], &straight_river(), 1.0, &params());
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
    let t = cpu::calculate_height([10.0, 17.0], &straight_river(), 1.0, &p);
    assert!(
        (t.flow[0] - 1.0).abs() < 1e-6 && t.flow[1].abs() < 1e-6,
        "{t:?}"
    );
    let fast: Vec<RiverSample> = (0..=192)
        .map(|k| RiverSample::new([16.0, k as f32 / 6.0], [0.0, -3.0], 5.0, 4.0))
        .collect();
    let t = cpu::calculate_height([15.0, 10.0], &fast, 1.0, &p);
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
    let t = cpu::calculate_height([17.0, 15.0], &bend, 1.0, &p);
    assert!(t.flow[0] > 0.2 && t.flow[1] > 0.2, "{t:?}");
}

#[test]
fn basin_rises_cubically_to_the_banks() {
    let samples = straight_river();
    let p = params();
    let centre = cpu::calculate_height([10.0, 16.0], &samples, 1.0, &p).terrain_height;
    let quarter = cpu::calculate_height([10.0, 16.5], &samples, 1.0, &p).terrain_height;
    let near_bank = cpu::calculate_height([10.0, 17.9], &samples, 1.0, &p).terrain_height;
    let outside = cpu::calculate_height([10.0, 19.0], &samples, 1.0, &p);
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
    let left = cpu::calculate_height([10.0, 18.5], &samples, 1.0, &params());
    let right = cpu::calculate_height([10.0, 13.5], &samples, 1.0, &params());
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
        let t = cpu::calculate_height([10.0, y], &samples, 1.0, &p);
        assert!(
            t.lerp_factor > last && (0.0..=1.0).contains(&t.lerp_factor),
            "{y}: {t:?}"
        );
        last = t.lerp_factor;
    }
}

/// Beyond the thesis: a lake's samples (negative width) give the vertices within half their width the lake's
/// level as water and mark them as in a basin whose water the mesh shows (distance 0, the lake half width), so
/// the water is drawn where the terrain lies below the level; they carve nothing. A river's basin keeps its own
/// water where it lies below the level (an outlet); an inflow's water above the level comes down to it across the
/// lake's reach, its bed with it, so no river's water stands above a lake it flows into.
#[test]
fn a_lake_gives_its_level_to_the_vertices_it_reaches() {
    let p = params();
    let lake = RiverSample::new([10.0, 10.0], [1.0, 0.0], 3.0, -8.0);
    let t = cpu::calculate_height([12.0, 10.0], &[lake], 1.0, &p);
    assert_eq!(t.water_height, 3.0);
    assert_eq!((t.min_distance, t.river_width), (0.0, cpu::LAKE_HALF_WIDTH));
    assert_eq!(
        (t.terrain_height, t.lerp_factor),
        (0.0, 1.0),
        "the planet's own terrain"
    );
    // Beyond half its width the lake is not there.
    let beyond = cpu::calculate_height([15.0, 10.0], &[lake], 1.0, &p);
    assert_eq!(beyond, cpu::calculate_height([15.0, 10.0], &[], 1.0, &p));
    // In a river's basin above the lake's level (an inflow), 2.5 into the lake's reach of 4: the water keeps
    // (2.5 / 4)^2 of its excess over the level, and the bed falls with it.
    let mut both = straight_river();
    both.push(RiverSample::new([10.0, 14.0], [1.0, 0.0], 4.0, -8.0));
    let in_river = cpu::calculate_height([10.0, 16.5], &both, 1.0, &p);
    let river_only = cpu::calculate_height([10.0, 16.5], &straight_river(), 1.0, &p);
    let excess = river_only.water_height - 4.0;
    assert!(excess > 0.5, "{river_only:?}");
    let kept = (2.5f32 / 4.0).powi(2);
    assert!(
        (in_river.water_height - (4.0 + excess * kept)).abs() < 1e-5,
        "{in_river:?}"
    );
    let drop = river_only.water_height - in_river.water_height;
    assert!((river_only.terrain_height - in_river.terrain_height - drop).abs() < 1e-5);
    assert_eq!(
        (
            in_river.lerp_factor,
            in_river.min_distance,
            in_river.river_width
        ),
        (
            river_only.lerp_factor,
            river_only.min_distance,
            river_only.river_width
        ),
        "still the river's basin"
    );
    // On the lake's line the inflow's water is at the level.
    let mut lake_line = straight_river();
    lake_line.push(RiverSample::new([10.0, 16.0], [1.0, 0.0], 4.0, -8.0));
    let mouth = cpu::calculate_height([10.0, 16.0], &lake_line, 1.0, &p);
    assert_eq!(mouth.water_height, 4.0);
    // A river below the lake's level (an outlet) keeps its water.
    let mut outlet = straight_river();
    outlet.push(RiverSample::new([10.0, 14.0], [1.0, 0.0], 7.0, -8.0));
    assert_eq!(
        cpu::calculate_height([10.0, 16.5], &outlet, 1.0, &p),
        river_only
    );
    // Beside the river, the lake's level, with the river's lerp factor; the river's terrain (its valley floor,
    // here above the level), 2 into the lake's reach of 4, keeps (2 / 4)^2 of its excess, as an inflow's water:
    // the drawn ground does not stand above the lake's water at its points.
    let beside = cpu::calculate_height([10.0, 12.0], &both, 1.0, &p);
    let river_beside = cpu::calculate_height([10.0, 12.0], &straight_river(), 1.0, &p);
    assert_eq!(beside.water_height, 4.0);
    assert_eq!(beside.lerp_factor, river_beside.lerp_factor);
    let excess = river_beside.terrain_height - 4.0;
    assert!(excess > 0.5, "{river_beside:?}");
    assert!(
        (beside.terrain_height - (4.0 + excess * 0.25)).abs() < 1e-5,
        "{beside:?}"
    );
}

#[test]
fn no_relevant_sample_keeps_the_base_terrain() {
    let far = [RiverSample::new([500.0, 500.0], [1.0, 0.0], 5.0, 4.0)];
    let p = params();
    for samples in [&far[..], &[]] {
        let t = cpu::calculate_height([1.0, 1.0], samples, 1.0, &p);
        assert_eq!(
            t,
            RiverTexel {
                terrain_height: 0.0,
                lerp_factor: 1.0,
                water_height: p.sea_level,
                min_distance: p.influence_distance,
                river_width: 0.0,
                flow: [0.0; 2],
                second_distance: p.influence_distance,
                second_width: 0.0,
                nearest_sample_width: 0.0,
                river_order: 0.0,
            }
        );
    }
}

/// Beyond the thesis (docs/rendering.md, "Painted confluences"): between two rivers a vertex reports the nearest
/// and the nearest sample of the other river, in the rivers' order; samples of the nearest river itself never
/// count as the second, however many lie nearer than the other river.
#[test]
fn vertices_between_two_rivers_measure_both() {
    let p = params();
    // River 7 along y = 16 (width 4), river 3 along y = 22 (width 2), both flowing +x.
    let main: Vec<RiverSample> = straight_river()
        .into_iter()
        .map(|s| s.on_river(7))
        .collect();
    let other: Vec<RiverSample> = (0..=192)
        .map(|k| RiverSample::new([k as f32 / 6.0, 22.0], [1.0, 0.0], 5.0, 2.0).on_river(3))
        .collect();
    for samples in [
        [main.clone(), other.clone()].concat(),
        [other, main].concat(),
    ] {
        // Nearer the wide river: it is the nearest, the narrow one second (left of its flow: negative).
        let t = cpu::calculate_height([10.0, 18.0], &samples, 1.0, &p);
        assert!((t.min_distance - -2.0).abs() < 1e-4, "{t:?}");
        assert!((t.second_distance - 4.0).abs() < 1e-4, "{t:?}");
        assert_eq!((t.nearest_sample_width, t.second_width), (2.0, 1.0));
        assert_eq!(t.river_order, -1.0, "river 7 nearest, 3 second");
        // Nearer the narrow one: the order turns.
        let t = cpu::calculate_height([10.0, 21.0], &samples, 1.0, &p);
        assert!((t.min_distance - 1.0).abs() < 1e-4, "{t:?}");
        assert!((t.second_distance - -5.0).abs() < 1e-4, "{t:?}");
        assert_eq!(t.river_order, 1.0);
    }
    // One river alone: no second.
    let t = cpu::calculate_height([10.0, 18.0], &straight_river(), 1.0, &p);
    assert_eq!(
        (t.second_distance, t.second_width, t.river_order),
        (p.influence_distance, 0.0, 0.0)
    );
    assert_eq!(t.nearest_sample_width, 2.0);
    // Beyond the river's end (it runs from x = 0 to 32) by more than its half width and the samples' floor (a
    // quarter of the spacing here): the half width turns negative, for the shaders to narrow the river to nothing
    // there; within them it stays.
    let beyond = cpu::calculate_height([36.0, 17.0], &straight_river(), 1.0, &p);
    assert_eq!(beyond.nearest_sample_width, -2.0);
    let near_end = cpu::calculate_height([33.5, 17.0], &straight_river(), 1.0, &p);
    assert_eq!(near_end.nearest_sample_width, 2.0);
    let coarse = cpu::calculate_height([36.0, 17.0], &straight_river(), 20.0, &p);
    assert_eq!(
        coarse.nearest_sample_width, 2.0,
        "within a quarter of a 20-unit spacing"
    );
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
        let t = cpu::calculate_height(v, s, 1.0, &p);
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

/// Procedure 3 as printed (Section 6.5): the vertex projected onto the sample's normal line, three square roots
/// and the divisions. Returns (height, w_dist, in basin, w_river, normal factor, signed distance).
fn procedure_3_as_printed(v: [f32; 2], s: &RiverSample, p: &KernelParams) -> Option<[f32; 6]> {
    let length = |x: f32, y: f32| (x * x + y * y).sqrt();
    let (q, d) = (s.position, s.derivative);
    let dist = length(v[0] - q[0], v[1] - q[1]);
    if dist > p.influence_distance {
        return None;
    }
    let half_width = s.width * 0.5;
    let n = [d[1], -d[0]];
    let nn = n[0] * n[0] + n[1] * n[1];
    let t = if nn > 0.0 {
        ((v[0] - q[0]) * n[0] + (v[1] - q[1]) * n[1]) / nn
    } else {
        0.0
    };
    let vn = [q[0] + t * n[0], q[1] + t * n[1]];
    let projection = length(vn[0] - v[0], vn[1] - v[1]);
    let normal = length(q[0] - vn[0], q[1] - vn[1]);
    let w_dist = 1.0 - dist / p.influence_distance;
    let in_basin = projection < half_width && normal <= half_width;
    let side = d[0] * (v[1] - q[1]) - d[1] * (v[0] - q[0]);
    Some([
        w_dist * s.height,
        w_dist,
        in_basin as u8 as f32,
        if in_basin {
            1.0 - projection / half_width
        } else {
            0.0
        },
        if in_basin { normal / half_width } else { 0.0 },
        if side > 0.0 { -dist } else { dist },
    ])
}

/// The reference rearranges Procedure 3 so that every device decides alike (docs/kernel.md); away from the
/// decisions' borders, where rounding may go either way, it equals the procedure as printed.
#[test]
fn the_reference_equals_procedure_3_as_printed() {
    let p = params();
    let mut rng = riverplanet::rng::Rng::new(5, &[]);
    let mut compared = 0;
    for _ in 0..20_000 {
        let mut f = |lo: f32, hi: f32| rng.range(lo, hi);
        let s = RiverSample::new(
            [f(0.0, 32.0), f(0.0, 32.0)],
            [f(-3.0, 3.0), f(-3.0, 3.0)],
            f(0.0, 9.0),
            f(0.5, 12.0),
        );
        let v = [f(0.0, 32.0), f(0.0, 32.0)];
        let printed = procedure_3_as_printed(v, &s, &p);
        let ours = cpu::calculate_height_by_sample(v, &s, &p);
        let (Some(printed), Some(c)) = (printed, ours) else {
            assert_eq!(printed.is_some(), ours.is_some(), "{v:?} {s:?}");
            continue;
        };
        // Skip pairs within rounding of a border: the basin's end and side.
        if printed[2] == 1.0 && (printed[3] < 1e-3 || printed[4] > 1.0 - 1e-3) {
            continue;
        }
        let normal_factor = if c.in_river {
            (c.in_river_depth / (c.w_river * c.basin_depth)).cbrt()
        } else {
            0.0
        };
        let ours = [
            c.height,
            c.w_dist,
            c.in_river as u8 as f32,
            c.w_river,
            normal_factor,
            c.dist,
        ];
        for (k, (a, b)) in printed.iter().zip(ours).enumerate() {
            assert!(
                (a - b).abs() <= 1e-4 * a.abs().max(1.0),
                "{k}: {printed:?} {ours:?} at {v:?} {s:?}"
            );
        }
        compared += 1;
    }
    assert!(compared > 5_000, "{compared}");
}

/// Vulkan rounds additions and multiplications correctly but lets a driver fuse them unless told not to: the
/// kernels' decisions are `precise` (NoContraction in the SPIR-V), so they equal the CPU's on every device.
#[test]
fn kernel_decisions_are_never_fused() {
    for (name, spirv) in [
        ("simple", riverplanet::shaders::KERNEL_SIMPLE_COMP),
        ("tiled", riverplanet::shaders::KERNEL_TILED_COMP),
    ] {
        let words: Vec<u32> = spirv
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]))
            .collect();
        let (mut at, mut no_contraction) = (5, 0);
        while at < words.len() {
            let (opcode, length) = (words[at] & 0xffff, (words[at] >> 16) as usize);
            // OpDecorate (71) with NoContraction (42).
            if opcode == 71 && words[at + 2] == 42 {
                no_contraction += 1;
            }
            at += length.max(1);
        }
        assert!(
            no_contraction >= 10,
            "{name}: {no_contraction} NoContraction decorations"
        );
    }
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
    // The case of the mismatch on NVIDIA: vertices on a sample's line (45 degrees), where the side is exactly 0
    // unless a driver fuses d.x * r.y - d.y * r.x into one FMA, which leaves the rounding error of one product
    // and flipped the sign of min_distance (2 x the distance).
    patches.push((
        1.0,
        vec![RiverSample::new([2.0, 2.0], [0.7, 0.7], 2.0, 2.0)],
    ));
    // Vertices exactly at the influence distance ((24, 4) and (16, 20) from (4, 4)), and one exactly on the
    // basin's side (8, 10): normal distance = half width.
    patches.push((
        1.0,
        vec![
            RiverSample::new([4.0, 4.0], [1.0, 0.0], 2.0, 2.0),
            RiverSample::new([8.0, 8.0], [1.0, 0.0], 3.0, 4.0),
        ],
    ));
    // A lake beside a river: the lake's samples (negative width) reach vertices in and out of the river's basin.
    let mut lake_and_river: Vec<RiverSample> = (0..40)
        .map(|k| RiverSample::new([k as f32, 12.0 + (k % 3) as f32], [1.0, 0.0], 2.5, -9.0))
        .collect();
    lake_and_river.extend(straight_river());
    patches.push((1.0, lake_and_river));
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
        // Same kernel body, same summation order: the tiled kernel equals the simple one bit for bit on lavapipe;
        // another driver may compile the two shaders' unmarked arithmetic differently (on NVIDIA both came within
        // 4e-6 of the reference).
        let between = max_abs_diff(&outputs[0], &outputs[1]);
        assert!(
            between <= tolerance,
            "{tuning:?}: simple and tiled differ by {between}"
        );
    }
    ctx.wait_idle().unwrap();
    common::assert_no_validation_errors(ctx);
}

/// The kernel's shape is measured on the device at first use, kept in the cache file, read back from it, and
/// remeasured when the file is not a cache.
#[test]
fn kernel_tuning_is_measured_once_and_cached_per_device() {
    use riverplanet::kernel::gpu::autotune::{cached, device_key, Tuned};
    let Some(ctx) = common::gpu() else { return };
    let dir = std::env::temp_dir().join(format!("riverplanet-tuning-{}", std::process::id()));
    let path = dir.join("nested").join("kernel-tuning.json");
    let measured = cached(ctx, N, Some(&path)).unwrap();
    measured.tuning.validate(ctx).unwrap();
    assert!(
        measured.simple_ms > 0.0 && measured.tiled_ms > 0.0,
        "{measured:?}"
    );
    let ms = |t: &Tuned| match t.variant {
        KernelVariant::Simple => t.simple_ms,
        KernelVariant::Tiled => t.tiled_ms,
    };
    assert_eq!(
        ms(&measured),
        measured.simple_ms.min(measured.tiled_ms),
        "the faster variant is chosen"
    );
    // The file holds this device's entry; an edited entry is what the next start uses.
    let read = |p: &std::path::Path| -> std::collections::BTreeMap<String, Tuned> {
        serde_json::from_slice(&std::fs::read(p).unwrap()).unwrap()
    };
    let key = device_key(ctx, N);
    let mut cache = read(&path);
    // JSON keeps the choice exactly and the times to their last bit or so (serde_json's parsing).
    let stored = cache[&key];
    assert_eq!(
        (stored.tuning, stored.variant),
        (measured.tuning, measured.variant)
    );
    for (a, b) in [
        (stored.simple_ms, measured.simple_ms),
        (stored.tiled_ms, measured.tiled_ms),
    ] {
        assert!((a - b).abs() <= 1e-12 * b, "{stored:?} {measured:?}");
    }
    // Times that JSON holds exactly, so the entry read back must equal it.
    let edited = Tuned {
        simple_ms: 123.0,
        tiled_ms: 45.5,
        ..measured
    };
    cache.insert(key.clone(), edited);
    std::fs::write(&path, serde_json::to_vec(&cache).unwrap()).unwrap();
    assert_eq!(cached(ctx, N, Some(&path)).unwrap(), edited);
    // An entry this device cannot run is measured again.
    let mut broken = edited;
    broken.tuning.tiled_block = [3, 3];
    cache.insert(key.clone(), broken);
    std::fs::write(&path, serde_json::to_vec(&cache).unwrap()).unwrap();
    cached(ctx, N, Some(&path))
        .unwrap()
        .tuning
        .validate(ctx)
        .unwrap();
    // A file that is not a cache is replaced by a fresh measurement.
    std::fs::write(&path, b"{ not json").unwrap();
    let again = cached(ctx, N, Some(&path)).unwrap();
    again.tuning.validate(ctx).unwrap();
    assert!(read(&path).contains_key(&key));
    std::fs::remove_dir_all(&dir).unwrap();
    common::assert_no_validation_errors(ctx);
}
