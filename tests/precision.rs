//! Precision at planetary scale (config/earth.xml, radius 6,371,000 m): two metres above a river's water, every
//! vertex the terrain pass draws near the camera lies where the f64 geometry puts it to within a millimetre, and
//! moving the camera by a centimetre moves no vertex by more than that motion explains (no jitter); the water's
//! ripples there are smooth, not streaks.

mod common;

use std::collections::HashMap;

use glam::DVec3;
use riverplanet::{
    planet::cube::PatchId,
    render::{
        presets::{self, Preset},
        target::Offscreen,
        Renderer, VertexCapture,
    },
    runtime::camera::Camera,
};

/// Vertices this close to the camera are checked (metres).
const NEAR: f64 = 20.0;
/// The largest error allowed (metres).
const MILLIMETRE: f64 = 1e-3;

/// Every drawn grid vertex within `NEAR` of the camera: world position (f64) and morph factor, by (patch, i, j).
fn near_vertices(capture: &VertexCapture) -> HashMap<(PatchId, u32, u32), (DVec3, f64)> {
    capture
        .drawn()
        .filter(|v| v.relative.length() < NEAR)
        .map(|v| ((v.patch, v.i, v.j), (capture.camera + v.relative, v.morph)))
        .collect()
}

#[test]
fn two_metres_above_an_earth_sized_river_vertices_are_exact_to_a_millimetre_and_do_not_jitter() {
    let Some(ctx) = common::gpu() else { return };
    // Everything streamed in as fast as the device goes: this test is about positions, not budgets.
    let world = common::earth_streaming_at_once();
    let config = &world.config;
    let radius = world.planet.radius;
    let n = config.rendering.vertices;
    let (eye, look_at) = presets::camera(Preset::Ground, &world).unwrap();
    let offscreen = Offscreen::new(ctx, 64, 36).unwrap();
    let mut renderer = common::renderer(ctx, &world);
    let target = offscreen.target([0.0, 0.0, 0.0, 1.0]);
    // `frames` frames at most, until every visible patch has its data.
    let frame = |renderer: &mut Renderer, camera: &Camera, capture: bool, frames: u32| {
        renderer.capture_vertices = capture;
        let (stats, _) = renderer
            .render_until_streamed(camera, &target, frames)
            .unwrap();
        stats
    };
    let camera_at =
        |offset: DVec3| Camera::look_at(eye + offset, look_at + offset, 60.0, 16.0 / 9.0, 0.1);
    let here = camera_at(DVec3::ZERO);
    let streamed = frame(&mut renderer, &here, false, 60).streamed();
    assert!(streamed, "patch data still streaming after 60 frames");
    let deepest = frame(&mut renderer, &here, true, 1).deepest_level;
    let before = renderer.last_capture.take().unwrap();
    // One centimetre sideways.
    let side = (look_at - eye).cross(eye).normalize() * 0.01;
    frame(&mut renderer, &camera_at(side), true, 1);
    let after = renderer.last_capture.take().unwrap();
    assert!(
        deepest >= 20,
        "deepest level {deepest} two metres above the water"
    );

    // Where the f64 geometry puts each vertex: the unit direction of its (morphed) grid point, compared with the
    // drawn position's direction (the height is the shader's to choose).
    let near = near_vertices(&before);
    assert!(
        near.len() > 1000,
        "only {} vertices near the camera",
        near.len()
    );
    let mut worst: f64 = 0.0;
    for ((patch, i, j), (position, morph)) in &near {
        let grid = |k: u32| (k as f64 - (k % 2) as f64 * morph) / (n - 1) as f64;
        let exact = patch.sphere_point(grid(*i), grid(*j));
        worst = worst.max((position.normalize() - exact).length() * position.length());
    }
    eprintln!(
        "largest position error near the camera: {:.3} mm",
        worst * 1e3
    );
    assert!(
        worst < MILLIMETRE,
        "a vertex is {:.3} mm from where it belongs",
        worst * 1e3
    );

    // Moving the camera moves no vertex: at most the morph a centimetre explains (its factor changes by 1 cm over
    // the morph band, at least 30 % of a 3 m switch distance).
    let moved = near_vertices(&after);
    let mut largest: f64 = 0.0;
    let mut compared = 0;
    for (key, (position, _)) in &near {
        if let Some((other, _)) = moved.get(key) {
            compared += 1;
            largest = largest.max(position.distance(*other));
        }
    }
    let spacing = |p: &PatchId| radius * p.size() / (n - 1) as f64;
    let explained = near
        .keys()
        .map(|(p, _, _)| {
            spacing(p) * 0.01
                / (0.3
                    * riverplanet::runtime::lod::threshold(
                        radius,
                        config.rendering.level_of_detail_switch_factor as f64,
                        p.level as u32,
                    ))
        })
        .fold(0.0, f64::max);
    eprintln!(
        "largest vertex move for a 1 cm camera move: {:.4} mm ({compared} vertices; morph explains {:.4} mm)",
        largest * 1e3,
        explained * 1e3
    );
    assert!(
        compared > 1000,
        "only {compared} vertices drawn in both frames"
    );
    assert!(
        largest <= explained + 1e-5,
        "a vertex moved {:.4} mm when the camera moved 1 cm (morphing explains {:.4} mm)",
        largest * 1e3,
        explained * 1e3
    );
    common::assert_no_validation_errors(ctx);
}

