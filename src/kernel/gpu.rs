//! The GPU river kernel (Chapter 7): the simple (7.3.1) and tiled (7.3.2) compute shaders, and the recording of
//! the dispatch that computes every new patch of a frame. A range table (one [`GpuPatchJob`] per patch, four for a
//! patch that takes river data from its parent) maps the workgroups' row index to the sample range, the output
//! slot and the vertices of the row.

use bytemuck::{Pod, Zeroable};

use super::{KernelParams, ParentQuadrant, PatchJob, RiverSample, RiverTexel};
use crate::{
    gpu::{
        bindless::{Bindless, Slot},
        pipeline::{BufferSetLayout, ComputePipeline},
        vk, Buffer, BufferDesc, Context, GpuError, Image, ImageDesc, MemoryLocation, Profiler,
        Recorder, ScopeTiming,
    },
    shaders,
};

/// Which compute shader runs the kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
pub enum KernelVariant {
    /// One invocation per vertex, samples read from the storage buffer (7.3.1).
    Simple,
    /// Samples staged in shared memory tile by tile (7.3.2).
    Tiled,
}

/// Workgroup shapes and tile size, chosen by measurement (docs/kernel.md).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct KernelTuning {
    /// Invocations per workgroup of the simple kernel (1D over a patch's vertices).
    pub simple_workgroup: u32,
    /// Vertex block per workgroup of the tiled kernel (x, y).
    pub tiled_block: [u32; 2],
    /// Samples staged per tile by the tiled kernel.
    pub tile_size: u32,
}

impl Default for KernelTuning {
    /// The best of the sweep in docs/kernel.md (lavapipe): 8x4 vertex blocks, 1024-sample tiles.
    fn default() -> Self {
        Self {
            simple_workgroup: 64,
            tiled_block: [8, 4],
            tile_size: 1024,
        }
    }
}

impl KernelTuning {
    /// The default, with the block grown until it holds whole subgroups of the device's largest size, and the
    /// tile shrunk to what the device's shared memory holds.
    pub fn for_device(ctx: &Context) -> Self {
        let mut t = Self::default();
        while t.tiled_invocations() < ctx.subgroup.max_size {
            let [x, y] = t.tiled_block;
            t.tiled_block = if x > y { [x, y * 2] } else { [x * 2, y] };
        }
        let shared = ctx.properties.limits.max_compute_shared_memory_size;
        while t.tile_size > 32 && tiled_shared_bytes(t.tile_size, t.tiled_invocations()) > shared {
            t.tile_size /= 2;
        }
        t
    }

    /// Invocations per workgroup of the tiled kernel: one per vertex of the block.
    pub fn tiled_invocations(&self) -> u32 {
        self.tiled_block[0] * self.tiled_block[1]
    }

    /// Checks the tuning against the kernels' layout rules and the device's limits; the message names the value
    /// and its valid range.
    pub fn validate(&self, ctx: &Context) -> Result<(), String> {
        let limit = ctx.properties.limits.max_compute_work_group_invocations;
        let subgroup = ctx.subgroup.max_size.max(1);
        let [x, y] = self.tiled_block;
        let invocations = self.tiled_invocations();
        if self.simple_workgroup == 0 || self.simple_workgroup > limit {
            return Err(format!(
                "simple workgroup of {} invocations must be in [1, {limit}]",
                self.simple_workgroup
            ));
        }
        if !x.is_power_of_two() || !y.is_power_of_two() || !(x == y || x == 2 * y) {
            return Err(format!(
                "tiled block {x}x{y} must be powers of two, square or twice as wide as high (Morton layout)"
            ));
        }
        if invocations > limit || invocations % subgroup != 0 {
            return Err(format!(
                "tiled block {x}x{y} has {invocations} invocations; it must be a multiple of the largest \
                 subgroup size {subgroup} and at most {limit}"
            ));
        }
        if self.tile_size == 0 || self.tile_size % 32 != 0 || self.tile_size > 32 * invocations {
            return Err(format!(
                "tile size {} must be a positive multiple of 32 (one reach-mask word) and at most 32 x the \
                 block's {invocations} invocations",
                self.tile_size
            ));
        }
        let shared = ctx.properties.limits.max_compute_shared_memory_size;
        let needed = tiled_shared_bytes(self.tile_size, invocations);
        if needed > shared {
            return Err(format!(
                "tile size {} needs {needed} bytes of shared memory; the device has {shared}",
                self.tile_size
            ));
        }
        Ok(())
    }
}

