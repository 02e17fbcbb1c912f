//! The GPU river kernel (Chapter 7): the simple (7.3.1) and tiled (7.3.2) compute shaders, and the recording of
//! the dispatch that computes every new patch of a frame. A range table (one [`GpuPatchJob`] per patch, four for a
//! patch that takes river data from its parent) maps the workgroups' row index to the sample range, the output
//! texture's place and the vertices of the row.

pub mod autotune;
mod batch;
mod jobs;
mod tuning;

pub use self::{
    batch::{decode_texels, run_batch, run_batch_into, BatchOutputs, BatchResult},
    jobs::{range_table, GpuPatchJob, RangeTable, NO_PARENT},
    tuning::{tiled_shared_bytes, KernelTuning},
};
use super::{KernelParams, ParentQuadrant, PatchJob, RiverSample};
use crate::{
    gpu::{
        bindless::{Bindless, SlotLayer},
        layers::LayerKind,
        pipeline::{BufferSetLayout, ComputeDesc, ComputePipeline},
        Access, Buffer, BufferDesc, Context, Extent2D, Format, GpuError, Image, MemoryLocation,
        Recorder,
    },
    shader_types::{KernelPush, TiledConstants},
    shaders,
};

/// Which compute shader runs the kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum KernelVariant {
    /// One invocation per vertex, samples read from the storage buffer (7.3.1).
    Simple,
    /// Samples staged in shared memory tile by tile (7.3.2).
    Tiled,
}

/// Format and layers of a patch's river texture: layer 0 = (terrain height, lerp factor, water height, signed
/// minimum distance), layer 1 = (river half width, flow x, flow y, 0), layer 2 = (second river's signed distance
/// and half width, nearest sample's half width, the rivers' order): [`crate::kernel::RiverTexel`].
pub const RIVER_TEXTURE_FORMAT: Format = Format::R32G32B32A32_SFLOAT;
/// See `RIVER_TEXTURE_FORMAT`.
pub const RIVER_TEXTURE_LAYERS: u32 = 3;

/// One dispatch's input: per job (patch), the place of its river texture (a slot and layers), and its spacing and
/// samples; and for jobs that take their even vertices from their parent (10.2), the place of the parent's river
/// texture (in the GENERAL layout) and the quadrant. `parents` is empty or as long as `jobs`.
#[derive(Clone, Copy)]
pub struct KernelBatch<'a> {
    /// The images the jobs' places lie in, each once: the dispatch writes them (their other layers keep their
    /// contents).
    pub textures: &'a [&'a Image],
    /// Per job, the place of its river texture.
    pub places: &'a [SlotLayer],
    /// The patches, with their vertex spacing and samples.
    pub jobs: &'a [PatchJob<'a>],
    /// Per job, its parent's river texture and the quadrant it covers of it, where it takes its even vertices
    /// from there.
    pub parents: &'a [Option<(SlotLayer, ParentQuadrant)>],
    /// The images those parents' places lie in (each once): the dispatch reads them.
    pub parent_textures: &'a [&'a Image],
}

/// Both kernel pipelines, ready to record dispatches.
pub struct RiverKernel {
    simple: ComputePipeline,
    /// The tiled kernel's pre-pass: which samples reach which vertex block (kernel_reach.comp).
    reach: ComputePipeline,
    tiled: ComputePipeline,
    /// Samples and range table (simple); plus the reach masks (reach pre-pass and tiled).
    inputs: BufferSetLayout,
    tiled_inputs: BufferSetLayout,
    /// Vertices per patch edge.
    pub grid_size: u32,
    /// The tiled kernel's workgroup shape and tile size.
    pub tuning: KernelTuning,
}

