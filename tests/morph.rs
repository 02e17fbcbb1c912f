//! Level-of-detail transitions as drawn: the camera descends across switch distances in small steps, and every
//! vertex the terrain pass places (captured from the vertex shader) is compared with the surface drawn one step
//! before. With morphing nothing jumps; with the thesis's instant switching new vertices pop to their heights.

mod common;

use std::{collections::HashMap, sync::OnceLock};

use glam::DVec3;
use riverplanet::{
    config::Config,
    gpu::{Access, Context},
    planet::cube::PatchId,
    render::{target::Offscreen, VertexCapture},
    runtime::camera::Camera,
    world::World,
};

fn world() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    WORLD.get_or_init(|| World::build(&Config::appendix_a(), 1).unwrap())
}

/// Lattice points as integers at this level, whatever the level of the patch that draws them.
const KEY_LEVEL: u32 = 24;

type Key = (u8, u64, u64);

fn key(patch: PatchId, n: u32, i: u32, j: u32) -> Key {
    let shift = KEY_LEVEL - patch.level as u32;
    let cells = (n - 1) as u64;
    (
        patch.face,
        (patch.x as u64 * cells + i as u64) << shift,
        (patch.y as u64 * cells + j as u64) << shift,
    )
}

/// Every drawn grid vertex, in world coordinates, by lattice point.
fn surface(capture: &VertexCapture) -> HashMap<Key, DVec3> {
    let mut out = HashMap::new();
    for v in capture.drawn() {
        out.entry(key(v.patch, capture.vertices, v.i, v.j))
            .or_insert(capture.camera + v.relative);
    }
    out
}

/// The largest distance, in vertex spacings of its patch, between a vertex drawn in `next` and the surface drawn
/// in `previous` at the same place: the same lattice point's vertex, or for a vertex new in `next` (an odd point
/// of a patch that just split) the previous surface along the edge or diagonal it lies on, at the point its morph
/// has moved it to. Returns the jump and how many vertices were compared.
fn largest_jump(previous: &VertexCapture, next: &VertexCapture, radius: f64) -> (f64, usize) {
    let before = surface(previous);
    let n = next.vertices;
    let (mut largest, mut compared) = (0.0f64, 0);
    for v in next.drawn() {
        let (patch, i, j) = (v.patch, v.i, v.j);
        let spacing = radius * patch.size() / (n - 1) as f64;
        let here = next.camera + v.relative;
        let expected = match before.get(&key(patch, n, i, j)) {
            Some(p) => *p,
            None => {
                let (oi, oj) = (i % 2, j % 2);
                if oi + oj == 0 || i < oi || j < oj || i + oi >= n || j + oj >= n {
                    continue;
                }
                let ends = (
                    before.get(&key(patch, n, i - oi, j - oj)),
                    before.get(&key(patch, n, i + oi, j + oj)),
                );
                let (Some(a), Some(b)) = ends else { continue };
                ((*a + *b) * 0.5).lerp(*a, v.morph)
            }
        };
        compared += 1;
        largest = largest.max(here.distance(expected) / spacing);
    }
    (largest, compared)
}

/// Descends from 140 to 110 units above the first river's middle segment (across the switch distance of level 6,
/// 128 units) in steps of 0.25 %, and returns the largest jump of any step. (Above the same river's widest
/// segment, where the river preset now looks, a vertex moves 0.27 vertex spacings in a step where the water in
/// the mesh meets its banks: the placement on the water's surface follows the morphed river data, whose signed
/// distance crosses the basin's edge while the vertex morphs. Open; measured in the closing note of issue "A
/// world shaped by water".)
fn descend(ctx: &Context, morphing: bool) -> (f64, usize) {
    let world = world();
    let r = world.planet.radius;
    let system = &world.network.systems[0];
    let middle = system.segments[system.segments.len() / 2].curve.point(0.5);
    let up = system.frame.to_sphere(middle).normalize();
    let side = up.cross(DVec3::Y).normalize();
    let ground = r + world.planet.height_at(up).max(world.planet.sea_level) as f64;
    let size = [96, 54];
    let offscreen = Offscreen::new(ctx, size[0], size[1]).unwrap();
    let mut renderer = common::renderer(ctx, world);
    renderer.morphing = morphing;
    let mut previous: Option<VertexCapture> = None;
    let (mut largest, mut compared) = (0.0f64, 0);
    let mut altitude: f64 = 140.0;
    while altitude > 110.0 {
        let eye = up * (ground + altitude) + side * altitude * 0.5;
        let camera = Camera::look_at(eye, up * ground, 60.0, 16.0 / 9.0, altitude * 0.05);
        // Stream until every visible patch has its own data, then capture.
        renderer.capture_vertices = false;
        renderer
            .render_until_streamed(&camera, &offscreen.target([0.0, 0.0, 0.0, 1.0]), 50)
            .unwrap();
        renderer.capture_vertices = true;
        renderer
            .render(
                &camera,
                &offscreen.target([0.0, 0.0, 0.0, 1.0]),
                Access::ColorAttachment,
                &[],
                &[],
            )
            .unwrap();
        renderer.finish().unwrap();
        let capture = renderer.last_capture.take().expect("vertices captured");
        if let Some(p) = &previous {
            let (jump, count) = largest_jump(p, &capture, r);
            largest = largest.max(jump);
            compared += count;
        }
        previous = Some(capture);
        altitude *= 0.9975;
    }
    (largest, compared)
}

/// The largest move of a drawn vertex between two steps, in vertex spacings of its patch.
const MORPH_BOUND: f64 = 0.05;

#[test]
fn no_vertex_jumps_when_patches_split_with_morphing_and_they_do_without() {
    let Some(ctx) = common::gpu() else { return };
    let (morphed, compared) = descend(ctx, true);
    let (switched, _) = descend(ctx, false);
    eprintln!("largest jump per step: morphing {morphed:.4}, instant {switched:.4} vertex spacings ({compared} compared)");
    assert!(compared > 100_000, "only {compared} vertices compared");
    // A step moves the camera by 0.25 %, which advances a morph by under 1 % of a vertex spacing.
    assert!(
        morphed < MORPH_BOUND,
        "with morphing a vertex moved {morphed:.4} vertex spacings in one step (bound {MORPH_BOUND})"
    );
    // The same path without morphing pops (so this test can tell the two apart).
    assert!(
        switched > 4.0 * MORPH_BOUND,
        "instant switching moved at most {switched:.4} spacings"
    );
    common::assert_no_validation_errors(ctx);
}
