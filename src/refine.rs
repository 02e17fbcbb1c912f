//! Base heights on demand on the GPU (glsl/heights_refine.comp): every patch finer than the precomputed lattice
//! gets its heights from its parent's by one diamond-square step, in the frame's submission before the river
//! kernel. Equal bit for bit to the CPU reference `planet::detail::refine` (tests/detail.rs).

use std::collections::HashMap;

use crate::{
    gpu::{
        bindless::{Bindless, SlotLayer},
        layers::{LayerKind, LayerPool},
        pipeline::{BufferSetLayout, ComputeDesc, ComputePipeline},
        Access, BufferDesc, Context, Extent2D, Format, GpuError, Image, MemoryLocation, Recorder,
    },
    planet::{cube::PatchId, detail::PatchHeights, Planet},
    shader_types::{GpuRefineJob, RefinePush},
    shaders,
};

/// Format of a patch's base-height texture: one f32 per lattice point, border included.
pub const HEIGHT_FORMAT: Format = Format::R32_SFLOAT;

/// A patch to refine: its id, the place of its fresh height texture, and its parent's.
#[derive(Clone, Copy, Debug)]
pub struct RefineJob {
    /// The patch.
    pub patch: PatchId,
    /// Where its fresh height texture lies.
    pub place: SlotLayer,
    /// Where its parent's lies.
    pub parent_place: SlotLayer,
}

/// A patch's lowest and highest base height.
pub type HeightRange = (f32, f32);

/// The height ranges of one recording's refined patches, in a host-visible buffer the shader writes.
pub struct RefinedRanges {
    patches: Vec<PatchId>,
    buffer: crate::gpu::Buffer,
    /// Bytes of the job tables and this buffer (the frame's temporary memory).
    pub bytes: u64,
}

impl RefinedRanges {
    /// Each refined patch's lowest and highest height (border included), once the submission has completed; the
    /// buffer is freed.
    pub fn read(self) -> Result<Vec<(PatchId, HeightRange)>, GpuError> {
        let ranges = self
            .buffer
            .mapped()
            .map(|bytes| {
                bytemuck::cast_slice::<u8, [f32; 2]>(&bytes[..self.patches.len() * 8]).to_vec()
            })
            .ok_or_else(|| GpuError::Invalid("height range buffer is not host-visible".into()));
        Ok(self
            .patches
            .into_iter()
            .zip(ranges?)
            .map(|(p, [lo, hi])| (p, (lo, hi)))
            .collect())
    }
}

/// The refinement pipeline.
pub struct HeightRefiner {
    pipeline: ComputePipeline,
    jobs_layout: BufferSetLayout,
    vertices: u32,
}

impl HeightRefiner {
    /// The refinement pipeline for patches of `vertices` a side.
    pub fn new(ctx: &Context, bindless: &Bindless, vertices: u32) -> Result<Self, GpuError> {
        let jobs_layout = BufferSetLayout::new(ctx, 2, "height refinement jobs and ranges")?;
        let pipeline = ComputePipeline::new(
            ctx,
            &ComputeDesc {
                name: "height refinement",
                spirv: shaders::HEIGHTS_REFINE_COMP,
                set_layouts: &[bindless.layout, jobs_layout.layout],
                push_constant_bytes: std::mem::size_of::<RefinePush>() as u32,
                // CELLS: cells per patch edge.
                specialization: bytemuck::bytes_of(&(vertices - 1)),
                full_subgroups: None,
            },
        );
        let pipeline = match pipeline {
            Ok(p) => p,
            Err(e) => {
                return Err(e);
            }
        };
        Ok(Self {
            pipeline,
            jobs_layout,
            vertices,
        })
    }