/// Shared memory of the tiled kernel: the staged samples (28 bytes each) and two counts per possible subgroup.
pub fn tiled_shared_bytes(tile_size: u32, invocations: u32) -> u32 {
    tile_size * 28 + 2 * invocations * 4
}

/// One row of the range table (std430, 32 bytes): a patch, or for a patch that takes river data from its parent,
/// one of its four vertex lattices (glsl/river_kernel.glsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuPatchJob {
    pub spacing: f32,
    pub sample_offset: u32,
    pub sample_count: u32,
    pub slot: u32,
    /// Mask words of the rows before this one: the tiled kernel's reach masks of this row start there.
    pub mask_offset: u32,
    /// Stride (bits 0-7) and parity along x (bits 8-15) and y (bits 16-23) of the vertices this row covers.
    pub lattice: u32,
    /// The parent's slot to copy the row's vertices from, or [`NO_PARENT`].
    pub parent_slot: u32,
    /// The parent vertex of the row's first vertex: x (bits 0-15), y (bits 16-31).
    pub parent_offset: u32,
}

/// `parent_slot` of a row computed by the kernel.
pub const NO_PARENT: u32 = u32::MAX;

impl GpuPatchJob {
    /// Reach-mask words per vertex block of this row: one bit per sample.
    pub fn mask_words(&self) -> u32 {
        self.sample_count.div_ceil(32)
    }

    /// Vertices along x and y of this row's lattice in an `n x n` patch.
    pub fn lattice_size(&self, n: u32) -> [u32; 2] {
        let stride = self.lattice & 0xff;
        let parity = [(self.lattice >> 8) & 0xff, (self.lattice >> 16) & 0xff];
        parity.map(|p| (n - p).div_ceil(stride))
    }
}

/// The rows of a batch (patches computed from scratch first, then the four rows of each patch that takes river
/// data from its parent) and where each patch's samples start in the sample buffer.
pub struct RangeTable {
    pub rows: Vec<GpuPatchJob>,
    /// Rows over all vertices of a patch (the first ones); the rest cover every second vertex.
    pub full_rows: usize,
    pub sample_offsets: Vec<u32>,
    /// Reach-mask words of all rows, with blocks of `block` vertices.
    pub mask_words: u64,
}

/// The range table of `batch` for `n x n` patches and the tiled kernel's `block`.
pub fn range_table(batch: &KernelBatch, n: u32, block: [u32; 2]) -> RangeTable {
    let mut sample_offsets = Vec::with_capacity(batch.jobs.len());
    let mut offset = 0;
    for job in batch.jobs {
        sample_offsets.push(offset);
        offset += job.samples.len() as u32;
    }
    let parent = |k: usize| batch.parents.get(k).copied().flatten();
    let row = |k: usize, lattice: u32, parent_slot: u32, parent_offset: u32| GpuPatchJob {
        spacing: batch.jobs[k].spacing,
        sample_offset: sample_offsets[k],
        sample_count: if parent_slot == NO_PARENT {
            batch.jobs[k].samples.len() as u32
        } else {
            0
        },
        slot: batch.slots[k].0,
        mask_offset: 0,
        lattice,
        parent_slot,
        parent_offset,
    };
    let mut rows: Vec<GpuPatchJob> = (0..batch.jobs.len())
        .filter(|&k| parent(k).is_none())
        .map(|k| row(k, 1, NO_PARENT, 0))
        .collect();
    let full_rows = rows.len();
    for k in 0..batch.jobs.len() {
        if let Some((slot, quadrant)) = parent(k) {
            let [x, y] = quadrant.offset;
            rows.push(row(k, 2, slot.0, x | y << 16));
            for parity in [[1, 0], [0, 1], [1, 1]] {
                rows.push(row(k, 2 | parity[0] << 8 | parity[1] << 16, NO_PARENT, 0));
            }
        }
    }
    let mut mask_words = 0u64;
    for r in &mut rows {
        r.mask_offset = mask_words as u32;
        let [lx, ly] = r.lattice_size(n);
        mask_words += (r.mask_words() * lx.div_ceil(block[0]) * ly.div_ceil(block[1])) as u64;
    }
    RangeTable {
        rows,
        full_rows,
        sample_offsets,
        mask_words,
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct PushParams {
    influence_distance: f32,
    basin_depth: f32,
    sea_level: f32,
    basin_water_offset: f32,
    grid_size: u32,
    first_job: u32,
}

/// Format and layers of a patch's river texture: layer 0 = (terrain height, lerp factor, water height, signed
/// minimum distance), layer 1 = (river half width, 0, 0, 0).
pub const RIVER_TEXTURE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
pub const RIVER_TEXTURE_LAYERS: u32 = 2;

/// One dispatch's input: per job (patch), its fresh river texture, the bindless slot of that texture, and its
/// spacing and samples; and for jobs that take their even vertices from their parent (10.2), the parent's slot
/// (its river texture in the GENERAL layout) and quadrant. `parents` is empty or as long as `jobs`.
#[derive(Clone, Copy)]
pub struct KernelBatch<'a> {
    pub textures: &'a [&'a Image],
    pub slots: &'a [Slot],
    pub jobs: &'a [PatchJob<'a>],
    pub parents: &'a [Option<(Slot, ParentQuadrant)>],
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
    pub grid_size: u32,
    pub tuning: KernelTuning,
}

