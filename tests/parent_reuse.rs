//! River data from the parent patch (10.2): once a patch's samples are the rivers' final detail, its children's
//! even vertices equal the parent's, so the kernels copy them and compute only the other three quarters; the
//! result equals computing the children from scratch.

mod common;

use std::{collections::HashMap, path::Path};

use glam::DVec3;

use riverplanet::{
    config::Config,
    gpu::bindless::Bindless,
    kernel::{
        cpu,
        gpu::{run_batch_into, BatchOutputs, KernelTuning, KernelVariant, RiverKernel},
        max_abs_diff, KernelParams, ParentQuadrant, PatchJob, RiverTexel,
    },
    planet::cube::PatchId,
    render::{
        presets::{self, Preset},
        target::Offscreen,
        VertexCapture,
    },
    river::samples::{patch_samples, PatchFrame, PatchSamples},
    runtime::camera::Camera,
    world::World,
};

fn earth() -> World {
    let config =
        Config::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("config/earth.xml")).unwrap();
    World::build(&config, config.resolve_seed()).unwrap()
}

/// The patches under the ground preset's look-at point, from level 0 to the deepest, with their samples.
fn column(world: &World) -> Vec<(PatchId, PatchSamples)> {
    let (_, look_at) = presets::camera(Preset::Ground, world).unwrap();
    let n = world.config.rendering.vertices;
    (0..=world.config.rendering.max_level_of_detail as u8)
        .map(|level| {
            let patch = PatchId::containing(look_at.normalize(), level);
            let frame = PatchFrame::new(patch, world.planet.radius, n);
            (patch, patch_samples(&world.network, &frame))
        })
        .collect()
}

#[test]
fn river_detail_becomes_final_at_some_level_and_stays_final_below_it() {
    let world = earth();
    let column = column(&world);
    assert!(column.iter().all(|(_, s)| !s.samples.is_empty()));
    let first = column
        .iter()
        .position(|(_, s)| s.final_detail)
        .expect("the rivers reach their final detail above the deepest level");
    println!("final river detail from level {first}");
    assert!(first > 0, "the coarse levels draw simplified rivers");
    assert!(
        column[first..].iter().all(|(_, s)| s.final_detail),
        "final from level {first} on"
    );
}

fn frame_jobs<'a>(
    world: &World,
    patches: &[PatchId],
    samples: &'a [PatchSamples],
) -> Vec<PatchJob<'a>> {
    let n = world.config.rendering.vertices;
    patches
        .iter()
        .zip(samples)
        .map(|(p, s)| PatchJob {
            spacing: PatchFrame::new(*p, world.planet.radius, n).spacing() as f32,
            samples: &s.samples,
        })
        .collect()
}

/// Children of `parent`'s patch with reuse on the CPU and both GPU kernels, against the children from scratch.
/// Returns the largest difference and the tolerance: 1e-4 of the height range, plus 4 f32 steps of the largest
/// height (the children's frames differ from the parent's by a translation, which rounds positions differently).
fn reuse_against_scratch(world: &World, parent: PatchId) -> (f32, f32) {
    let n = world.config.rendering.vertices;
    let params = KernelParams::from_config(&world.config);
    let children: Vec<PatchId> = (0..4).map(|q| parent.child(q)).collect();
    let samples = |ps: &[PatchId]| -> Vec<PatchSamples> {
        ps.iter()
            .map(|p| patch_samples(&world.network, &PatchFrame::new(*p, world.planet.radius, n)))
            .collect()
    };
    let parent_samples = samples(&[parent]);
    let child_samples = samples(&children);
    let parent_jobs = frame_jobs(world, &[parent], &parent_samples);
    let child_jobs = frame_jobs(world, &children, &child_samples);
    let quadrants: Vec<ParentQuadrant> = children
        .iter()
        .map(|c| ParentQuadrant::of(*c, n).unwrap())
        .collect();
    let scratch = cpu::compute_patches(&child_jobs, n, &params);
    let parent_cpu = cpu::compute_patches(&parent_jobs, n, &params);
    let range = scratch
        .iter()
        .flatten()
        .map(|t| t.terrain_height)
        .fold((f32::MAX, f32::MIN), |(lo, hi), h| (lo.min(h), hi.max(h)));
    let largest = range.0.abs().max(range.1.abs());
    let tolerance = 1e-4 * (range.1 - range.0).max(1.0) + 4.0 * f32::EPSILON * largest;
    let cpu_reuse: Vec<Vec<RiverTexel>> = child_jobs
        .iter()
        .zip(&quadrants)
        .map(|(job, q)| cpu::compute_patch_from_parent(job, &parent_cpu[0], *q, n, &params))
        .collect();
    let mut diff = max_abs_diff(&scratch, &cpu_reuse);

    let Some(ctx) = common::gpu() else {
        return (diff, tolerance);
    };
    let mut bindless = Bindless::new(ctx, 64).unwrap();
    let kernel = RiverKernel::new(ctx, &bindless, n, KernelTuning::for_device(ctx)).unwrap();
    let parent_out = BatchOutputs::new(ctx, &mut bindless, 1, n).unwrap();
    let child_out = BatchOutputs::new(ctx, &mut bindless, 4, n).unwrap();
    let run = |variant, jobs: &[PatchJob], parents, outputs: &BatchOutputs| {
        run_batch_into(
            ctx, &bindless, &kernel, variant, jobs, parents, &params, outputs,
        )
        .unwrap()
    };
    let parent_place = parent_out.places()[0];
    let parents: Vec<_> = quadrants.iter().map(|q| Some((parent_place, *q))).collect();
    let parent_textures = parent_out.parent_textures(&parents);
    for variant in [KernelVariant::Simple, KernelVariant::Tiled] {
        let parent_gpu = run(variant, &parent_jobs, (&[], &[]), &parent_out).texels;
        let reused = run(
            variant,
            &child_jobs,
            (&parents, &parent_textures),
            &child_out,
        )
        .texels;
        diff = diff.max(max_abs_diff(&scratch, &reused));
        // The even vertices are the parent's GPU values, copied.
        for (texels, q) in reused.iter().zip(&quadrants) {
            for (k, texel) in texels.iter().enumerate() {
                let (i, j) = (k as u32 % n, k as u32 / n);
                if let Some((pi, pj)) = q.parent_vertex(i, j) {
                    assert_eq!(*texel, parent_gpu[0][(pj * n + pi) as usize], "{variant:?}");
                }
            }
        }
    }
    ctx.wait_idle().unwrap();
    common::assert_no_validation_errors(ctx);
    (diff, tolerance)
}