impl RiverKernel {
    /// Both pipelines for patches of `grid_size` vertices a side, the tiled one with `tuning` (checked against the
    /// device's limits).
    pub fn new(
        ctx: &Context,
        bindless: &Bindless,
        grid_size: u32,
        tuning: KernelTuning,
    ) -> Result<Self, GpuError> {
        tuning.validate(ctx).map_err(GpuError::Invalid)?;
        let inputs = BufferSetLayout::new(ctx, 2, "river kernel inputs")?;
        let tiled_inputs = BufferSetLayout::new(ctx, 3, "tiled river kernel inputs")?;
        let layouts = [bindless.layout, inputs.layout];
        let tiled_layouts = [bindless.layout, tiled_inputs.layout];
        let push = std::mem::size_of::<KernelPush>() as u32;
        let simple = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "river kernel simple",
                spirv: shaders::KERNEL_SIMPLE_COMP,
                set_layouts: &layouts,
                push_constant_bytes: push,
                // The workgroup size.
                specialization: bytemuck::bytes_of(&tuning.simple_workgroup),
                full_subgroups: None,
            },
        )?;
        let reach = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "river kernel reach masks",
                spirv: shaders::KERNEL_REACH_COMP,
                set_layouts: &tiled_layouts,
                push_constant_bytes: push,
                // BLOCK_X, BLOCK_Y.
                specialization: bytemuck::bytes_of(&tuning.tiled_block),
                full_subgroups: None,
            },
        )?;
        let tiled_constants = TiledConstants {
            invocations: tuning.tiled_invocations(),
            block_x: tuning.tiled_block[0],
            block_y: tuning.tiled_block[1],
            tile_size: tuning.tile_size,
            subgroup_size: ctx.subgroup.max_size,
        };
        let tiled = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "river kernel tiled",
                spirv: shaders::KERNEL_TILED_COMP,
                set_layouts: &tiled_layouts,
                push_constant_bytes: push,
                specialization: bytemuck::bytes_of(&tiled_constants),
                full_subgroups: Some(ctx.subgroup.max_size),
            },
        )?;
        Ok(Self {
            simple,
            reach,
            tiled,
            inputs,
            tiled_inputs,
            grid_size,
            tuning,
        })
    }

    /// Records one dispatch computing every job of `batch` into its river texture's layers. The images are moved
    /// to GENERAL here, keeping their other layers. The sample and range-table buffers are host-visible
    /// per-dispatch buffers, freed when the submission completes. Returns their size in bytes (the frame's
    /// temporary sample memory). The caller makes the results visible to whatever reads them next.
    pub fn record(
        &self,
        rec: &mut Recorder,
        bindless: &Bindless,
        variant: KernelVariant,
        batch: &KernelBatch,
        params: &KernelParams,
    ) -> Result<u64, GpuError> {
        if batch.jobs.is_empty() {
            return Ok(0);
        }
        // The parents' river textures were written by an earlier dispatch; they may share an image with the
        // textures written now.
        rec.use_images_reading_writing(
            (batch.parent_textures, Access::ComputeRead),
            (batch.textures, Access::ComputeWrite),
        );
        let ctx = rec.ctx();
        let host_buffer = |name: &str, size: usize| {
            ctx.create_buffer(&BufferDesc {
                name,
                size: size.max(16) as u64,
                uses: &[Access::ComputeRead],
                location: MemoryLocation::CpuToGpu,
            })
        };
        let n = self.grid_size;
        let table = range_table(batch, n, self.tuning.tiled_block);
        let rows = &table.rows;
        let mut job_buffer = host_buffer("river range table", std::mem::size_of_val(&rows[..]))?;
        job_buffer.write(0, rows)?;
        // Every patch's samples are written straight into the mapped buffer at its range.
        let sample_bytes = std::mem::size_of::<RiverSample>();
        let total: usize = batch.jobs.iter().map(|j| j.samples.len()).sum();
        let mut sample_buffer = host_buffer("river samples", total * sample_bytes)?;
        for (job, offset) in batch.jobs.iter().zip(&table.sample_offsets) {
            sample_buffer.write(*offset as usize * sample_bytes, job.samples)?;
        }
        let bytes = sample_buffer.size + job_buffer.size;
        // Rows over whole patches, then rows over every second vertex (from the parent's patches).
        let half = n.div_ceil(2);
        let groups = [
            (0, table.full_rows, [n, n]),
            (table.full_rows, rows.len() - table.full_rows, [half, half]),
        ];
        let push = |first_job: usize| KernelPush {
            influence_distance: params.influence_distance,
            basin_depth: params.basin_depth,
            sea_level: params.sea_level,
            basin_water_offset: params.basin_water_offset,
            grid_size: n,
            first_job: first_job as u32,
            sample_floor: params.sample_floor,
        };
        let inputs = [&sample_buffer, &job_buffer];
        let dispatched = match variant {
            KernelVariant::Simple => rec.buffer_set(&self.inputs, &inputs).map(|set| {
                for (first, count, [x, y]) in groups.into_iter().filter(|g| g.1 > 0) {
                    let size = [
                        (x * y).div_ceil(self.tuning.simple_workgroup),
                        count as u32,
                        1,
                    ];
                    let push = push(first);
                    rec.dispatch(
                        &self.simple,
                        &[bindless.set, set],
                        bytemuck::bytes_of(&push),
                        size,
                    );
                }
                0
            }),
            KernelVariant::Tiled => self.record_tiled(rec, bindless, inputs, &table, groups, push),
        };
        rec.free_after_completion(sample_buffer);
        rec.free_after_completion(job_buffer);
        Ok(bytes + dispatched?)
    }

    /// The tiled variant: clears the reach masks, runs the pre-pass that fills them, then the tiled kernel over
    /// each group of rows (first row, rows, lattice size). Returns the size of the mask buffer, which is freed
    /// when the submission completes.
    fn record_tiled(
        &self,
        rec: &mut Recorder,
        bindless: &Bindless,
        [samples, table_buffer]: [&Buffer; 2],
        table: &RangeTable,
        groups: [(usize, usize, [u32; 2]); 2],
        push: impl Fn(usize) -> KernelPush,
    ) -> Result<u64, GpuError> {
        let [bx, by] = self.tuning.tiled_block;
        let masks = rec.ctx().create_buffer(&BufferDesc {
            name: "river reach masks",
            size: (table.mask_words * 4).max(16),
            uses: &[
                Access::TransferWrite,
                Access::ComputeRead,
                Access::ComputeWrite,
            ],
            location: MemoryLocation::GpuOnly,
        })?;
        let size = masks.size;
        let set = rec.buffer_set(&self.tiled_inputs, &[samples, table_buffer, &masks]);
        if let Ok(set) = set {
            rec.fill_buffer(&masks, 0);
            rec.use_buffer(&masks, &[Access::ComputeRead, Access::ComputeWrite]);
            let rows = table.rows.len() as u32;
            rec.dispatch(
                &self.reach,
                &[bindless.set, set],
                bytemuck::bytes_of(&push(0)),
                [1, rows, 1],
            );
            rec.use_buffer(&masks, &[Access::ComputeRead]);
            for (first, count, [x, y]) in groups.into_iter().filter(|g| g.1 > 0) {
                let size = [x.div_ceil(bx), y.div_ceil(by), count as u32];
                let push = push(first);
                rec.dispatch(
                    &self.tiled,
                    &[bindless.set, set],
                    bytemuck::bytes_of(&push),
                    size,
                );
            }
        }
        rec.free_after_completion(masks);
        set.map(|_| size)
    }
}

/// Patches' river textures as layers of array images: written by the kernel, read by the terrain's shaders and
/// by children's kernel rows, copied out by tests and benchmarks.
pub fn river_textures(grid_size: u32) -> LayerKind {
    LayerKind {
        name: "river data",
        extent: Extent2D {
            width: grid_size,
            height: grid_size,
        },
        format: RIVER_TEXTURE_FORMAT,
        layers_per_texture: RIVER_TEXTURE_LAYERS,
        uses: &[
            Access::ComputeWrite,
            Access::GraphicsSampled,
            Access::TransferRead,
        ],
    }
}