/// The mean difference between vertically neighbouring pixels' brightness (0-255) in the lower 40 % of `image`.
fn row_to_row_change(image: &image::RgbaImage) -> f64 {
    let brightness = |x: u32, y: u32| {
        let p = image.get_pixel(x, y).0;
        (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0
    };
    let (w, h) = image.dimensions();
    let rows = h * 6 / 10..h - 1;
    let mut sum = 0.0;
    for y in rows.clone() {
        for x in 0..w {
            sum += (brightness(x, y + 1) - brightness(x, y)).abs();
        }
    }
    sum / (rows.len() as f64 * w as f64)
}

/// Two metres above an Earth river the ripples are a few metres across; their coordinates in f32 absolute
/// positions lay 0.4 m apart there and broke them into bright streaks across the water (mean row-to-row change of
/// the water below the horizon 7.0 levels, against 0.7 for still water). From the patch-relative detail
/// coordinates (docs/rendering.md, "Water that flows") flowing water is as smooth from row to row as still water,
/// within a small allowance for the ripples themselves.
#[test]
fn ripples_on_an_earth_river_show_no_streaks() {
    let Some(ctx) = common::gpu() else { return };
    let world = common::earth_streaming_at_once();
    let (eye, look_at) = presets::camera(Preset::Ground, &world).unwrap();
    let camera = Camera::look_at(eye, look_at, 60.0, 16.0 / 9.0, 0.1);
    let offscreen = Offscreen::new(ctx, 640, 360).unwrap();
    let target = offscreen.target([0.0, 0.0, 0.0, 1.0]);
    let change = |flowing: bool| {
        let mut renderer = common::renderer(ctx, &world);
        renderer.flowing_water = flowing;
        let (stats, _) = renderer
            .render_until_streamed(&camera, &target, 60)
            .unwrap();
        assert!(
            stats.streamed(),
            "patch data still streaming after 60 frames"
        );
        row_to_row_change(&offscreen.read(ctx).unwrap())
    };
    let (flowing, still) = (change(true), change(false));
    eprintln!("row-to-row change below the horizon: flowing {flowing:.2}, still {still:.2}");
    assert!(
        flowing <= 2.0 * still + 0.5,
        "flowing water changes by {flowing:.2} from row to row, still water by {still:.2}: streaks"
    );
    common::assert_no_validation_errors(ctx);
}
