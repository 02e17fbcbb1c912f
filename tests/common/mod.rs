//! Shared GPU test harness: one device per test binary, validation on, and a canary that fails a test when the
//! validation layer reported any error. Without a driver a GPU test prints why and skips, unless
//! `RIVERPLANET_REQUIRE_GPU=1` (tools/test and CI set it), which turns the skip into a failure.

#![allow(dead_code)]

use std::sync::OnceLock;

use riverplanet::{
    config::Config,
    gpu::{Access, Context, ContextOptions},
    render::{
        target::{Offscreen, COLOR_FORMAT, DEPTH_FORMAT},
        FrameStats, Renderer,
    },
    runtime::camera::Camera,
    world::World,
};

static CONTEXT: OnceLock<Result<Context, String>> = OnceLock::new();

/// A context with validation on (unless `RIVERPLANET_VALIDATION=0`), and synchronization validation too if asked.
fn new_context(synchronization: bool) -> Result<Context, String> {
    let _ = env_logger::builder().is_test(true).try_init();
    let mut options = ContextOptions::from_env();
    options.validation = std::env::var("RIVERPLANET_VALIDATION").map_or(true, |v| v != "0");
    options.synchronization_validation |= synchronization && options.validation;
    Context::new(&options).map_err(|e| e.to_string())
}

/// A context of the calling test's own, for a test that counts what the context holds (the shared one is used by
/// the binary's other tests at the same time), or `None` where `gpu` skips.
pub fn own_gpu() -> Option<Context> {
    gpu()?;
    Some(new_context(false).expect("a second context on the device"))
}

/// The shared context, or `None` (test skipped) when no usable device exists and a GPU is not required.
pub fn gpu() -> Option<&'static Context> {
    shared(&CONTEXT, false)
}

/// As `gpu`, with synchronization validation on as well (use in a test binary of its own: it is slow).
pub fn gpu_with_synchronization_validation() -> Option<&'static Context> {
    static SYNC: OnceLock<Result<Context, String>> = OnceLock::new();
    shared(&SYNC, true)
}

fn shared(
    cell: &'static OnceLock<Result<Context, String>>,
    synchronization: bool,
) -> Option<&'static Context> {
    let result = cell.get_or_init(|| new_context(synchronization));
    let required = std::env::var("RIVERPLANET_REQUIRE_GPU").is_ok_and(|v| v == "1");
    match result {
        Ok(ctx) => {
            if required {
                assert!(
                    ctx.validation_enabled(),
                    "RIVERPLANET_REQUIRE_GPU=1 but the validation layer is not active (install vulkan-validationlayers)"
                );
            }
            Some(ctx)
        }
        Err(e) if required => panic!("RIVERPLANET_REQUIRE_GPU=1 but no usable Vulkan device: {e}"),
        Err(e) => {
            eprintln!("skipping GPU test: {e}");
            None
        }
    }
}

/// Fails the calling test if the validation layer reported errors so far (in this binary).
pub fn assert_no_validation_errors(ctx: &Context) {
    let errors = ctx.validation_errors();
    assert!(
        errors.is_empty(),
        "validation errors:\n{}",
        errors.join("\n")
    );
}

/// A renderer of `world` for the offscreen target's formats.
pub fn renderer<'a>(ctx: &'a Context, world: &'a World) -> Renderer<'a> {
    renderer_with(ctx, world, &world.config)
}

/// A renderer of `world`'s planet and rivers with `config`'s rendering settings, for the offscreen target's
/// formats.
pub fn renderer_with<'a>(ctx: &'a Context, world: &'a World, config: &'a Config) -> Renderer<'a> {
    Renderer::new(
        ctx,
        &world.planet,
        &world.network,
        config,
        COLOR_FORMAT,
        DEPTH_FORMAT,
    )
    .unwrap()
}

/// Renders one frame of `camera` into `target` (cleared to black), without waiting for it.
pub fn render_frame(renderer: &mut Renderer, camera: &Camera, target: &Offscreen) -> FrameStats {
    renderer
        .render(
            camera,
            &target.target([0.0, 0.0, 0.0, 1.0]),
            Access::ColorAttachment,
            &[],
            &[],
        )
        .unwrap()
}

/// config/earth.xml's world, its patches streamed in as fast as the device goes (no generation budget): for tests
/// of what the ground view draws, not of budgets.
pub fn earth_streaming_at_once() -> World {
    let mut config =
        Config::load(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/earth.xml"))
            .unwrap();
    config.rendering.generation_budget_ms = 1e6;
    World::build(&config, config.resolve_seed()).unwrap()
}
