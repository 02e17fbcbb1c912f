//! The viewer's screenshots: the view rendered offscreen at the window's size (with the overlay while it is
//! shown), written as PNG with a JSON sidecar beside it (`ViewerCamera::sidecar`: the seed, the camera and the
//! `render` command that makes the same image).

use super::{App, ViewerError};
use crate::{
    gpu::{swapchain::SWAPCHAIN_FORMAT, Access},
    render::target::Offscreen,
};

fn screenshot_error(path: &std::path::Path, e: impl std::fmt::Display) -> ViewerError {
    ViewerError::Screenshot {
        path: path.display().to_string(),
        message: e.to_string(),
    }
}

impl App<'_> {
    /// The window's size, or the requested one before the window has a swapchain.
    pub(super) fn screenshot_size(&self) -> [u32; 2] {
        self.swapchain
            .as_ref()
            .map_or(self.options.size, |s| [s.extent.width, s.extent.height])
    }

    /// Renders the current view offscreen at the window's size, writes it as PNG and beside it its JSON sidecar
    /// (`ViewerCamera::sidecar`).
    pub(super) fn screenshot(&mut self, path: &std::path::Path) -> Result<(), ViewerError> {
        let [w, h] = self.screenshot_size();
        let camera = self.camera(w, h);
        let Some(renderer) = &mut self.renderer else {
            return Ok(());
        };
        let overlay = &mut self.overlay;
        let target = Offscreen::with_format(self.ctx, w, h, SWAPCHAIN_FORMAT)?;
        let result = (|| {
            for _ in 0..50 {
                // The overlay as shown (what you see is what you get; U hides it).
                let mut draw_overlay = |rec: &mut crate::gpu::Recorder, extent| {
                    if let Some(overlay) = overlay.as_mut() {
                        if let Err(e) = overlay.record(rec, extent) {
                            log::error!("{e}");
                        }
                    }
                };
                let stats = renderer.render_with_overlay(
                    &camera,
                    &target.target(crate::render::SPACE_CLEAR),
                    Access::ColorAttachment,
                    (&[], &[]),
                    Some(&mut draw_overlay),
                )?;
                if stats.pending_patches == 0 && stats.fallback_patches == 0 {
                    break;
                }
            }
            target.read(self.ctx)
        })();
        let image = result?;
        crate::export::files::save_image(&image, path).map_err(|e| screenshot_error(path, e))?;
        let sidecar = path.with_extension("json");
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let bookmark = self.camera.sidecar(
            &name,
            (self.world.seed, self.frames),
            self.altitude(),
            [w, h],
            self.options.config.as_deref(),
        );
        let text =
            serde_json::to_string_pretty(&bookmark).map_err(|e| screenshot_error(&sidecar, e))?;
        crate::export::files::write_bytes(&sidecar, text.as_bytes())
            .map_err(|e| screenshot_error(&sidecar, e))?;
        println!(
            "screenshot: {} (camera: {})",
            path.display(),
            sidecar.display()
        );
        Ok(())
    }

    /// P: a screenshot into the screenshot folder, named by seed and frame.
    pub(super) fn screenshot_into_folder(&mut self) -> Result<(), ViewerError> {
        let dir = self.options.screenshots.clone();
        std::fs::create_dir_all(&dir).map_err(|e| screenshot_error(&dir, e))?;
        let path = dir.join(format!(
            "riverplanet-seed{}-frame{}.png",
            self.world.seed, self.frames
        ));
        self.screenshot(&path)
    }
}