impl RiverKernel {
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
        let push = std::mem::size_of::<PushParams>() as u32;
        let simple = ComputePipeline::new(
            ctx,
            shaders::KERNEL_SIMPLE_COMP,
            "river kernel simple",
            &layouts,
            push,
            &[tuning.simple_workgroup],
        )?;
        let reach = ComputePipeline::new(
            ctx,
            shaders::KERNEL_REACH_COMP,
            "river kernel reach masks",
            &tiled_layouts,
            push,
            &tuning.tiled_block,
        )?;
        let tiled = ComputePipeline::with_full_subgroups(
            ctx,
            shaders::KERNEL_TILED_COMP,
            "river kernel tiled",
            &tiled_layouts,
            push,
            &[
                tuning.tiled_invocations(),
                tuning.tiled_block[0],
                tuning.tiled_block[1],
                tuning.tile_size,
                ctx.subgroup.max_size,
            ],
            ctx.subgroup.max_size,
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

    /// Records one dispatch computing every job of `batch` into its slot's river texture. The textures are fresh
    /// (any layout): they are moved to GENERAL here. The sample and range-table buffers are host-visible
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
        rec.image_transitions(
            batch.textures,
            vk::ImageLayout::UNDEFINED,
            vk::ImageLayout::GENERAL,
            vk::PipelineStageFlags2::NONE,
            vk::AccessFlags2::NONE,
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::AccessFlags2::SHADER_STORAGE_WRITE,
        );
        if batch.jobs.is_empty() {
            return Ok(0);
        }
        if batch.parents.iter().any(Option::is_some) {
            // The parents' river textures were written by an earlier dispatch.
            rec.memory_barrier(
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ,
            );
        }
        let ctx = rec.ctx();
        let host_buffer = |name: &str, size: usize| {
            ctx.create_buffer(&BufferDesc {
                name,
                size: size.max(16) as u64,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
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
        let push = |first_job: usize| PushParams {
            influence_distance: params.influence_distance,
            basin_depth: params.basin_depth,
            sea_level: params.sea_level,
            basin_water_offset: params.basin_water_offset,
            grid_size: n,
            first_job: first_job as u32,
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
        push: impl Fn(usize) -> PushParams,
    ) -> Result<u64, GpuError> {
        let [bx, by] = self.tuning.tiled_block;
        let masks = rec.ctx().create_buffer(&BufferDesc {
            name: "river reach masks",
            size: (table.mask_words * 4).max(16),
            usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuOnly,
        })?;
        let size = masks.size;
        let set = rec.buffer_set(&self.tiled_inputs, &[samples, table_buffer, &masks]);
        if let Ok(set) = set {
            rec.fill_buffer(&masks, 0);
            rec.buffer_barrier(
                &masks,
                vk::PipelineStageFlags2::CLEAR,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            );
            let rows = table.rows.len() as u32;
            rec.dispatch(
                &self.reach,
                &[bindless.set, set],
                bytemuck::bytes_of(&push(0)),
                [1, rows, 1],
            );
            rec.buffer_barrier(
                &masks,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_WRITE,
                vk::PipelineStageFlags2::COMPUTE_SHADER,
                vk::AccessFlags2::SHADER_STORAGE_READ,
            );
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

    pub fn destroy(self, ctx: &Context) {
        self.simple.destroy(ctx);
        self.reach.destroy(ctx);
        self.tiled.destroy(ctx);
        self.inputs.destroy(ctx);
        self.tiled_inputs.destroy(ctx);
    }
}

/// Creates one patch's river texture.
pub fn create_river_texture(ctx: &Context, grid_size: u32, name: &str) -> Result<Image, GpuError> {
    ctx.create_image(&ImageDesc {
        name,
        extent: vk::Extent2D {
            width: grid_size,
            height: grid_size,
        },
        layers: RIVER_TEXTURE_LAYERS,
        format: RIVER_TEXTURE_FORMAT,
        usage: vk::ImageUsageFlags::STORAGE
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_SRC,
        aspect: vk::ImageAspectFlags::COLOR,
        array: true,
    })
}

/// Decodes one read-back river texture (both layers, tightly packed RGBA32F) into texels.
pub fn decode_texels(bytes: &[u8], grid_size: u32) -> Vec<RiverTexel> {
    let texels: &[[f32; 4]] = bytemuck::cast_slice(bytes);
    let (heights, widths) = texels.split_at((grid_size * grid_size) as usize);
    heights
        .iter()
        .zip(widths)
        .map(
            |(&[terrain_height, lerp_factor, water_height, min_distance], width)| RiverTexel {
                terrain_height,
                lerp_factor,
                water_height,
                min_distance,
                river_width: width[0],
            },
        )
        .collect()
}

/// The result of [`run_batch`]: texels per patch and the GPU times of the scopes.
pub struct BatchResult {
    pub texels: Vec<Vec<RiverTexel>>,
    pub timings: Vec<ScopeTiming>,
    pub temporary_bytes: u64,
}

/// The output side of a batch: a river texture per patch, each in its bindless slot, and a host-visible buffer
/// the textures are copied to. Benchmarks keep one between repetitions, as the renderer keeps its textures
/// resident, so that repetitions measure the work and not the driver's first touch of fresh memory.
pub struct BatchOutputs {
    images: Vec<Image>,
    slots: Vec<Slot>,
    readback: Buffer,
    grid_size: u32,
}

impl BatchOutputs {
    /// Textures and read-back space for up to `patches` patches of `grid_size` x `grid_size` vertices.
    pub fn new(
        ctx: &Context,
        bindless: &mut Bindless,
        patches: usize,
        grid_size: u32,
    ) -> Result<Self, GpuError> {
        let readback = ctx.create_buffer(&BufferDesc {
            name: "river readback",
            size: Self::texel_bytes(grid_size) * patches.max(1) as u64,
            usage: vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuToCpu,
        })?;
        let mut outputs = Self {
            images: Vec::with_capacity(patches),
            slots: Vec::with_capacity(patches),
            readback,
            grid_size,
        };
        for k in 0..patches {
            let Some(slot) = bindless.allocate() else {
                let capacity = bindless.capacity;
                outputs.destroy(ctx, bindless);
                return Err(GpuError::Invalid(format!(
                    "batch of {patches} patches exceeds the {capacity} bindless slots"
                )));
            };
            outputs.slots.push(slot);
            let image = match create_river_texture(ctx, grid_size, &format!("river texture {k}")) {
                Ok(image) => image,
                Err(e) => {
                    outputs.destroy(ctx, bindless);
                    return Err(e);
                }
            };
            bindless.write(ctx, slot, &image, true, vk::ImageLayout::GENERAL);
            outputs.images.push(image);
        }
        Ok(outputs)
    }

    /// The bindless slots of the textures, in order.
    pub fn slots(&self) -> &[Slot] {
        &self.slots
    }

    /// Bytes of one patch's two layers, tightly packed.
    fn texel_bytes(grid_size: u32) -> u64 {
        (grid_size * grid_size * 16 * RIVER_TEXTURE_LAYERS) as u64
    }

    /// Frees the textures (after the GPU is done with them) and their slots.
    pub fn destroy(self, ctx: &Context, bindless: &mut Bindless) {
        for s in self.slots {
            bindless.release(s);
        }
        for i in self.images {
            ctx.retire_image(i);
        }
        ctx.retire_buffer(self.readback);
    }
}

/// Computes `jobs` on the GPU in one dispatch, end to end: textures, upload, dispatch, readback. The scope
/// "kernel" times the dispatch alone. For tests; benchmarks reuse their outputs with [`run_batch_into`].
pub fn run_batch(
    ctx: &Context,
    bindless: &mut Bindless,
    kernel: &RiverKernel,
    variant: KernelVariant,
    jobs: &[PatchJob],
    params: &KernelParams,
) -> Result<BatchResult, GpuError> {
    let outputs = BatchOutputs::new(ctx, bindless, jobs.len(), kernel.grid_size)?;
    let result = run_batch_into(ctx, bindless, kernel, variant, jobs, &[], params, &outputs);
    outputs.destroy(ctx, bindless);
    result
}

/// [`run_batch`] into existing outputs (at least one texture per job): upload, dispatch, readback, decode.
/// `parents` as in [`KernelBatch`].
#[allow(clippy::too_many_arguments)]
pub fn run_batch_into(
    ctx: &Context,
    bindless: &Bindless,
    kernel: &RiverKernel,
    variant: KernelVariant,
    jobs: &[PatchJob],
    parents: &[Option<(Slot, ParentQuadrant)>],
    params: &KernelParams,
    outputs: &BatchOutputs,
) -> Result<BatchResult, GpuError> {
    let n = kernel.grid_size;
    if outputs.images.len() < jobs.len() || outputs.grid_size != n {
        return Err(GpuError::Invalid(format!(
            "batch of {} patches of {n}x{n} vertices does not fit outputs for {} patches of {}x{}",
            jobs.len(),
            outputs.images.len(),
            outputs.grid_size,
            outputs.grid_size
        )));
    }
    let texel_bytes = BatchOutputs::texel_bytes(n);
    let images = &outputs.images[..jobs.len()];
    let slots = &outputs.slots[..jobs.len()];
    let readback = &outputs.readback;
    let mut profiler = Profiler::new(ctx, 2, "river kernel timestamps")?;
    let image_refs: Vec<&Image> = images.iter().collect();
    let result = ctx.run_and_wait("river kernel batch", |rec| {
        let batch = KernelBatch {
            textures: &image_refs,
            slots,
            jobs,
            parents,
        };
        let scope = profiler.begin(rec, "kernel")?;
        let bytes = kernel.record(rec, bindless, variant, &batch, params)?;
        profiler.end(rec, scope);
        rec.memory_barrier(
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::AccessFlags2::SHADER_STORAGE_WRITE,
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_READ,
        );
        for (k, image) in images.iter().enumerate() {
            rec.copy_image_to_buffer(
                image,
                vk::ImageLayout::GENERAL,
                readback,
                k as u64 * texel_bytes,
            );
        }
        rec.buffer_barrier(
            readback,
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::PipelineStageFlags2::HOST,
            vk::AccessFlags2::HOST_READ,
        );
        Ok(bytes)
    });
    let outcome = result.and_then(|temporary_bytes| {
        let timings = profiler.read(ctx)?;
        let bytes = readback
            .mapped()
            .ok_or_else(|| GpuError::Invalid("readback buffer is not host-visible".into()))?;
        let texels = (0..jobs.len())
            .map(|k| {
                let start = k * texel_bytes as usize;
                decode_texels(&bytes[start..start + texel_bytes as usize], n)
            })
            .collect();
        Ok(BatchResult {
            texels,
            timings,
            temporary_bytes,
        })
    });
    profiler.destroy(ctx);
    outcome
}
