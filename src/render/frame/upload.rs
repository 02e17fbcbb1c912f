//! Patch upload: the new patches' data on the GPU. Base heights of the precomputed levels are cut on the CPU and
//! uploaded, finer ones refined from their parents by `refine` (one dispatch per level); river samples (6.3-6.4)
//! go to one kernel dispatch for all new river patches (Chapter 7).

use std::collections::HashMap;

use rayon::prelude::*;

use super::{
    resident::{PatchData, TextureKind},
    Renderer,
};
use crate::{
    gpu::{bindless::SlotLayer, Access, GpuError, Recorder},
    kernel::{gpu::KernelBatch, ParentQuadrant, PatchJob, RiverSample},
    planet::{cube::PatchId, detail::PatchHeights},
    refine::{prepare_height_textures, RefineJob, RefinedRanges},
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
        let n = self.config.rendering.vertices;
        let bases = (0..prepared.len())
            .map(|_| self.texture_place(TextureKind::Heights))
            .collect::<Result<Vec<SlotLayer>, GpuError>>()?;
        prepare_height_textures(rec, &self.textures.heights.images(bases.iter().copied()));
        // Place and height range (border included) of each new patch: exact for uploaded ones, a bound for
        // refined ones until the shader's own range is read back after the frame.
        let mut made: HashMap<PatchId, (SlotLayer, (f32, f32))> = HashMap::new();
        let mut jobs: Vec<RefineJob> = Vec::new();
        for (p, &place) in prepared.iter().zip(&bases) {
            let range = match &p.heights {
                Some(heights) => {
                    let image = self.textures.heights.image(place).ok_or_else(|| {
                        GpuError::Invalid(format!("no height image at {place:?}"))
                    })?;
                    rec.upload_image_layer(
                        image,
                        place.layer,
                        bytemuck::cast_slice(&heights.data),
                    )?;
                    heights.range()
                }
                None => {
                    let parent = p.patch.parent().expect("refined patches have parents");
                    let (parent_place, (lo, hi)) = match made.get(&parent) {
                        Some(&made) => made,
                        None => {
                            let data = self.cache.touch(&parent).ok_or_else(|| {
                                GpuError::Invalid(format!("{:?} has no resident parent", p.patch))
                            })?;
                            (data.base, data.height_range)
                        }
                    };
                    jobs.push(RefineJob {
                        patch: p.patch,
                        place,
                        parent_place,
                    });
                    let extra = self.planet.rule.remaining_range(p.patch.level as u32 - 1);
                    (lo - extra, hi + extra)
                }
            };
            made.insert(p.patch, (place, range));
        }
        let mut bytes = 0;
        let mut ranges = None;
        if !jobs.is_empty() {
            let (refiner, bindless, planet) = (&self.refiner, &self.bindless, self.planet);
            let heights = &self.textures.heights;
            ranges = self.frames.profiler().scope(rec, "heights", |rec| {
                refiner.record(rec, (bindless, planet), &jobs, |place| heights.image(place))
            })??;
            bytes += ranges.as_ref().map_or(0, |r| r.bytes);
        }
        // Read by the terrain's shaders, and by the vertex cache's compute pass before them (draw.rs): without the
        // compute stage here, a GPU could compute a new patch's vertices before its heights were written.
        rec.use_images(
            &self.textures.heights.images(bases.iter().copied()),
            &[Access::GraphicsSampled, Access::ComputeSampled],
        );

        let mut rivers: Vec<SlotLayer> = Vec::new();
        let mut patch_jobs: Vec<PatchJob> = Vec::new();
        let mut parents: Vec<Option<(SlotLayer, ParentQuadrant)>> = Vec::new();
        let mut river_of: Vec<Option<usize>> = Vec::with_capacity(prepared.len());
        for p in prepared {
            if p.samples.is_empty() {
                river_of.push(None);
                continue;
            }
            let place = self.texture_place(TextureKind::River)?;
            patch_jobs.push(PatchJob {
                spacing: PatchFrame::new(p.patch, self.planet.radius, n).spacing() as f32,
                samples: &p.samples,
            });
            parents.push(self.river_parent(p.patch));
            river_of.push(Some(rivers.len()));
            rivers.push(place);
        }
        if let (false, Some(observe)) = (patch_jobs.is_empty(), &mut self.kernel_observer) {
            observe(&patch_jobs);
        }
        if !rivers.is_empty() {
            let river_images = &self.textures.rivers;
            let textures = river_images.images(rivers.iter().copied());
            // The resident parents' river textures (made in earlier frames), each image once.
            let parent_textures =
                river_images.images(parents.iter().flatten().map(|(place, _)| *place));
            let batch = KernelBatch {
                textures: &textures,
                places: &rivers,
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
        for ((p, base), river) in prepared.iter().zip(bases).zip(river_of) {
            self.cache.insert(
                p.patch,
                PatchData {
                    base,
                    river: river.map(|k| rivers[k]),
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
    fn river_parent(&mut self, patch: PatchId) -> Option<(SlotLayer, ParentQuadrant)> {
        if !self.parent_reuse {
            return None;
        }
        let quadrant = ParentQuadrant::of(patch, self.config.rendering.vertices)?;
        let data = self.cache.touch(&patch.parent()?)?;
        let place = data.river.filter(|_| data.river_final)?;
        Some((place, quadrant))
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
