//! Patch upload: the new patches' data on the GPU. Base heights of the precomputed levels are cut on the CPU and
//! uploaded, finer ones refined from their parents by `refine` (one dispatch per level); river samples (6.3-6.4)
//! go to one kernel dispatch for all new river patches (Chapter 7).

use std::collections::HashMap;

use rayon::prelude::*;

use super::{resident::PatchData, Renderer};
use crate::{
    gpu::{bindless::Slot, Access, GpuError, Image, Recorder},
    kernel::{
        gpu::{create_river_texture, KernelBatch},
        ParentQuadrant, PatchJob, RiverSample,
    },
    planet::{cube::PatchId, detail::PatchHeights},
    refine::{create_height_texture, prepare_height_textures, RefineJob, RefinedRanges},
    river::samples::{patch_samples, PatchFrame},
};

/// A patch that gets its data this frame: base heights from the precomputed lattice (`None`: refined on the GPU
/// from its parent's), and its river samples.
pub(super) struct NewPatch {
    patch: PatchId,
    heights: Option<PatchHeights>,
    pub samples: Vec<RiverSample>,
    /// Whether the samples are the rivers' final detail (children may take river data from this patch).
    final_detail: bool,
}

/// What recording the new patches left for after the frame.
pub(super) struct Uploaded {
    /// Temporary bytes: samples, range and job tables.
    pub bytes: u64,
    pub river_patches: usize,
    /// River patches that took their even vertices from their parent.
    pub river_patches_from_parent: usize,
    /// Where the refined patches' height ranges arrive.
    pub ranges: Option<RefinedRanges>,
}

