//! The patch cache: for every patch whose data is on the GPU, its base-height texture and (if a river
//! influences it) its river texture, each in a slot of the bindless array. Least recently used patches are
//! evicted beyond the budget; the six roots stay, so every patch always has a resident ancestor to stand in for it
//! while its own data is on the way.

use std::collections::HashMap;

use crate::{
    gpu::{
        bindless::{Bindless, Slot},
        Context, Image,
    },
    planet::cube::PatchId,
};

/// A patch's resident data.
pub struct PatchData {
    pub base: Image,
    pub base_slot: Slot,
    pub river: Option<(Image, Slot)>,
    pub samples: usize,
    /// Whether the samples were the rivers' final detail: then children take river data from this patch (10.2).
    pub river_final: bool,
    /// Lowest and highest base height (with the border): whether the patch can show sea, and the bounds of its
    /// vertices for the level of detail. Exact once known (uploaded, or read back after refinement).
    pub height_range: (f32, f32),
    /// The heights river beds and water can take in the patch (its samples' heights widened by the basin
    /// depth), which may lie below the base heights where a river cuts through high ground.
    pub river_range: Option<(f32, f32)>,
    last_used: u64,
}

impl PatchData {
    pub fn new(
        (base, base_slot): (Image, Slot),
        river: Option<(Image, Slot)>,
        (samples, river_final): (usize, bool),
        height_range: (f32, f32),
        river_range: Option<(f32, f32)>,
    ) -> Self {
        Self {
            base,
            base_slot,
            river,
            samples,
            river_final,
            height_range,
            river_range,
            last_used: 0,
        }
    }

    /// Lowest and highest height a drawn vertex of the patch can have: base heights and river beds.
    pub fn surface_range(&self) -> (f32, f32) {
        let (lo, hi) = self.height_range;
        self.river_range
            .map_or((lo, hi), |(a, b)| (lo.min(a), hi.max(b)))
    }

    pub fn bytes(&self) -> u64 {
        let size =
            |i: &Image| (i.extent.width * i.extent.height * i.layers) as u64 * texel_bytes(i);
        size(&self.base) + self.river.as_ref().map_or(0, |(i, _)| size(i))
    }
}

fn texel_bytes(image: &Image) -> u64 {
    use crate::gpu::Format;
    match image.format {
        Format::R32G32B32A32_SFLOAT => 16,
        _ => 4,
    }
}

/// Resident patches, with LRU eviction beyond `capacity` patches.
pub struct PatchCache {
    entries: HashMap<PatchId, PatchData>,
    pub capacity: usize,
    frame: u64,
}

impl PatchCache {
    pub fn new(capacity: usize) -> Self {
        Self {
            entries: HashMap::new(),
            capacity: capacity.max(6),
            frame: 0,
        }
    }

    /// Starts a new frame (for recency).
    pub fn next_frame(&mut self) {
        self.frame += 1;
    }

    pub fn contains(&self, patch: &PatchId) -> bool {
        self.entries.contains_key(patch)
    }

    /// The data of a resident patch, marked as used this frame.
    pub fn touch(&mut self, patch: &PatchId) -> Option<&PatchData> {
        let frame = self.frame;
        self.entries.get_mut(patch).map(|e| {
            e.last_used = frame;
            &*e
        })
    }

    pub fn insert(&mut self, patch: PatchId, mut data: PatchData) {
        data.last_used = self.frame;
        self.entries.insert(patch, data);
    }

    /// Replaces a resident patch's height range (the exact one, read back after its refinement).
    pub fn set_height_range(&mut self, patch: &PatchId, range: (f32, f32)) {
        if let Some(e) = self.entries.get_mut(patch) {
            e.height_range = range;
        }
    }

    /// The patch itself if resident, or else its nearest resident ancestor, with its data.
    pub fn nearest_resident(&self, patch: PatchId) -> Option<(PatchId, &PatchData)> {
        let mut p = Some(patch);
        while let Some(q) = p {
            if let Some(data) = self.entries.get(&q) {
                return Some((q, data));
            }
            p = q.parent();
        }
        None
    }

    /// The nearest resident ancestor of `patch`.
    pub fn resident_ancestor(&self, patch: PatchId) -> Option<PatchId> {
        let mut p = patch.parent();
        while let Some(a) = p {
            if self.entries.contains_key(&a) {
                return Some(a);
            }
            p = a.parent();
        }
        None
    }

    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Bytes of all resident patch textures.
    pub fn bytes(&self) -> u64 {
        self.entries.values().map(PatchData::bytes).sum()
    }

    /// Evicts least recently used patches (never the roots, never one used this frame) until at most `target`
    /// remain (or only protected ones); their textures are freed once the GPU is done with them. Returns how many
    /// were evicted.
    pub fn evict_to(&mut self, target: usize, ctx: &Context, bindless: &mut Bindless) -> usize {
        if self.entries.len() <= target {
            return 0;
        }
        let mut candidates: Vec<(u64, PatchId)> = self
            .entries
            .iter()
            .filter(|(id, e)| id.level > 0 && e.last_used < self.frame)
            .map(|(id, e)| (e.last_used, *id))
            .collect();
        candidates.sort();
        let excess = self.entries.len() - target;
        let mut evicted = 0;
        for (_, id) in candidates.into_iter().take(excess) {
            if let Some(data) = self.entries.remove(&id) {
                release(ctx, bindless, data);
                evicted += 1;
            }
        }
        evicted
    }

    /// Frees everything (at shutdown).
    pub fn clear(&mut self, ctx: &Context, bindless: &mut Bindless) {
        for (_, data) in self.entries.drain() {
            release(ctx, bindless, data);
        }
    }
}

/// Frees `data`'s bindless slots; its images are retired as it drops.
fn release(ctx: &Context, bindless: &mut Bindless, data: PatchData) {
    bindless.release(ctx, data.base_slot);
    if let Some((_, slot)) = data.river {
        bindless.release(ctx, slot);
    }
}
