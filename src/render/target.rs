//! An offscreen colour + depth target, and reading it back into an image.

use crate::gpu::{
    pipeline::RenderTarget, Access, BufferDesc, Context, Extent2D, Format, GpuError, Image,
    ImageDesc, MemoryLocation, Recorder,
};

/// The offscreen targets' colour format.
pub const COLOR_FORMAT: Format = Format::R8G8B8A8_UNORM;
/// Every target's depth format (reversed Z, runtime/camera.rs).
pub const DEPTH_FORMAT: Format = Format::D32_SFLOAT;

/// Colour and depth images of one size.
pub struct Offscreen {
    /// The colour image.
    pub color: Image,
    /// The depth image.
    pub depth: Image,
}

impl Offscreen {
    /// A target in `COLOR_FORMAT`.
    pub fn new(ctx: &Context, width: u32, height: u32) -> Result<Self, GpuError> {
        Self::with_format(ctx, width, height, COLOR_FORMAT)
    }

    /// A target in `format` (RGBA8 or BGRA8 UNORM), to match pipelines made for a swapchain.
    pub fn with_format(
        ctx: &Context,
        width: u32,
        height: u32,
        format: Format,
    ) -> Result<Self, GpuError> {
        let extent = Extent2D { width, height };
        let color = ctx.create_image(&ImageDesc {
            name: "offscreen colour",
            extent,
            layers: 1,
            format,
            uses: &[Access::ColorAttachment, Access::TransferRead],
            array: false,
        })?;
        let depth = create_depth(ctx, extent)?;
        Ok(Self { color, depth })
    }

    /// The two images as a target cleared to `clear_color`.
    pub fn target(&self, clear_color: [f32; 4]) -> RenderTarget {
        RenderTarget::new(&self.color, &self.depth, clear_color)
    }

    /// Reads the colour image (after a frame left it in COLOR_ATTACHMENT_OPTIMAL) as RGBA8.
    pub fn read(&self, ctx: &Context) -> Result<image::RgbaImage, GpuError> {
        let (w, h) = (self.color.extent.width, self.color.extent.height);
        let buffer = ctx.create_buffer(&BufferDesc {
            name: "offscreen readback",
            size: (w * h * 4) as u64,
            uses: &[Access::TransferWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })?;
        let result = ctx.run_and_wait("read offscreen colour", |rec: &mut Recorder| {
            rec.use_images(&[&self.color], &[Access::TransferRead]);
            rec.copy_image_to_buffer(&self.color, &buffer, 0);
            rec.use_buffer(&buffer, &[Access::HostRead]);
            rec.use_images(&[&self.color], &[Access::ColorAttachment]);
            Ok(())
        });
        let image = result.and_then(|()| {
            let bytes = buffer
                .mapped()
                .ok_or_else(|| GpuError::Invalid("readback not host-visible".into()))?;
            let mut pixels = bytes.to_vec();
            if self.color.format == Format::B8G8R8A8_UNORM {
                pixels.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
            }
            image::RgbaImage::from_raw(w, h, pixels)
                .ok_or_else(|| GpuError::Invalid("readback size mismatch".into()))
        });
        image
    }
}

/// A depth image for a target of `extent`.
pub fn create_depth(ctx: &Context, extent: Extent2D) -> Result<Image, GpuError> {
    ctx.create_image(&ImageDesc {
        name: "depth",
        extent,
        layers: 1,
        format: DEPTH_FORMAT,
        uses: &[Access::DepthAttachment],
        array: false,
    })
}
