//! Beyond the thesis: the vertex cache (docs/rendering.md, "The vertex cache"). Once a frame, a compute pass
//! (glsl/vertex_cache.comp) computes every grid vertex of every drawn patch as the thesis's vertex shader would
//! (Section 8.2: heights blended with the river data, morphed, placed on the sphere, its normal and, beyond the
//! thesis, the air in front of it); the terrain and water passes' vertex shaders then read it. Lavapipe runs compute
//! on all its threads but vertex shaders on one, and both passes shade the same vertices, so each is computed once,
//! in parallel. Patches beyond the cache's size, or all with `Renderer::vertex_cache` off, compute their vertices
//! in the vertex shaders, the thesis's way.
//!
//! A second pass (glsl/water_triangles.comp) then makes the water pass's geometry-shader choice for the cached
//! patches from the cache (docs/rendering.md, "Water without the geometry shader"): per drawn quadrant, the list of
//! triangles that get water and the indirect draw of that list, which the water pass draws without a geometry
//! shader (glsl/water_surface.vert).

use std::mem::size_of;

use crate::{
    gpu::{
        pipeline::{ComputeDesc, ComputePipeline},
        Access, Buffer, BufferDesc, Context, DescriptorSet, DescriptorSetLayout,
        DrawIndexedIndirectCommand, GpuError, MemoryLocation, Recorder,
    },
    render::mesh::QuadrantMesh,
    shader_types::FramePush,
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
    water_triangles: ComputePipeline,
}

impl VertexCache {
    pub(super) fn new(ctx: &Context, layouts: &[DescriptorSetLayout]) -> Result<Self, GpuError> {
        let pipeline = |name, spirv| frame_compute(ctx, layouts, name, spirv, &[]);
        Ok(Self {
            pipeline: pipeline("vertex cache", shaders::VERTEX_CACHE_COMP)?,
            water_triangles: pipeline("water triangles", shaders::WATER_TRIANGLES_COMP)?,
        })
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

    /// The water pass's indirect draws of `patches` cached patches, as the water-triangle pass finds them: per
    /// patch (instance k) its four quadrants' grid cells in the mesh, which that pass turns into the draws of
    /// their water triangles. At least one draw's bytes.
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

    /// The water triangles' indices of `patches` cached patches of `n` x `n` vertices: room for every grid cell
    /// of every quadrant (`6 m^2` indices for `m = (n - 1) / 2` cells a side, as water_triangles.comp lays them
    /// out). At least one index's bytes.
    pub(super) fn water_indices(ctx: &Context, patches: usize, n: u32) -> Result<Buffer, GpuError> {
        let m = (n as u64 - 1) / 2;
        ctx.create_buffer(&BufferDesc {
            name: "water indices",
            size: (patches as u64 * 4 * 6 * m * m * 4).max(4),
            uses: &[Access::ComputeWrite, Access::IndexRead],
            location: MemoryLocation::GpuOnly,
        })
    }

    /// Records the passes that fill `cache`, then, for a frame with the water pass, its `water` draws and indices
    /// from it (all bound in `sets`), for instances 0 .. `patches`, and makes them visible to the vertex shaders and
    /// the indexed indirect draws.
    pub(super) fn record(
        &self,
        rec: &mut Recorder,
        (sets, push): (&[DescriptorSet], &[u8]),
        cache: &Buffer,
        patches: usize,
        n: u32,
        water: Option<(&Buffer, &Buffer)>,
    ) {
        if patches == 0 {
            return;
        }
        rec.use_buffer(cache, &[Access::ComputeWrite]);
        rec.dispatch(
            &self.pipeline,
            sets,
            push,
            [(n * n).div_ceil(WORKGROUP), patches as u32, 1],
        );
        rec.use_buffer(cache, &[Access::ComputeRead, Access::VertexShaderRead]);
        let Some((draws, indices)) = water else {
            return;
        };
        // The draws' instance counts are read and written (counted up), the indices written.
        rec.use_buffer(draws, &[Access::ComputeRead, Access::ComputeWrite]);
        rec.use_buffer(indices, &[Access::ComputeWrite]);
        rec.dispatch(&self.water_triangles, sets, push, [1, patches as u32, 1]);
        rec.use_buffer(draws, &[Access::IndirectCommands]);
        rec.use_buffer(indices, &[Access::IndexRead]);
    }
}

/// A compute pipeline of the frame: it binds the frame's sets (`layouts`) and reads its push constants
/// (`FramePush`), as the vertex cache's passes and the sky dome do.
pub(super) fn frame_compute(
    ctx: &Context,
    layouts: &[DescriptorSetLayout],
    name: &str,
    spirv: &[u8],
    specialization: &[u8],
) -> Result<ComputePipeline, GpuError> {
    ComputePipeline::new(
        ctx,
        &ComputeDesc {
            name,
            spirv,
            set_layouts: layouts,
            push_constant_bytes: std::mem::size_of::<FramePush>() as u32,
            specialization,
            full_subgroups: None,
        },
    )
}
