//! Frames in flight: the renderer records a frame while the one before is still queued, hands GPU times back when
//! they arrive, and a 100-frame flight passes synchronization validation.

mod common;

use std::sync::OnceLock;

use riverplanet::{bench::path::Flight, config::Config, render::target::Offscreen, world::World};

fn world() -> &'static World {
    static WORLD: OnceLock<World> = OnceLock::new();
    WORLD.get_or_init(|| World::build(&Config::default(), 1).unwrap())
}

#[test]
fn a_flight_keeps_two_frames_in_flight_and_passes_synchronization_validation() {
    let Some(ctx) = common::gpu_with_synchronization_validation() else {
        return;
    };
    let world = world();
    let (w, h) = (320, 180);
    let target = Offscreen::new(ctx, w, h).unwrap();
    let mut renderer = common::renderer(ctx, world);
    assert_eq!(
        renderer.frames_in_flight(),
        2,
        "two frames in flight by default"
    );
    let frames = 100;
    let flight = Flight::new(world, frames, 1.0, w as f64 / h as f64);
    let mut timed = Vec::new();
    let mut returned_early = 0;
    for frame in 0..frames {
        let stats = common::render_frame(&mut renderer, &flight.camera(world, frame), &target);
        // The CPU never waited for the previous frame before submitting this one, and returned before the GPU
        // finished this one.
        assert!(
            stats.synchronized_frame == 0 || stats.synchronized_frame + 2 <= stats.frame,
            "frame {}: the CPU had waited for frame {} before submitting it",
            stats.frame,
            stats.synchronized_frame
        );
        // Whether the GPU was still busy with it when the call returned depends on how fast the GPU was; the
        // CPU's not waiting (above) does not.
        returned_early += usize::from(stats.frames_in_flight >= 1);
        timed.extend(renderer.take_gpu_times().into_iter().map(|t| t.frame));
    }
    renderer.finish().unwrap();
    timed.extend(renderer.take_gpu_times().into_iter().map(|t| t.frame));
    // Every frame's GPU times arrive exactly once, in order.
    assert_eq!(timed, (1..=frames as u64).collect::<Vec<_>>());
    assert!(
        returned_early >= frames as usize / 4,
        "only {returned_early} of {frames} frames were still on the GPU when render returned"
    );
    drop(target);
    eprintln!(
        "synchronization hazards waived through the bindless set's runtime arrays: {}",
        ctx.waived_validation_messages()
    );
    common::assert_no_validation_errors(ctx);
}

#[test]
fn one_frame_in_flight_waits_for_every_frame_as_the_thesis() {
    let Some(ctx) = common::gpu_with_synchronization_validation() else {
        return;
    };
    let world = world();
    let target = Offscreen::new(ctx, 160, 90).unwrap();
    let mut renderer = common::renderer(ctx, world);
    renderer.set_frames_in_flight(1).unwrap();
    let flight = Flight::new(world, 10, 1.0, 16.0 / 9.0);
    for frame in 0..10 {
        let stats = common::render_frame(&mut renderer, &flight.camera(world, frame), &target);
        assert_eq!(stats.synchronized_frame + 1, stats.frame);
    }
    assert!(renderer.set_frames_in_flight(4).is_err(), "at most three");
    drop(target);
    common::assert_no_validation_errors(ctx);
}