    /// Records the refinement of `jobs`, sorted by level, each child's parent resident or earlier in the list:
    /// one dispatch per level (a workgroup per patch), each declaring the images of the parents' textures it
    /// samples and of the children's it writes (`image` of a place; one image may hold both), so that a child
    /// reads its parent's finished heights, uploaded or refined a level before. The caller declares the results'
    /// next use. Returns where each child's height range arrives (read it once the submission has completed), or
    /// `None` without jobs.
    pub fn record<'a>(
        &self,
        rec: &mut Recorder,
        (bindless, planet): (&Bindless, &Planet),
        jobs: &[RefineJob],
        image: impl Fn(SlotLayer) -> Option<&'a Image>,
    ) -> Result<Option<RefinedRanges>, GpuError> {
        if jobs.is_empty() {
            return Ok(None);
        }
        debug_assert!(jobs
            .windows(2)
            .all(|w| w[0].patch.level <= w[1].patch.level));
        let table: Vec<GpuRefineJob> = jobs
            .iter()
            .enumerate()
            .map(|(k, j)| GpuRefineJob {
                child_place: j.place.shader_index() as i32,
                parent_place: j.parent_place.shader_index() as i32,
                face: j.patch.face as i32,
                level: j.patch.level as i32,
                x: j.patch.x as i32,
                y: j.patch.y as i32,
                range_index: k as i32,
                unused: 0,
            })
            .collect();
        let push = RefinePush {
            seed: planet.rule.seed,
            amplitude: planet.rule.amplitude,
            flat_share: planet.rule.flat_share,
            spread_gain: planet.rule.spread_gain(),
        };
        let push = bytemuck::bytes_of(&push);
        let row = std::mem::size_of::<GpuRefineJob>();
        let ranges = rec.ctx().create_buffer(&BufferDesc {
            name: "refined height ranges",
            size: (jobs.len() * 8) as u64,
            uses: &[Access::ComputeWrite, Access::HostRead],
            location: MemoryLocation::GpuToCpu,
        })?;
        let mut out = RefinedRanges {
            patches: jobs.iter().map(|j| j.patch).collect(),
            bytes: ranges.size,
            buffer: ranges,
        };
        rec.use_buffer(&out.buffer, &[Access::ComputeWrite]);
        let mut start = 0;
        while start < jobs.len() {
            let level = jobs[start].patch.level;
            let end = start
                + jobs[start..]
                    .iter()
                    .take_while(|j| j.patch.level == level)
                    .count();
            let images_of = |place: fn(&RefineJob) -> SlotLayer, whose: &str| {
                let mut images: Vec<&Image> = Vec::new();
                for j in &jobs[start..end] {
                    let found = image(place(j)).ok_or_else(|| {
                        GpuError::Invalid(format!("no texture for the {whose} of {:?}", j.patch))
                    })?;
                    if !images.iter().any(|i| std::ptr::eq(*i, found)) {
                        images.push(found);
                    }
                }
                Ok::<_, GpuError>(images)
            };
            let parents = images_of(|j| j.parent_place, "parent")?;
            let children = images_of(|j| j.place, "heights")?;
            rec.use_images_reading_writing(
                (&parents, Access::ComputeSampled),
                (&children, Access::ComputeWrite),
            );
            let mut buffer = rec.ctx().create_buffer(&BufferDesc {
                name: "height refinement jobs",
                size: ((end - start) * row) as u64,
                uses: &[Access::ComputeRead],
                location: MemoryLocation::CpuToGpu,
            })?;
            buffer.write(0, &table[start..end])?;
            out.bytes += buffer.size;
            let set = rec.buffer_set(&self.jobs_layout, &[&buffer, &out.buffer]);
            if let Ok(set) = set {
                rec.dispatch(
                    &self.pipeline,
                    &[bindless.set, set],
                    push,
                    [(end - start) as u32, 1, 1],
                );
            }
            rec.free_after_completion(buffer);
            set?;
            start = end;
        }
        rec.use_buffer(&out.buffer, &[Access::HostRead]);
        Ok(Some(out))
    }
}

/// Makes the images of new base-height textures ready for uploads and for the refinement shader's writes (in
/// GENERAL, keeping the other layers).
pub fn prepare_height_textures(rec: &mut Recorder, images: &[&Image]) {
    rec.use_images(images, &[Access::TransferWrite, Access::ComputeWrite]);
}

/// Patches' base-height textures as layers of array images: `(n + 2 BORDER)^2` texels each, written by upload
/// (precomputed levels) or by the refinement shader, read by the terrain shaders and by the refinement of the
/// children.
pub fn height_textures(vertices: u32) -> LayerKind {
    let side = PatchHeights::side(vertices) as u32;
    LayerKind {
        name: "base heights",
        extent: Extent2D {
            width: side,
            height: side,
        },
        format: HEIGHT_FORMAT,
        layers_per_texture: 1,
        uses: &[
            Access::GraphicsSampled,
            Access::ComputeWrite,
            Access::TransferWrite,
            Access::TransferRead,
        ],
    }
}

