//! `riverplanet render` (headless) and `riverplanet view` (the interactive viewer).

use riverplanet::{
    gpu::{Context, ContextOptions},
    kernel::gpu::autotune::KernelChoice,
};

use super::{RenderArgs, ViewArgs};
use crate::{check_output, load_config, planet_seed, usage};

pub fn render(options: &ContextOptions, args: &RenderArgs) -> anyhow::Result<()> {
    let (config, _) = load_config(args.planet.config.as_deref())?;
    check_output("--out", &args.out, true)?;
    let recorded = match &args.path {
        Some(file) => {
            let frame = path_frame(file, args.path_frame)?;
            check_path_frame(&frame, &config)
                .map_err(|e| usage(format!("--path {}: {e}", file.display())))?;
            Some(frame)
        }
        None => None,
    };
    if args.preset.is_none() && recorded.is_none() {
        check_camera(args.eye, args.look_at, &config)?;
    }
    if !(0.0..=MAX_TIME_S).contains(&args.time) {
        return Err(usage(format!(
            "--time {} must be in [0, {MAX_TIME_S}] seconds (the water's clock is single precision)",
            args.time
        )));
    }
    if let Some(up) = args.up {
        let forward = (args.look_at - args.eye).normalize_or_zero();
        if up.cross(forward).length() < 1e-6 * up.length() || up.length() == 0.0 {
            return Err(usage(format!(
                "--up {up} must be a direction across the view (not zero, not along --look-at minus --eye)"
            )));
        }
    }
    if !(1.0..=170.0).contains(&args.fov) {
        return Err(usage(format!(
            "--fov {} must be in [1, 170] degrees",
            args.fov
        )));
    }
    // Before any work: a device that cannot draw is refused here.
    let ctx = Context::new(&ContextOptions {
        draws: true,
        ..options.clone()
    })?;
    let seed = planet_seed(args.planet.seed, &config);
    let world = super::progress::build_world(&config, seed)?;
    let (eye, look_at) = match (args.preset, &recorded) {
        (Some(preset), _) => {
            riverplanet::render::presets::camera(preset, &world).ok_or_else(|| {
                anyhow::anyhow!("preset {preset:?} needs a river, and this planet has none")
            })?
        }
        (None, Some(frame)) => {
            let eye = glam::DVec3::from_array(frame.position);
            (eye, eye + glam::DVec3::from_array(frame.forward))
        }
        (None, None) => (args.eye, args.look_at),
    };
    println!(
        "camera: --eye {},{},{} --look-at {},{},{}",
        eye.x, eye.y, eye.z, look_at.x, look_at.y, look_at.z
    );
    let [w, h] = args.size;
    let target = riverplanet::render::target::Offscreen::new(&ctx, w, h)?;
    let mut renderer = riverplanet::render::Renderer::new(
        &ctx,
        &world.planet,
        &world.network,
        &config,
        riverplanet::render::target::COLOR_FORMAT,
        riverplanet::render::target::DEPTH_FORMAT,
    )?;
    renderer.water_mode = args.water;
    renderer.view_mode = args.view;
    if let KernelChoice::Fixed(variant) = args.kernel {
        renderer.variant = variant;
    }
    renderer.morphing = !args.no_morphing;
    renderer.atmosphere_on = args.atmosphere.on();
    renderer.flowing_water = args.flowing_water.on();
    renderer.water_in_mesh = args.water_in_mesh.on();
    renderer.time = args.time as f32;
    if let Some(elevation) = args.sun_elevation {
        // Straight ahead along the camera's horizon, raised by the elevation.
        let up = eye.normalize();
        let forward = look_at - eye;
        let ahead = (forward - up * forward.dot(up))
            .try_normalize()
            .unwrap_or_else(|| up.any_orthonormal_vector());
        let e = elevation.to_radians();
        renderer.sun = Some(ahead * e.cos() + up * e.sin());
    }
    renderer.lod_rule = riverplanet::config::LodRule::for_run(
        args.lod_rule,
        renderer.morphing,
        config.rendering.level_of_detail_rule,
    );
    // Above the drawn surface (terrain or water) below the eye, not the radius: high ground would clip the surface
    // in front of a camera close above it.
    let ground = riverplanet::render::ground::Ground::new(&world).height_below(eye, &world);
    let altitude = eye.length() - config.planet.radius as f64 - ground;
    let mut camera = riverplanet::runtime::camera::Camera::look_at(
        eye,
        look_at,
        args.fov,
        w as f64 / h as f64,
        riverplanet::runtime::camera::near_plane(altitude),
    );
    if let Some(up) = args.up {
        camera.up = up.normalize();
    }
    if let Some(frame) = &recorded {
        camera = frame.camera(w as f64 / h as f64);
    }
    let c = args.clear_color;
    let clear = [c.x as f32, c.y as f32, c.z as f32, 1.0];
    let progress =
        super::progress::Progress::start("rendering until every visible patch has its data");
    let (stats, frames) =
        renderer.render_until_streamed(&camera, &target.target(clear), args.max_frames)?;
    drop(progress);
    let image = target.read(&ctx)?;
    riverplanet::export::files::save_image(&image, &args.out)?;
    println!(
        "{}: {w}x{h}, {frames} frames to stream the patches; last frame: {} visible patches, {} resident, \
         deepest level {}",
        args.out.display(),
        stats.visible_patches,
        stats.resident_patches,
        stats.deepest_level
    );
    for (pass, ms) in &stats.gpu_ms {
        println!("  gpu {pass:<8} {ms:8.3} ms");
    }
    println!("  frame     {:8.3} ms", stats.frame_ms);
    let errors = ctx.validation_errors();
    if !errors.is_empty() {
        anyhow::bail!(
            "validation reported {} error(s): {}",
            errors.len(),
            errors[0]
        );
    }
    Ok(())
}

