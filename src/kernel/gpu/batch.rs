//! The kernel outside the renderer: one batch end to end (textures, upload, dispatch, read-back), for the tests
//! and the kernel benchmarks.

use super::{river_textures, KernelBatch, KernelVariant, RiverKernel, RIVER_TEXTURE_LAYERS};
use crate::{
    gpu::{
        bindless::{Bindless, SlotLayer},
        layers::LayerPool,
        Access, Buffer, BufferDesc, Context, GpuError, Image, MemoryLocation, Profiler,
        ScopeTiming,
    },
    kernel::{KernelParams, ParentQuadrant, PatchJob, RiverTexel},
};

/// Decodes one read-back river texture (its layers, tightly packed RGBA32F) into texels.
pub fn decode_texels(bytes: &[u8], grid_size: u32) -> Vec<RiverTexel> {
    let texels: &[[f32; 4]] = bytemuck::cast_slice(bytes);
    let (heights, rest) = texels.split_at((grid_size * grid_size) as usize);
    let (widths, seconds) = rest.split_at((grid_size * grid_size) as usize);
    heights
        .iter()
        .zip(widths)
        .zip(seconds)
        .map(
            |((&[terrain_height, lerp_factor, water_height, min_distance], width), second)| {
                RiverTexel {
                    terrain_height,
                    lerp_factor,
                    water_height,
                    min_distance,
                    river_width: width[0],
                    flow: [width[1], width[2]],
                    second_distance: second[0],
                    second_width: second[1],
                    nearest_sample_width: second[2],
                    river_order: second[3],
                }
            },
        )
        .collect()
}

/// The result of [`run_batch`]: texels per patch and the GPU times of the scopes.
pub struct BatchResult {
    /// Per patch, its texels read back.
    pub texels: Vec<Vec<RiverTexel>>,
    /// The kernel's scopes' GPU times.
    pub timings: Vec<ScopeTiming>,
    /// Bytes of the batch's temporary buffers (samples, range table, reach masks).
    pub temporary_bytes: u64,
}

/// The output side of a batch: a river texture per patch, as layers of array images (the renderer's
/// [`LayerPool`]), and a host-visible buffer the textures are copied to. Benchmarks keep one between repetitions,
/// as the renderer keeps its textures resident, so that repetitions measure the work and not the driver's first
/// touch of fresh memory.
pub struct BatchOutputs {
    pool: LayerPool,
    places: Vec<SlotLayer>,
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
            uses: &[Access::TransferWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })?;
        let (pool, places) = LayerPool::filled(river_textures(grid_size), patches, ctx, bindless)?;
        Ok(Self {
            pool,
            places,
            readback,
            grid_size,
        })
    }

    /// The places of the textures, in order.
    pub fn places(&self) -> &[SlotLayer] {
        &self.places
    }

    /// The images that `parents` (as in [`KernelBatch`]) name by their places, each once: what a batch reading
    /// these outputs as its parents declares it reads.
    pub fn parent_textures(&self, parents: &[Option<(SlotLayer, ParentQuadrant)>]) -> Vec<&Image> {
        self.pool
            .images(parents.iter().flatten().map(|(place, _)| *place))
    }

    /// Bytes of one patch's layers, tightly packed.
    fn texel_bytes(grid_size: u32) -> u64 {
        (grid_size * grid_size * 16 * RIVER_TEXTURE_LAYERS) as u64
    }

    /// Frees the images' slots; the images and the read-back buffer are retired as `self` drops (freed once
    /// the GPU is done with them).
    pub fn release(self, ctx: &Context, bindless: &mut Bindless) {
        self.pool.release_slots(ctx, bindless);
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
    let result = run_batch_into(
        ctx,
        bindless,
        kernel,
        variant,
        jobs,
        (&[], &[]),
        params,
        &outputs,
    );
    outputs.release(ctx, bindless);
    result
}

/// Where a batch's patches take their parents' river data: per job, the parent's river texture and quadrant, and
/// the images those lie in (as in [`KernelBatch`]).
pub type Parents<'a> = (&'a [Option<(SlotLayer, ParentQuadrant)>], &'a [&'a Image]);

/// [`run_batch`] into existing outputs (at least one texture per job): upload, dispatch, readback, decode.
/// `parents` and the textures they name as in [`KernelBatch`] ([`BatchOutputs::parent_textures`]).
#[allow(clippy::too_many_arguments)]
pub fn run_batch_into(
    ctx: &Context,
    bindless: &Bindless,
    kernel: &RiverKernel,
    variant: KernelVariant,
    jobs: &[PatchJob],
    (parents, parent_textures): Parents,
    params: &KernelParams,
    outputs: &BatchOutputs,
) -> Result<BatchResult, GpuError> {
    let n = kernel.grid_size;
    if outputs.places.len() < jobs.len() || outputs.grid_size != n {
        return Err(GpuError::Invalid(format!(
            "batch of {} patches of {n}x{n} vertices does not fit outputs for {} patches of {}x{}",
            jobs.len(),
            outputs.places.len(),
            outputs.grid_size,
            outputs.grid_size
        )));
    }
    let texel_bytes = BatchOutputs::texel_bytes(n);
    let places = &outputs.places[..jobs.len()];
    let readback = &outputs.readback;
    let mut profiler = Profiler::new(ctx, 2, "river kernel timestamps")?;
    let image_refs = outputs.pool.images(places.iter().copied());
    let result = ctx.run_and_wait("river kernel batch", |rec| {
        let batch = KernelBatch {
            textures: &image_refs,
            places,
            jobs,
            parents,
            parent_textures,
        };
        let bytes = profiler.scope(rec, "kernel", |rec| {
            kernel.record(rec, bindless, variant, &batch, params)
        })??;
        rec.use_images(&image_refs, &[Access::TransferRead]);
        for (k, place) in places.iter().enumerate() {
            let image = outputs.pool.image(*place).ok_or_else(|| {
                GpuError::Invalid(format!("{place:?} lies in none of the outputs' images"))
            })?;
            let layers = place.layer..place.layer + RIVER_TEXTURE_LAYERS;
            rec.copy_layers_to_buffer(image, layers, readback, k as u64 * texel_bytes);
        }
        rec.use_buffer(readback, &[Access::HostRead]);
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
    outcome
}
