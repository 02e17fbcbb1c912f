//! Beyond the thesis: the vertex cache (docs/rendering.md, "The vertex cache"). Once a frame, a compute pass
//! (glsl/vertex_cache.comp) computes every grid vertex of every drawn patch as the thesis's vertex shader would
//! (Section 8.2: heights blended with the river data, morphed, placed on the sphere, its normal and, beyond the
//! thesis, the air in front of it); the terrain and water passes' vertex shaders then read it. Lavapipe runs compute
//! on all its threads but vertex shaders on one, and both passes shade the same vertices, so each is computed once,
//! in parallel. Patches beyond the cache's size, or all with `Renderer::vertex_cache` off, compute their vertices
//! in the vertex shaders, the thesis's way.
//!
//! The pass also finds which drawn quadrants have water: the water pass draws a cached patch through four
//! indirect draws, one per quadrant, that the pass gives an instance only where a vertex is in a river's basin or
//! below sea level.

use std::mem::size_of;

use super::FramePush;
use crate::{
    gpu::{
        pipeline::{ComputeDesc, ComputePipeline},
        Access, Buffer, BufferDesc, Context, DescriptorSet, DescriptorSetLayout,
        DrawIndexedIndirectCommand, GpuError, MemoryLocation, Recorder,
    },
    render::mesh::QuadrantMesh,
    shaders,
};

/// Bytes of one cached vertex (`CachedVertex` in glsl/terrain_vertex.glsl).
const VERTEX_BYTES: u64 = 64;

/// The most bytes one frame's cache takes (64 MiB: 963 patches of 33 x 33 vertices); patches beyond it are
/// computed in the vertex shaders.
const MAX_BYTES: u64 = 64 << 20;

/// Grid vertices per workgroup (`local_size_x` of vertex_cache.comp).
const WORKGROUP: u32 = 64;

pub(super) struct VertexCache {
    pipeline: ComputePipeline,
}

impl VertexCache {
    pub(super) fn new(ctx: &Context, layouts: &[DescriptorSetLayout]) -> Result<Self, GpuError> {
        let pipeline = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "vertex cache",
                spirv: shaders::VERTEX_CACHE_COMP,
                set_layouts: layouts,
                push_constant_bytes: std::mem::size_of::<FramePush>() as u32,
                specialization: &[],
                full_subgroups: None,
            },
        )?;
        Ok(Self { pipeline })
    }

    /// How many of `drawn` patches of `n` x `n` vertices one frame caches.
    pub(super) fn patches(drawn: usize, n: u32) -> usize {
        drawn.min((MAX_BYTES / (n as u64 * n as u64 * VERTEX_BYTES)) as usize)
    }

    /// A cache for `patches` patches of `n` x `n` vertices (at least one vertex's bytes, so it can be bound).
    pub(super) fn buffer(ctx: &Context, patches: usize, n: u32) -> Result<Buffer, GpuError> {
        ctx.create_buffer(&BufferDesc {
            name: "vertex cache",
            size: (patches as u64 * n as u64 * n as u64 * VERTEX_BYTES).max(VERTEX_BYTES),
            uses: &[Access::ComputeWrite, Access::VertexShaderRead],
            location: MemoryLocation::GpuOnly,
        })
    }

    /// The water pass's indirect draws of `patches` cached patches: per patch (instance k) its four quadrants'
    /// grid cells, with no instance until the cache's pass finds water there. At least one draw's bytes.
    pub(super) fn water_draws(
        ctx: &Context,
        patches: usize,
        quadrants: &[QuadrantMesh; 4],
    ) -> Result<Buffer, GpuError> {
        // VkDrawIndexedIndirectCommand: index count, instance count, first index, vertex offset, first instance.
        let draws: Vec<[u32; 5]> = (0..patches as u32)
            .flat_map(|k| {
                quadrants
                    .iter()
                    .map(move |q| [q.grid.end - q.grid.start, 0, q.grid.start, 0, k])
            })
            .collect();
        let mut buffer = ctx.create_buffer(&BufferDesc {
            name: "water draws",
            size: (draws.len().max(1) * size_of::<DrawIndexedIndirectCommand>()) as u64,
            uses: &[
                Access::ComputeRead,
                Access::ComputeWrite,
                Access::IndirectCommands,
            ],
            location: MemoryLocation::CpuToGpu,
        })?;
        buffer.write(0, &draws)?;
        Ok(buffer)
    }

    /// Records the pass that fills `cache` and `water_draws` for instances 0 .. `patches` (which `sets` bind), and
    /// makes them visible to the vertex shaders and the indirect draws.
    pub(super) fn record(
        &self,
        rec: &mut Recorder,
        (sets, push): (&[DescriptorSet], &[u8]),
        (cache, water_draws): (&Buffer, &Buffer),
        patches: usize,
        n: u32,
    ) {
        if patches == 0 {
            return;
        }
        rec.dispatch(
            &self.pipeline,
            sets,
            push,
            [(n * n).div_ceil(WORKGROUP), patches as u32, 1],
        );
        rec.buffer_barrier(cache, &[Access::ComputeWrite], &[Access::VertexShaderRead]);
        rec.buffer_barrier(
            water_draws,
            &[Access::ComputeRead, Access::ComputeWrite],
            &[Access::IndirectCommands],
        );
    }

    pub(super) fn destroy(self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
