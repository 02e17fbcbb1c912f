//! What the renderer keeps of a resident patch (the payload of `runtime::cache::PatchCache`): where its
//! base-height texture and (if a river influences it) its river texture lie, each a layer or layers of the
//! renderer's array images ([`PatchTextures`]), and what it knows of their heights.

use crate::{
    gpu::{
        bindless::{Bindless, SlotLayer},
        layers::LayerPool,
        Context, GpuError,
    },
    kernel::gpu::river_textures,
    refine::height_textures,
};

/// A patch's resident data.
pub struct PatchData {
    /// Where its base heights lie.
    pub base: SlotLayer,
    /// Where its river data lies, if a river influences it.
    pub river: Option<SlotLayer>,
    /// Whether the samples were the rivers' final detail: then children take river data from this patch (10.2).
    pub river_final: bool,
    /// Lowest and highest base height (with the border): whether the patch can show sea, and the bounds of its
    /// vertices for the level of detail. Exact once known (uploaded, or read back after refinement).
    pub height_range: (f32, f32),
    /// The heights river beds and water can take in the patch (its samples' heights widened by the basin
    /// depth), which may lie below the base heights where a river cuts through high ground.
    pub river_range: Option<(f32, f32)>,
}

impl PatchData {
    /// Lowest and highest height a drawn vertex of the patch can have: base heights and river beds.
    pub fn surface_range(&self) -> (f32, f32) {
        let (lo, hi) = self.height_range;
        self.river_range
            .map_or((lo, hi), |(a, b)| (lo.min(a), hi.max(b)))
    }

    /// Bytes of its textures.
    pub fn bytes(&self, textures: &PatchTextures) -> u64 {
        textures.heights.texture_bytes() + self.river.map_or(0, |_| textures.rivers.texture_bytes())
    }

    /// Frees its textures' layers once the frames in flight are done with them.
    pub fn release(self, ctx: &Context, textures: &mut PatchTextures) {
        textures.heights.release(ctx, self.base);
        if let Some(place) = self.river {
            textures.rivers.release(ctx, place);
        }
    }
}

/// The kinds of patch texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureKind {
    /// Base heights.
    Heights,
    /// River data.
    River,
}

/// Every resident patch's textures, by kind: base heights (a layer each) and river data (three layers each) in a
/// few array images per kind, made as the resident set grows (docs/rendering.md, "Patch textures as layers").
pub struct PatchTextures {
    /// Base heights.
    pub heights: LayerPool,
    /// River data.
    pub rivers: LayerPool,
}

impl PatchTextures {
    /// Room for `patches` textures of each kind of patches of `vertices` a side; no image is made yet.
    pub fn new(vertices: u32, patches: usize) -> Result<Self, GpuError> {
        Ok(Self {
            heights: LayerPool::new(height_textures(vertices), patches)?,
            rivers: LayerPool::new(river_textures(vertices), patches)?,
        })
    }

    /// Bindless slots the images of `patches` textures of each kind take at most.
    pub fn slots_for(patches: usize) -> usize {
        let kinds = [1, crate::kernel::gpu::RIVER_TEXTURE_LAYERS];
        kinds
            .iter()
            .map(|&layers| LayerPool::images_for(patches, layers))
            .sum()
    }

    /// A free place for a texture of `kind`, `Ok(None)` when the kind's room is in use.
    pub fn allocate(
        &mut self,
        ctx: &Context,
        bindless: &mut Bindless,
        kind: TextureKind,
    ) -> Result<Option<SlotLayer>, GpuError> {
        match kind {
            TextureKind::Heights => self.heights.allocate(ctx, bindless),
            TextureKind::River => self.rivers.allocate(ctx, bindless),
        }
    }

    /// Places released but still read by frames in flight.
    pub fn pending_release(&self) -> usize {
        self.heights.pending_release() + self.rivers.pending_release()
    }
}
