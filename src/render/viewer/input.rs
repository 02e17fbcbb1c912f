//! The viewer's keys: the held ones move and turn the camera every frame, the pressed ones switch what is drawn
//! or act (screenshot, bookmarks, home).

use glam::DVec3;
use winit::{event_loop::ActiveEventLoop, keyboard::KeyCode};

use super::{home, App};
use crate::{
    config::LodRule,
    kernel::gpu::KernelVariant,
    render::{viewer_camera::CameraMode, ViewMode},
};

impl App<'_> {
    pub(super) fn update_camera(&mut self, dt: f64) {
        let fast =
            self.keys.contains(&KeyCode::ShiftLeft) || self.keys.contains(&KeyCode::ShiftRight);
        let speed = self.altitude().max(0.5) * if fast { 3.0 } else { 0.8 };
        let (f, r, u) = (
            self.camera.forward,
            self.camera.right(),
            self.camera.radial(),
        );
        let mut motion = DVec3::ZERO;
        for (key, dir) in [
            (KeyCode::KeyW, f),
            (KeyCode::KeyS, -f),
            (KeyCode::KeyD, r),
            (KeyCode::KeyA, -r),
            (KeyCode::KeyE, u),
            (KeyCode::KeyQ, -u),
        ] {
            if self.keys.contains(&key) {
                motion += dir;
            }
        }
        self.camera.position += motion * speed * dt;
        self.keep_above_ground();
        let turn = 1.2 * dt;
        for (key, yaw, pitch) in [
            (KeyCode::ArrowLeft, -turn, 0.0),
            (KeyCode::ArrowRight, turn, 0.0),
            (KeyCode::ArrowUp, 0.0, turn),
            (KeyCode::ArrowDown, 0.0, -turn),
        ] {
            if self.keys.contains(&key) {
                self.camera.turn(yaw, pitch);
            }
        }
    }

    pub(super) fn key(&mut self, event_loop: &ActiveEventLoop, code: KeyCode) {
        let Some(renderer) = &mut self.renderer else {
            return;
        };
        match code {
            KeyCode::Escape => event_loop.exit(),
            // Home: back to the start view, wherever the flight went.
            KeyCode::KeyH => {
                self.camera = home(&self.options, self.radius());
                self.keep_above_ground();
            }
            KeyCode::KeyB => {
                let altitude = self.altitude();
                match self.paths.bookmark(&self.camera, altitude) {
                    Ok(k) => println!("bookmark {k}: key {k} flies back here"),
                    Err(e) => log::error!("cannot save the bookmark: {e}"),
                }
            }
            KeyCode::Digit1
            | KeyCode::Digit2
            | KeyCode::Digit3
            | KeyCode::Digit4
            | KeyCode::Digit5
            | KeyCode::Digit6
            | KeyCode::Digit7
            | KeyCode::Digit8
            | KeyCode::Digit9 => {
                let k = code as usize - KeyCode::Digit0 as usize;
                if let Some(camera) = self.paths.recall(k, self.radius()) {
                    self.camera = camera;
                    self.keep_above_ground();
                }
            }
            KeyCode::KeyC => {
                self.camera.mode = match self.camera.mode {
                    CameraMode::Fly => CameraMode::Orbit,
                    CameraMode::Orbit => CameraMode::Fly,
                }
            }
            KeyCode::KeyU => {
                if let Some(overlay) = &mut self.overlay {
                    overlay.visible = !overlay.visible;
                }
            }
            KeyCode::KeyM => renderer.water_mode = renderer.water_mode.next(),
            KeyCode::KeyT => renderer.atmosphere_on = !renderer.atmosphere_on,
            KeyCode::KeyF => renderer.wireframe_on = !renderer.wireframe_on,
            KeyCode::KeyL => {
                renderer.view_mode = if renderer.view_mode == ViewMode::Lod {
                    ViewMode::Shaded
                } else {
                    ViewMode::Lod
                }
            }
            KeyCode::KeyR => {
                renderer.view_mode = if renderer.view_mode == ViewMode::PaintedRed {
                    ViewMode::Shaded
                } else {
                    ViewMode::PaintedRed
                }
            }
            KeyCode::KeyZ => renderer.freeze_lod = !renderer.freeze_lod,
            KeyCode::KeyO => renderer.morphing = !renderer.morphing,
            KeyCode::KeyG => {
                renderer.lod_rule = match renderer.lod_rule {
                    LodRule::ScreenSpaceError => LodRule::Distance,
                    LodRule::Distance => LodRule::ScreenSpaceError,
                }
            }
            KeyCode::KeyK => {
                renderer.variant = match renderer.variant {
                    KernelVariant::Simple => KernelVariant::Tiled,
                    KernelVariant::Tiled => KernelVariant::Simple,
                }
            }
            KeyCode::KeyP => {
                if let Err(e) = self.screenshot_into_folder() {
                    self.fail(event_loop, e);
                }
            }
            _ => {}
        }
    }
}