impl Renderer<'_> {
    /// Sections 6.3-6.4 for the patches of `plan`, in parallel: base heights of precomputed levels (finer ones are
    /// refined on the GPU) and river samples.
    pub(super) fn prepare(&self, plan: &[PatchId]) -> Vec<NewPatch> {
        let planet = self.planet;
        let network = self.network;
        let n = self.config.rendering.vertices;
        let precomputed = planet.precomputed_level;
        plan.par_iter()
            .map(|&p| {
                let samples = patch_samples(network, &PatchFrame::new(p, planet.radius, n));
                NewPatch {
                    patch: p,
                    heights: (p.level as u32 <= precomputed)
                        .then(|| planet.lattice.patch_heights(p, n)),
                    samples: samples.samples,
                    final_detail: samples.final_detail,
                }
            })
            .collect()
    }

    /// Creates the textures of new patches; uploads the base heights of precomputed levels and refines the rest
    /// from their parents on the GPU (parents first, one dispatch per level); then computes all river textures in
    /// one kernel dispatch. Returns the temporary bytes (samples, job tables), how many patches have rivers, and
    /// where the refined patches' height ranges arrive.
    pub(super) fn upload_new_patches(
        &mut self,
        rec: &mut Recorder,
        prepared: &[NewPatch],
    ) -> Result<Uploaded, GpuError> {
        if prepared.is_empty() {
            return Ok(Uploaded {
                bytes: 0,
                river_patches: 0,
                river_patches_from_parent: 0,
                ranges: None,
            });
        }
        let ctx = self.ctx;
        let n = self.config.rendering.vertices;
        let mut bases: Vec<(Image, Slot)> = Vec::with_capacity(prepared.len());
        for p in prepared {
            let image = create_height_texture(ctx, n, &format!("base heights {:?}", p.patch))?;
            let slot = self.slot()?;
            self.bindless.write(ctx, slot, &image, true);
            bases.push((image, slot));
        }
        let base_refs: Vec<&Image> = bases.iter().map(|(i, _)| i).collect();
        prepare_height_textures(rec, &base_refs);
        // Slot and height range (border included) of each new patch: exact for uploaded ones, a bound for
        // refined ones until the shader's own range is read back after the frame.
        let mut made: HashMap<PatchId, (Slot, (f32, f32))> = HashMap::new();
        let mut jobs: Vec<RefineJob> = Vec::new();
        for (p, (image, slot)) in prepared.iter().zip(&bases) {
            let range = match &p.heights {
                Some(heights) => {
                    rec.upload_image_layer(image, 0, bytemuck::cast_slice(&heights.data))?;
                    heights.range()
                }
                None => {
                    let parent = p.patch.parent().expect("refined patches have parents");
                    let (parent_slot, (lo, hi)) = match made.get(&parent) {
                        Some(&made) => made,
                        None => {
                            let data = self.cache.touch(&parent).ok_or_else(|| {
                                GpuError::Invalid(format!("{:?} has no resident parent", p.patch))
                            })?;
                            (data.base_slot, data.height_range)
                        }
                    };
                    jobs.push(RefineJob {
                        patch: p.patch,
                        slot: *slot,
                        parent_slot,
                    });
                    let extra = self.planet.rule.remaining_range(p.patch.level as u32 - 1);
                    (lo - extra, hi + extra)
                }
            };
            made.insert(p.patch, (*slot, range));
        }
        let mut bytes = 0;
        let mut ranges = None;
        if !jobs.is_empty() {
            // The parents' textures: made in this frame, or resident from an earlier one.
            let made_here: HashMap<Slot, &Image> = bases.iter().map(|(i, s)| (*s, i)).collect();
            let cache = &self.cache;
            let parent_texture = |job: &RefineJob| {
                made_here
                    .get(&job.parent_slot)
                    .copied()
                    .or_else(|| cache.peek(&job.patch.parent()?).map(|data| &data.base))
            };
            let (refiner, bindless, planet) = (&self.refiner, &self.bindless, self.planet);
            ranges = self.frames.profiler().scope(rec, "heights", |rec| {
                refiner.record(rec, (bindless, planet), &jobs, parent_texture)
            })??;
            bytes += ranges.as_ref().map_or(0, |r| r.bytes);
        }
        // Read by the terrain's shaders, and by the vertex cache's compute pass before them (draw.rs): without the
        // compute stage here, a GPU could compute a new patch's vertices before its heights were written.
        rec.use_images(
            &base_refs,
            &[Access::GraphicsSampled, Access::ComputeSampled],
        );

        let mut rivers: Vec<(Image, Slot)> = Vec::new();
        let mut patch_jobs: Vec<PatchJob> = Vec::new();
        let mut parents: Vec<Option<(Slot, ParentQuadrant)>> = Vec::new();
        let mut river_of: Vec<Option<usize>> = Vec::with_capacity(prepared.len());
        for p in prepared {
            if p.samples.is_empty() {
                river_of.push(None);
                continue;
            }
            let slot = self.slot()?;
            let image = create_river_texture(ctx, n, &format!("river data {:?}", p.patch))?;
            self.bindless.write(ctx, slot, &image, true);
            patch_jobs.push(PatchJob {
                spacing: PatchFrame::new(p.patch, self.planet.radius, n).spacing() as f32,
                samples: &p.samples,
            });
            parents.push(self.river_parent(p.patch));
            river_of.push(Some(rivers.len()));
            rivers.push((image, slot));
        }
        let slots: Vec<Slot> = rivers.iter().map(|(_, s)| *s).collect();
        if let (false, Some(observe)) = (patch_jobs.is_empty(), &mut self.kernel_observer) {
            observe(&patch_jobs);
        }
        if !rivers.is_empty() {
            let textures: Vec<&Image> = rivers.iter().map(|(i, _)| i).collect();
            // The resident parents' river textures (made in earlier frames), each once.
            let mut parent_patches: Vec<PatchId> = prepared
                .iter()
                .zip(&river_of)
                .filter(|(_, river)| river.is_some_and(|k| parents[k].is_some()))
                .filter_map(|(p, _)| p.patch.parent())
                .collect();
            parent_patches.sort_unstable();
            parent_patches.dedup();
            let parent_textures: Vec<&Image> = parent_patches
                .iter()
                .filter_map(|q| self.cache.peek(q)?.river.as_ref().map(|(image, _)| image))
                .collect();
            let batch = KernelBatch {
                textures: &textures,
                slots: &slots,
                jobs: &patch_jobs,
                parents: &parents,
                parent_textures: &parent_textures,
            };
            let (kernel, bindless, variant, params) =
                (&self.kernel, &self.bindless, self.variant, &self.params);
            bytes += self.frames.profiler().scope(rec, "kernel", |rec| {
                kernel.record(rec, bindless, variant, &batch, params)
            })??;
            rec.use_images(
                &textures,
                &[Access::GraphicsSampled, Access::ComputeSampled],
            );
        }
        let river_count = rivers.len();
        let mut rivers: Vec<Option<(Image, Slot)>> = rivers.into_iter().map(Some).collect();
        for ((p, (base, slot)), river) in prepared.iter().zip(bases).zip(river_of) {
            let river = river.and_then(|k| rivers[k].take());
            self.cache.insert(
                p.patch,
                PatchData {
                    base,
                    base_slot: slot,
                    river,
                    river_final: p.final_detail,
                    height_range: made[&p.patch].1,
                    river_range: river_range(&p.samples, self.config.river.basin_depth),
                },
            );
        }
        Ok(Uploaded {
            bytes,
            river_patches: river_count,
            river_patches_from_parent: parents.iter().flatten().count(),
            ranges,
        })
    }
}

impl Renderer<'_> {
    /// Where `patch` takes river data from (10.2): its parent's river texture and quadrant, when parent reuse is
    /// on and the resident parent has the rivers' final detail (it was made in an earlier frame: the cache
    /// holds only those).
    fn river_parent(&mut self, patch: PatchId) -> Option<(Slot, ParentQuadrant)> {
        if !self.parent_reuse {
            return None;
        }
        let quadrant = ParentQuadrant::of(patch, self.config.rendering.vertices)?;
        let data = self.cache.touch(&patch.parent()?)?;
        let (_, slot) = data.river.as_ref().filter(|_| data.river_final)?;
        Some((*slot, quadrant))
    }
}

/// The heights river beds and water can take near `samples`: their heights widened by the basin depth.
fn river_range(samples: &[RiverSample], basin_depth: f32) -> Option<(f32, f32)> {
    samples
        .iter()
        .map(|s| s.height)
        .fold(None, |range: Option<(f32, f32)>, h| {
            Some(range.map_or((h, h), |(lo, hi)| (lo.min(h), hi.max(h))))
        })
        .map(|(lo, hi)| (lo - basin_depth, hi + basin_depth))
}
