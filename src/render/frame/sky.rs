//! The atmosphere on the GPU (beyond the thesis; docs/rendering.md, "Atmosphere"): the transmittance table as a
//! bindless texture that every pass reads, and the sky pass that draws the air where no surface is.

use super::{vertex_cache::frame_compute, Renderer};
use crate::{
    gpu::{
        bindless::{Bindless, Slot},
        pipeline::{Blend, ComputePipeline, GraphicsDesc, GraphicsPipeline},
        Access, Buffer, BufferDesc, Context, DescriptorSet, DescriptorSetLayout, Extent2D, Format,
        GpuError, Image, ImageDesc, MemoryLocation, Recorder,
    },
    planet::atmosphere::Atmosphere,
    render::mesh::{dome_mesh, index_buffer},
    shader_types::FramePush,
    shaders,
};

/// Rings of the sky dome (glsl/sky_dome.comp), from the lowest terrain's sphere to the top of the shell.
const RINGS: u32 = 48;
/// Segments of every ring.
const SEGMENTS: u32 = 96;
/// The dome's vertices: `RINGS + 1` rings of `SEGMENTS + 1`.
const DOME_VERTICES: u32 = (RINGS + 1) * (SEGMENTS + 1);
/// Bytes of one dome vertex (`SkyVertex` in glsl/sky_vertex.glsl).
const DOME_VERTEX_BYTES: u64 = 64;
/// Dome vertices per workgroup (`local_size_x` of sky_dome.comp).
const WORKGROUP: u32 = 64;

pub(super) struct Sky {
    /// The atmosphere's table, held while `slot` points at it (retired as the sky drops).
    _table: Image,
    slot: Slot,
    pipeline: GraphicsPipeline,
    /// Marches the dome's vertices once a frame.
    dome_pipeline: ComputePipeline,
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
            uses: &[
                Access::GraphicsSampled,
                Access::ComputeSampled,
                Access::TransferWrite,
            ],
            array: true,
        })?;
        ctx.run_and_wait("upload atmosphere transmittance", |rec| {
            rec.overwrite_images(&[&image], &[Access::TransferWrite]);
            rec.upload_image_layer(&image, 0, bytemuck::cast_slice(&table.texels))?;
            // Sampled by the terrain's shaders and by the sky dome's compute pass.
            rec.use_images(
                &[&image],
                &[Access::GraphicsSampled, Access::ComputeSampled],
            );
            Ok(())
        })?;
        let indices = dome_mesh(RINGS, SEGMENTS);
        let dome = index_buffer(ctx, "sky dome indices", &indices)?;
        let slot = bindless.allocate(ctx).ok_or_else(|| {
            GpuError::Invalid("no bindless slot left for the atmosphere".to_string())
        })?;
        bindless.write(ctx, slot, &image, false);
        let dome_pipeline = frame_compute(
            ctx,
            set_layouts,
            "sky dome",
            shaders::SKY_DOME_COMP,
            bytemuck::bytes_of(&[RINGS, SEGMENTS]),
        )?;
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
                specialization: &[],
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
            dome_pipeline,
            dome,
            dome_indices: indices.len() as u32,
            height: (atmosphere.top - atmosphere.bottom) as f32,
        })
    }

    /// The table's slot, as the shaders take it.
    pub(super) fn slot(&self) -> f32 {
        self.slot.0 as f32
    }

    /// A frame's dome vertices, for `record_dome` to fill and the sky pass to read (binding 6 of the instance set).
    pub(super) fn dome_vertices(ctx: &Context) -> Result<Buffer, GpuError> {
        ctx.create_buffer(&BufferDesc {
            name: "sky dome vertices",
            size: DOME_VERTICES as u64 * DOME_VERTEX_BYTES,
            uses: &[Access::ComputeWrite, Access::VertexShaderRead],
            location: MemoryLocation::GpuOnly,
        })
    }

    /// Marches the dome's vertices into `vertices` (bound in `sets`) for this frame's camera, before the
    /// rendering scope, and makes them visible to the sky pass.
    pub(super) fn record_dome(
        &self,
        rec: &mut Recorder,
        (sets, push): (&[DescriptorSet], &[u8]),
        vertices: &Buffer,
    ) {
        rec.use_buffer(vertices, &[Access::ComputeWrite]);
        rec.dispatch(
            &self.dome_pipeline,
            sets,
            push,
            [DOME_VERTICES.div_ceil(WORKGROUP), 1, 1],
        );
        rec.use_buffer(vertices, &[Access::VertexShaderRead]);
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
}

impl Renderer<'_> {
    /// The atmosphere this frame draws: the planet's, unless it has none or `atmosphere_on` is off.
    pub(super) fn sky(&self) -> Option<&Sky> {
        self.sky.as_ref().filter(|_| self.atmosphere_on)
    }
}
