//! egui's triangles on this context (beyond the thesis: the viewer's overlay), through `egui-ash-renderer`: its
//! pipeline for dynamic rendering into the frame's colour attachment (no depth test), its vertex buffers one per
//! frame that can be in flight, its textures uploaded on the context's queue.

use egui::{epaint::ImageDelta, ClippedPrimitive, TextureId};
use egui_ash_renderer::{DynamicRendering, Options, Renderer};

use super::{
    frames::MAX_FRAMES_IN_FLIGHT, submit::transient_command_pool, vk, Context, GpuError, Recorder,
};

/// Draws the viewer's egui overlay (egui-ash-renderer) into a target, uploading its textures on its own pool.
pub struct OverlayRenderer {
    renderer: Renderer,
    pool: vk::CommandPool,
}

fn overlay_error(e: egui_ash_renderer::RendererError) -> GpuError {
    GpuError::Invalid(format!("the overlay's renderer: {e}"))
}

impl OverlayRenderer {
    /// For targets of `color` with a `depth` attachment (not tested against), in non-sRGB formats.
    pub fn new(ctx: &Context, color: vk::Format, depth: vk::Format) -> Result<Self, GpuError> {
        let renderer = Renderer::with_default_allocator(
            &ctx.instance,
            ctx.physical,
            ctx.device.clone(),
            DynamicRendering {
                color_attachment_format: color,
                depth_attachment_format: Some(depth),
            },
            Options {
                in_flight_frames: MAX_FRAMES_IN_FLIGHT,
                enable_depth_test: false,
                enable_depth_write: false,
                srgb_framebuffer: false,
            },
        )
        .map_err(overlay_error)?;
        Ok(Self {
            renderer,
            pool: transient_command_pool(ctx)?,
        })
    }

    /// Uploads new and changed textures (the queue is held meanwhile; the renderer waits for its copies).
    pub fn set_textures(
        &mut self,
        ctx: &Context,
        textures: &[(TextureId, ImageDelta)],
    ) -> Result<(), GpuError> {
        if textures.is_empty() {
            return Ok(());
        }
        let queue = ctx.queue();
        self.renderer
            .set_textures(*queue, self.pool, textures)
            .map_err(overlay_error)
    }

    /// Frees textures egui no longer uses, once the frames in flight are done with them.
    pub fn free_textures(&mut self, ctx: &Context, ids: &[TextureId]) -> Result<(), GpuError> {
        if ids.is_empty() {
            return Ok(());
        }
        ctx.wait_idle()?;
        self.renderer.free_textures(ids).map_err(overlay_error)
    }

    /// Records `primitives` into `rec`'s current rendering of `extent`.
    pub fn record(
        &mut self,
        rec: &mut Recorder,
        extent: vk::Extent2D,
        pixels_per_point: f32,
        primitives: &[ClippedPrimitive],
    ) -> Result<(), GpuError> {
        self.renderer
            .cmd_draw(rec.cmd, extent, pixels_per_point, primitives)
            .map_err(overlay_error)
    }

    /// After the device is idle.
    pub fn destroy(self, ctx: &Context) {
        drop(self.renderer);
        // SAFETY: the device is idle; nothing uses the pool's command buffers.
        unsafe { ctx.device.destroy_command_pool(self.pool, None) };
    }
}
