//! Render one frame headless into a PNG from Rust: a Vulkan context (any GPU, or Mesa lavapipe without one), a
//! planet, a renderer and an offscreen target, the camera from one of the planet's presets.
//!
//! `cargo run --release --example render_png [CONFIG.xml] [OUT.png] [SEED]` (default: config/planet.xml, river.png,
//! the configuration's seed).
//! `tools/env.sh`'s `use_lavapipe` selects lavapipe where no GPU is installed.

use anyhow::Context as _;
use riverplanet::{
    config::Config,
    gpu::{Context, ContextOptions},
    render::{
        presets::{self, Preset},
        target::{Offscreen, COLOR_FORMAT, DEPTH_FORMAT},
        Renderer,
    },
    runtime::camera::{near_plane, Camera},
    world::World,
};

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let path = args.next().unwrap_or_else(|| "config/planet.xml".into());
    let out = args.next().unwrap_or_else(|| "river.png".into());
    let config = Config::load(path.as_ref()).with_context(|| format!("reading {path}"))?;
    // The device first: one that cannot draw is refused before the planet is built.
    let ctx = Context::new(&ContextOptions {
        draws: true,
        ..ContextOptions::from_env()
    })?;
    let seed = match args.next() {
        Some(s) => s
            .parse()
            .with_context(|| format!("seed {s:?} is not a whole number"))?,
        None => config.resolve_seed(),
    };
    let world = World::build(&config, seed)?;
    let (eye, look_at) =
        presets::camera(Preset::River, &world).context("this planet has no river")?;
    let (width, height) = (960, 540);
    // The near plane from the height above the ground below the eye (close enough for depth precision there).
    let planet = &world.planet;
    let ground = planet.height_at(eye.normalize()).max(planet.sea_level) as f64;
    let near = near_plane(eye.length() - planet.radius - ground);
    // A 45-degree vertical field of view, as `riverplanet render` uses.
    let camera = Camera::look_at(eye, look_at, 45.0, width as f64 / height as f64, near);
    let target = Offscreen::new(&ctx, width, height)?;
    let mut renderer = Renderer::new(
        &ctx,
        &world.planet,
        &world.network,
        &config,
        COLOR_FORMAT,
        DEPTH_FORMAT,
    )?;
    // Frames until every visible patch has its heights and river data (at most 60).
    let (stats, frames) =
        renderer.render_until_streamed(&camera, &target.target([0.02, 0.03, 0.06, 1.0]), 60)?;
    target.read(&ctx)?.save(&out)?;
    println!(
        "{out}: seed {seed}, {width}x{height} on {}, {frames} frames, {} patches drawn, deepest level {}",
        ctx.adapter.name, stats.visible_patches, stats.deepest_level
    );
    Ok(())
}
