//! What the renderer keeps of a resident patch (the payload of `runtime::cache::PatchCache`): its base-height
//! texture and (if a river influences it) its river texture, each in a slot of the bindless array, and what it
//! knows of their heights.

use crate::gpu::{
    bindless::{Bindless, Slot},
    Context, Format, Image,
};

/// A patch's resident data.
pub struct PatchData {
    pub base: Image,
    pub base_slot: Slot,
    pub river: Option<(Image, Slot)>,
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
    pub fn bytes(&self) -> u64 {
        let size =
            |i: &Image| (i.extent.width * i.extent.height * i.layers) as u64 * texel_bytes(i);
        size(&self.base) + self.river.as_ref().map_or(0, |(i, _)| size(i))
    }

    /// Frees its bindless slots; its images are retired as it drops.
    pub fn release(self, ctx: &Context, bindless: &mut Bindless) {
        bindless.release(ctx, self.base_slot);
        if let Some((_, slot)) = self.river {
            bindless.release(ctx, slot);
        }
    }
}

fn texel_bytes(image: &Image) -> u64 {
    match image.format {
        Format::R32G32B32A32_SFLOAT => 16,
        _ => 4,
    }
}
