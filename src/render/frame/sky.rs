//! The atmosphere on the GPU (beyond the thesis; docs/rendering.md, "Atmosphere"): the transmittance table as a
//! bindless texture that every pass reads, and the sky pass that draws the air where no surface is.

use super::{FramePush, Renderer};
use crate::{
    gpu::{
        bindless::{Bindless, Slot},
        pipeline::{Blend, GraphicsDesc, GraphicsPipeline},
        Access, Buffer, Context, DescriptorSet, DescriptorSetLayout, Extent2D, Format, GpuError,
        Image, ImageDesc, ImageUse, Recorder,
    },
    planet::atmosphere::Atmosphere,
    render::mesh::{dome_mesh, index_buffer},
    shaders,
};

/// Rings of the sky dome (glsl/sky.vert), from the lowest terrain's sphere to the top of the shell.
const RINGS: u32 = 48;
/// Segments of every ring.
const SEGMENTS: u32 = 96;

pub(super) struct Sky {
    /// The atmosphere's table, held while `slot` points at it (retired as the sky drops).
    _table: Image,
    slot: Slot,
    pipeline: GraphicsPipeline,
    /// The dome's triangles: vertex `ring * (SEGMENTS + 1) + segment`.
    dome: Buffer,
    dome_indices: u32,
    /// atmosphere-height, as the shaders take it.
    pub(super) height: f32,
}

impl Sky {
    /// Computes and uploads the transmittance table of `atmosphere` and builds the sky pipeline.
    pub(super) fn new(
        ctx: &Context,
        bindless: &mut Bindless,
        atmosphere: &Atmosphere,
        set_layouts: &[DescriptorSetLayout],
        formats: (Format, Format),
    ) -> Result<Self, GpuError> {
        let table = atmosphere.transmittance_table();
        let image = ctx.create_image(&ImageDesc {
            name: "atmosphere transmittance",
            extent: Extent2D {
                width: table.width,
                height: table.height,
            },
            layers: 1,
            format: Format::R32G32B32A32_SFLOAT,
            uses: &[Access::GraphicsSampled, Access::TransferWrite],
            array: true,
        })?;
        ctx.run_and_wait("upload atmosphere transmittance", |rec| {
            rec.image_barriers(
                &[&image],
                ImageUse {
                    before: &[Access::Nothing],
                    after: &[Access::TransferWrite],
                    discard: true,
                },
            );
            rec.upload_image_layer(&image, 0, bytemuck::cast_slice(&table.texels))?;
            rec.image_barriers(
                &[&image],
                ImageUse {
                    before: &[Access::TransferWrite],
                    after: &[Access::GraphicsSampled],
                    discard: false,
                },
            );
            Ok(())
        })?;
        let indices = dome_mesh(RINGS, SEGMENTS);
        let dome = index_buffer(ctx, "sky dome indices", &indices)?;
        let slot = bindless.allocate(ctx).ok_or_else(|| {
            GpuError::Invalid("no bindless slot left for the atmosphere".to_string())
        })?;
        bindless.write(ctx, slot, &image, false);
        // The dome lies at depth 0: only pixels no surface covered pass the depth test.
        let pipeline = GraphicsPipeline::new(
            ctx,
            &GraphicsDesc {
                name: "sky",
                vertex: shaders::SKY_VERT,
                geometry: None,
                fragment: shaders::SKY_FRAG,
                set_layouts,
                push_constant_bytes: std::mem::size_of::<FramePush>() as u32,
                specialization: bytemuck::bytes_of(&[RINGS, SEGMENTS]),
                color_format: formats.0,
                depth_format: formats.1,
                depth_write: false,
                depth_test: true,
                blend: Blend::Transmit,
                wireframe: false,
                cull_back_faces: false,
            },
        )?;
        Ok(Self {
            _table: image,
            slot,
            pipeline,
            dome,
            dome_indices: indices.len() as u32,
            height: (atmosphere.top - atmosphere.bottom) as f32,
        })
    }

    /// The table's slot, as the shaders take it.
    pub(super) fn slot(&self) -> f32 {
        self.slot.0 as f32
    }

    /// Draws the sky (inside the frame's rendering scope).
    pub(super) fn record(&self, rec: &mut Recorder, sets: &[DescriptorSet], push: &[u8]) {
        rec.draw_indexed(
            &self.pipeline,
            sets,
            push,
            &self.dome,
            0..self.dome_indices,
            0..1,
        );
    }

    pub(super) fn destroy(self, ctx: &Context, bindless: &mut Bindless) {
        self.pipeline.destroy(ctx);
        bindless.release(ctx, self.slot);
    }
}

impl Renderer<'_> {
    /// The atmosphere this frame draws: the planet's, unless it has none or `atmosphere_on` is off.
    pub(super) fn sky(&self) -> Option<&Sky> {
        self.sky.as_ref().filter(|_| self.atmosphere_on)
    }
}
