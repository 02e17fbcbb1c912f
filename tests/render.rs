//! Headless rendering on a real device: reference images, no holes in the planet's disc, zero validation errors.

mod common;

use std::{path::PathBuf, sync::OnceLock};

use glam::DVec3;
use riverplanet::{
    bench::holes::{hole_pixels, HOLE_COLOUR},
    config::Config,
    gpu::{vk, Context},
    render::{
        presets::{self, Preset},
        target::Offscreen,
        Renderer, WaterMode,
    },
    runtime::camera::Camera,
    world::World,
};

const SEED: u32 = 1;
const CLEAR: [f32; 4] = HOLE_COLOUR;

fn world() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    WORLD.get_or_init(|| World::build(&Config::default(), SEED).unwrap())
}

/// Renders until every visible patch has its own data, and returns the image.
fn render(ctx: &Context, camera: &Camera, size: [u32; 2], water: WaterMode) -> image::RgbaImage {
    render_with(ctx, camera, size, |renderer| renderer.water_mode = water)
}

fn preset_camera(preset: Preset, aspect: f64) -> Camera {
    let (eye, target) = presets::camera(preset, world()).unwrap();
    let altitude = eye.length() - world().planet.radius;
    Camera::look_at(
        eye,
        target,
        45.0,
        aspect,
        (altitude * 0.05).clamp(0.01, 10.0),
    )
}

fn out_dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("render");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Mean absolute difference per channel (0-255), and the share of pixels differing by more than 48 in any channel.
fn compare(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, f64) {
    let mut sum = 0u64;
    let mut outliers = 0usize;
    for (p, q) in a.pixels().zip(b.pixels()) {
        let d: Vec<u32> = (0..3)
            .map(|c| (p.0[c] as i32 - q.0[c] as i32).unsigned_abs())
            .collect();
        sum += d.iter().map(|x| *x as u64).sum::<u64>();
        if d.iter().any(|x| *x > 48) {
            outliers += 1;
        }
    }
    let n = (a.width() * a.height()) as f64;
    (sum as f64 / (3.0 * n), outliers as f64 / n)
}

#[test]
fn renders_match_the_references() {
    let Some(ctx) = common::gpu() else { return };
    let size = [256, 144];
    let aspect = size[0] as f64 / size[1] as f64;
    for (name, preset, water) in [
        ("orbit", Preset::Orbit, WaterMode::Auto),
        ("river-geometry", Preset::River, WaterMode::Geometry),
        ("river-painted", Preset::River, WaterMode::Painted),
    ] {
        let image = render(ctx, &preset_camera(preset, aspect), size, water);
        let actual = out_dir().join(format!("{name}.png"));
        image.save(&actual).unwrap();
        let reference =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("tests/references/{name}.png"));
        if std::env::var("RIVERPLANET_UPDATE_REFERENCES").is_ok_and(|v| v == "1") {
            image.save(&reference).unwrap();
            continue;
        }
        let expected = image::open(&reference)
            .unwrap_or_else(|e| {
                panic!(
                    "{}: {e} (run with RIVERPLANET_UPDATE_REFERENCES=1)",
                    reference.display()
                )
            })
            .to_rgba8();
        let (mean, outliers) = compare(&image, &expected);
        assert!(
            mean < 4.0 && outliers < 0.02,
            "{name}: mean difference {mean:.2}, {:.2}% outliers; actual image at {}",
            outliers * 100.0,
            actual.display()
        );
    }
    common::assert_no_validation_errors(ctx);
}

#[test]
fn the_two_water_modes_differ_where_rivers_are() {
    let Some(ctx) = common::gpu() else { return };
    let size = [256, 144];
    let camera = preset_camera(Preset::River, size[0] as f64 / size[1] as f64);
    let geometry = render(ctx, &camera, size, WaterMode::Geometry);
    let painted = render(ctx, &camera, size, WaterMode::Painted);
    let (mean, _) = compare(&geometry, &painted);
    assert!(
        mean > 0.05,
        "geometry and painted water look identical (mean difference {mean})"
    );
    common::assert_no_validation_errors(ctx);
}

#[test]
fn no_pixel_inside_the_planet_shows_the_clear_colour() {
    let Some(ctx) = common::gpu() else { return };
    let world = world();
    let r = world.planet.radius;
    let size = [160, 120];
    let source = world.network.systems[0].source;
    let cameras = [
        (source * r * 3.0, DVec3::ZERO),
        (source * r * 1.6, source * r),
        (
            (source + DVec3::X * 0.3).normalize() * (r + 200.0),
            source * r,
        ),
        (
            source * (r + 60.0),
            (source + DVec3::Y * 0.2).normalize() * r,
        ),
        (
            DVec3::new(0.3, -0.8, 0.5).normalize() * r * 2.2,
            DVec3::ZERO,
        ),
    ];
    for (k, (eye, target)) in cameras.iter().enumerate() {
        let altitude = eye.length() - r;
        let camera = Camera::look_at(
            *eye,
            *target,
            60.0,
            4.0 / 3.0,
            (altitude * 0.05).clamp(0.01, 10.0),
        );
        let image = render(ctx, &camera, size, WaterMode::Auto);
        let inner = r + world.planet.stats.min_height as f64 - 2.0;
        let (holes, inside) = hole_pixels(&image, &camera, inner);
        if holes > 0 {
            let path = out_dir().join(format!("holes-{k}.png"));
            image.save(&path).unwrap();
            panic!(
                "camera {k}: {holes} of {inside} planet pixels show the clear colour; see {}",
                path.display()
            );
        }
        assert!(inside > 0, "camera {k} sees no planet");
    }
    common::assert_no_validation_errors(ctx);
}

/// Renders with the renderer configured by `setup`, until every visible patch has its own data.
fn render_with(
    ctx: &Context,
    camera: &Camera,
    size: [u32; 2],
    setup: impl Fn(&mut Renderer),
) -> image::RgbaImage {
    let world = world();
    let target = Offscreen::new(ctx, size[0], size[1]).unwrap();
    let mut renderer = common::renderer(ctx, world);
    setup(&mut renderer);
    let mut layout = vk::ImageLayout::UNDEFINED;
    renderer
        .render_until_streamed(camera, &target.target(CLEAR), &mut layout, 100)
        .unwrap();
    let image = target.read(ctx).unwrap();
    renderer.destroy();
    target.destroy(ctx);
    image
}