/// The latest `--time` (seconds): beyond it the water's f32 clock moves in steps of a frame or more.
const MAX_TIME_S: f64 = 1e6;

/// Refuses a camera inside the planet (below half its radius: the terrain never reaches there), further than
/// [`MAX_CAMERA_RADII`] radii from its centre, or one that looks at itself, before any work.
fn check_camera(
    eye: glam::DVec3,
    look_at: glam::DVec3,
    config: &riverplanet::config::Config,
) -> anyhow::Result<()> {
    camera_distance(eye, config).map_err(|e| usage(format!("--eye {e}")))?;
    if (look_at - eye).length() < 1e-9 {
        return Err(usage("--look-at must differ from --eye"));
    }
    Ok(())
}

/// The farthest a camera may be from the planet's centre, in radii: the planet is then a few pixels wide, and
/// further out the camera-relative f32 positions of its patches lose their metres.
const MAX_CAMERA_RADII: f64 = 1e4;

/// Why a camera at `eye` cannot see this planet, if it cannot: inside it (below half its radius) or too far.
fn camera_distance(eye: glam::DVec3, config: &riverplanet::config::Config) -> Result<(), String> {
    let radius = config.planet.radius as f64;
    if !eye.is_finite() || eye.length() <= radius * 0.5 {
        return Err(format!("{eye} is inside the planet (radius {radius})"));
    }
    if eye.length() > radius * MAX_CAMERA_RADII {
        return Err(format!(
            "{eye} is {:.3e} radii from the planet's centre, more than {MAX_CAMERA_RADII:e} (radius {radius})",
            eye.length() / radius
        ));
    }
    Ok(())
}

/// Refuses a recorded camera as `--eye` is refused.
pub(crate) fn check_path_frame(
    frame: &riverplanet::runtime::camera_path::PathFrame,
    config: &riverplanet::config::Config,
) -> Result<(), String> {
    camera_distance(glam::DVec3::from_array(frame.position), config)
}

/// Frame `number` (1-based; the last without one) of the camera path in `file`.
fn path_frame(
    file: &std::path::Path,
    number: Option<u32>,
) -> anyhow::Result<riverplanet::runtime::camera_path::PathFrame> {
    let path = riverplanet::runtime::camera_path::CameraPath::load(file)
        .map_err(|e| usage(format!("--path {e}")))?;
    let count = path.frames.len();
    let k = number.map_or(count, |n| n as usize);
    if k > count {
        return Err(usage(format!(
            "--path-frame {k} must be in [1, {count}] ({} has {count} frames)",
            file.display()
        )));
    }
    Ok(path.frames[k - 1])
}

pub fn view(options: &ContextOptions, args: &ViewArgs) -> anyhow::Result<()> {
    let (config, _) = load_config(args.planet.config.as_deref())?;
    if let Some(path) = &args.screenshot {
        check_output("--screenshot", path, true)?;
    }
    if let Some(path) = &args.record {
        check_output("--record", path, false)?;
    }
    if let Some(eye) = args.eye {
        check_camera(eye, args.look_at, &config)?;
    }
    riverplanet::gpu::adapter::check_can_draw(options)?;
    let event_loop = riverplanet::render::viewer::event_loop()?;
    let seed = planet_seed(args.planet.seed, &config);
    let world = super::progress::build_world(&config, seed)?;
    let (eye, look_at) = match args.eye {
        Some(eye) => (eye, args.look_at),
        None => riverplanet::render::presets::camera(
            riverplanet::render::presets::Preset::Orbit,
            &world,
        )
        .unwrap_or((
            glam::DVec3::new(0.0, 0.0, config.planet.radius as f64 * 3.0),
            glam::DVec3::ZERO,
        )),
    };
    riverplanet::render::viewer::run(
        event_loop,
        &world,
        options,
        riverplanet::render::viewer::ViewerOptions {
            size: args.size,
            eye,
            look_at,
            frames: args.frames,
            screenshot: args.screenshot.clone(),
            screenshots: args.screenshots.clone(),
            record: args.record.clone(),
            overlay: args.overlay.on(),
            config: args.planet.config.clone(),
            water: args.water,
            atmosphere: args.atmosphere.on(),
            flowing_water: args.flowing_water.on(),
            water_in_mesh: args.water_in_mesh.on(),
        },
    )?;
    Ok(())
}