#[test]
fn children_of_a_final_parent_take_its_vertices_and_equal_the_children_from_scratch() {
    let world = earth();
    let column = column(&world);
    let first = column.iter().position(|(_, s)| s.final_detail).unwrap();
    // The first final parent and one four levels deeper (or the column's deepest).
    let deeper = (first + 4).min(column.len() - 1);
    for (parent, _) in [&column[first], &column[deeper]] {
        let (diff, tolerance) = reuse_against_scratch(&world, *parent);
        assert!(
            diff <= tolerance,
            "level {}: reuse differs from scratch by {diff} > {tolerance}",
            parent.level
        );
    }
}

#[test]
fn above_the_final_detail_the_parent_draws_other_rivers_than_its_children() {
    // Why reuse waits for the final detail: a coarser parent's rivers are simplified, and copying its vertices
    // would put the children's river beds elsewhere.
    let world = earth();
    let column = column(&world);
    let first = column.iter().position(|(_, s)| s.final_detail).unwrap();
    let (diff, tolerance) = reuse_against_scratch(&world, column[first - 3].0);
    assert!(
        diff > tolerance,
        "level {}: {diff} <= {tolerance}",
        column[first - 3].0.level
    );
}

/// The ground preset of config/earth.xml rendered until everything has streamed in: the drawn vertices (relative
/// to the camera, by patch) and how many patches took river data from their parent on the way.
fn ground_vertices(parent_reuse: bool) -> Option<(VertexCapture, usize)> {
    let ctx = common::gpu()?;
    let world = common::earth_streaming_at_once();
    let (eye, look_at) = presets::camera(Preset::Ground, &world).unwrap();
    let camera = Camera::look_at(eye, look_at, 60.0, 16.0 / 9.0, 0.1);
    let offscreen = Offscreen::new(ctx, 64, 36).unwrap();
    let target = offscreen.target([0.0, 0.0, 0.0, 1.0]);
    let mut renderer = common::renderer(ctx, &world);
    renderer.parent_reuse = parent_reuse;
    let mut from_parent = 0;
    for _ in 0..60 {
        let (stats, _) = renderer.render_until_streamed(&camera, &target, 1).unwrap();
        from_parent += stats.river_patches_from_parent;
        if stats.streamed() {
            break;
        }
    }
    renderer.capture_vertices = true;
    renderer.render_until_streamed(&camera, &target, 1).unwrap();
    let capture = renderer.last_capture.take().unwrap();
    common::assert_no_validation_errors(ctx);
    Some((capture, from_parent))
}

#[test]
fn the_ground_view_draws_the_same_terrain_with_and_without_river_data_from_the_parent() {
    let Some((reused, from_parent)) = ground_vertices(true) else {
        return;
    };
    let (scratch, none) = ground_vertices(false).unwrap();
    assert!(from_parent > 0, "no patch took river data from its parent");
    assert_eq!(none, 0);
    // Vertices drawn in both views, by instance patch and grid point.
    let scratch: HashMap<(PatchId, u32, u32), DVec3> = scratch
        .drawn()
        .map(|v| ((v.patch, v.i, v.j), v.relative))
        .collect();
    let (mut compared, mut worst) = (0, 0.0f64);
    for v in reused.drawn() {
        if let Some(other) = scratch.get(&(v.patch, v.i, v.j)) {
            compared += 1;
            worst = worst.max((v.relative - *other).abs().max_element());
        }
    }
    println!("{compared} vertices compared, largest difference {worst} m");
    assert!(compared > 10_000, "only {compared} vertices in both views");
    // A millimetre: the children's frames round positions differently from the parent's (the kernel test's
    // tolerance of a few f32 steps of heights of thousands of metres).
    assert!(worst <= 1e-3, "the views differ by {worst} m");
}