/// The patches to make so that `wanted` can be refined: each with every ancestor finer than the precomputed
/// level, parents first, without repeats, skipping what `resident` already has.
pub fn with_ancestors(
    wanted: &[PatchId],
    precomputed_level: u32,
    resident: impl Fn(&PatchId) -> bool,
) -> Vec<PatchId> {
    let mut out: Vec<PatchId> = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for &patch in wanted {
        let mut chain = Vec::new();
        let mut p = Some(patch);
        while let Some(q) = p {
            if resident(&q) || seen.contains(&q) {
                break;
            }
            chain.push(q);
            if q.level as u32 <= precomputed_level {
                break;
            }
            p = q.parent();
        }
        for q in chain.into_iter().rev() {
            seen.insert(q);
            out.push(q);
        }
    }
    out.sort_by_key(|p| p.level);
    out
}

/// What [`generate_on_gpu`] read back.
pub struct GpuPatches {
    /// The requested patches' heights, in request order.
    pub heights: Vec<PatchHeights>,
    /// The height range the shader reported for every refined patch (requested or ancestor).
    pub ranges: HashMap<PatchId, HeightRange>,
}

/// Makes `patches` and every ancestor they need on the GPU (the precomputed ones uploaded from the planet's
/// lattice, the rest refined level by level) and reads their heights back. For tests and tools: the renderer
/// records the same work into its frames.
pub fn generate_on_gpu(
    ctx: &Context,
    bindless: &mut Bindless,
    refiner: &HeightRefiner,
    planet: &Planet,
    patches: &[PatchId],
) -> Result<GpuPatches, GpuError> {
    let n = refiner.vertices;
    let all = with_ancestors(patches, planet.precomputed_level, |_| false);
    let (pool, made) = LayerPool::filled(height_textures(n), all.len(), ctx, bindless)?;
    let places: HashMap<PatchId, SlotLayer> = all.iter().copied().zip(made).collect();
    let texel_bytes = (PatchHeights::side(n).pow(2) * 4) as u64;
    let readback = ctx.create_buffer(&BufferDesc {
        name: "height readback",
        size: texel_bytes * patches.len().max(1) as u64,
        uses: &[Access::TransferWrite, Access::HostRead],
        location: MemoryLocation::GpuToCpu,
    });
    let readback = match readback {
        Ok(b) => b,
        Err(e) => {
            pool.release_slots(ctx, bindless);
            return Err(e);
        }
    };
    let bindless_ref = &*bindless;
    let image = |place: SlotLayer| pool.image(place);
    let result = ctx.run_and_wait("height refinement", |rec| {
        let images = pool.images(places.values().copied());
        prepare_height_textures(rec, &images);
        let mut jobs = Vec::new();
        for p in &all {
            let place = places[p];
            if p.level as u32 <= planet.precomputed_level {
                let heights = planet.lattice.patch_heights(*p, n);
                let data = bytemuck::cast_slice(&heights.data);
                rec.upload_image_layer(pool_image(image, place)?, place.layer, data)?;
            } else {
                let parent = p.parent().expect("refined patches have parents");
                jobs.push(RefineJob {
                    patch: *p,
                    place,
                    parent_place: places[&parent],
                });
            }
        }
        let ranges = refiner.record(rec, (bindless_ref, planet), &jobs, image)?;
        let wanted: Vec<SlotLayer> = patches.iter().map(|p| places[p]).collect();
        rec.use_images(
            &pool.images(wanted.iter().copied()),
            &[Access::TransferRead],
        );
        for (k, place) in wanted.iter().enumerate() {
            let layers = place.layer..place.layer + 1;
            let offset = k as u64 * texel_bytes;
            rec.copy_layers_to_buffer(pool_image(image, *place)?, layers, &readback, offset);
        }
        rec.use_buffer(&readback, &[Access::HostRead]);
        Ok(ranges)
    });
    let out = result.and_then(|ranges| {
        let ranges = match ranges {
            Some(r) => r.read()?.into_iter().collect(),
            None => HashMap::new(),
        };
        let bytes = readback
            .mapped()
            .ok_or_else(|| GpuError::Invalid("readback buffer is not host-visible".into()))?;
        let heights = patches
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let start = k * texel_bytes as usize;
                let texels: &[f32] =
                    bytemuck::cast_slice(&bytes[start..start + texel_bytes as usize]);
                PatchHeights {
                    patch: *p,
                    n,
                    data: texels.to_vec(),
                }
            })
            .collect();
        Ok(GpuPatches { heights, ranges })
    });
    pool.release_slots(ctx, bindless);
    out
}

/// The image `place` lies in, or an error naming it.
fn pool_image<'a>(
    image: impl Fn(SlotLayer) -> Option<&'a Image>,
    place: SlotLayer,
) -> Result<&'a Image, GpuError> {
    image(place).ok_or_else(|| GpuError::Invalid(format!("no height texture at {place:?}")))
}
