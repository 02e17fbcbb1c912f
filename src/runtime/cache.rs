//! The patch cache: the patches whose data is resident, each with its payload (the renderer's textures and what
//! it knows of them), and which were used when. Least recently used patches are evicted beyond the budget and
//! handed back, for their owner to free; the six roots stay, so every patch always has a resident ancestor to
//! stand in for it while its own data is on the way.

use crate::planet::cube::{PatchId, PatchMap};

struct Entry<D> {
    data: D,
    last_used: u64,
}

/// Resident patches with payload `D`, with LRU eviction beyond `capacity` patches.
pub struct PatchCache<D> {
    entries: PatchMap<Entry<D>>,
    /// Patches held at most.
    pub capacity: usize,
    frame: u64,
}

impl<D> PatchCache<D> {
    /// An empty cache of `capacity` patches (at least the six roots).
    pub fn new(capacity: usize) -> Self {
        Self {
            entries: PatchMap::default(),
            capacity: capacity.max(6),
            frame: 0,
        }
    }

    /// Starts a new frame (for recency).
    pub fn next_frame(&mut self) {
        self.frame += 1;
    }

    /// Whether `patch` is resident (without marking it used).
    pub fn contains(&self, patch: &PatchId) -> bool {
        self.entries.contains_key(patch)
    }

    /// The data of a resident patch, marked as used this frame.
    pub fn touch(&mut self, patch: &PatchId) -> Option<&D> {
        let frame = self.frame;
        self.entries.get_mut(patch).map(|e| {
            e.last_used = frame;
            &e.data
        })
    }

    /// The data of a resident patch, without marking it used.
    pub fn peek(&self, patch: &PatchId) -> Option<&D> {
        self.entries.get(patch).map(|e| &e.data)
    }

    /// The data of a resident patch to change, without marking it used.
    pub fn get_mut(&mut self, patch: &PatchId) -> Option<&mut D> {
        self.entries.get_mut(patch).map(|e| &mut e.data)
    }

    /// Makes `patch` resident with `data`, used this frame; hands back what it held before.
    pub fn insert(&mut self, patch: PatchId, data: D) -> Option<D> {
        let entry = Entry {
            data,
            last_used: self.frame,
        };
        self.entries.insert(patch, entry).map(|e| e.data)
    }

    /// The patch itself if resident, or else its nearest resident ancestor, with its data.
    pub fn nearest_resident(&self, patch: PatchId) -> Option<(PatchId, &D)> {
        let mut p = Some(patch);
        while let Some(q) = p {
            if let Some(e) = self.entries.get(&q) {
                return Some((q, &e.data));
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

    /// Resident patches.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether none is resident.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// Every resident patch's data.
    pub fn values(&self) -> impl Iterator<Item = &D> {
        self.entries.values().map(|e| &e.data)
    }

    /// Evicts least recently used patches (never the roots, never one used this frame) until at most `target`
    /// remain (or only protected ones), and hands their data back.
    pub fn evict_to(&mut self, target: usize) -> Vec<D> {
        if self.entries.len() <= target {
            return Vec::new();
        }
        let mut candidates: Vec<(u64, PatchId)> = self
            .entries
            .iter()
            .filter(|(id, e)| id.level > 0 && e.last_used < self.frame)
            .map(|(id, e)| (e.last_used, *id))
            .collect();
        candidates.sort();
        let excess = self.entries.len() - target;
        candidates
            .into_iter()
            .take(excess)
            .filter_map(|(_, id)| self.entries.remove(&id).map(|e| e.data))
            .collect()
    }

    /// Empties the cache (at shutdown), handing every patch's data back.
    pub fn drain(&mut self) -> Vec<D> {
        self.entries.drain().map(|(_, e)| e.data).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn patch(level: u8, x: u32) -> PatchId {
        PatchId {
            face: 0,
            level,
            x,
            y: 0,
        }
    }

    #[test]
    fn eviction_hands_back_the_least_recently_used_and_keeps_roots_and_this_frame() {
        let mut cache = PatchCache::new(6);
        cache.insert(patch(0, 0), "root");
        cache.insert(patch(1, 0), "old");
        cache.next_frame();
        cache.insert(patch(1, 1), "newer");
        cache.next_frame();
        cache.insert(patch(2, 0), "current");
        assert_eq!(cache.evict_to(2), vec!["old", "newer"]);
        assert_eq!(cache.evict_to(0), Vec::<&str>::new());
        assert_eq!(cache.len(), 2);
        assert_eq!(
            cache.nearest_resident(patch(2, 1)),
            Some((patch(0, 0), &"root"))
        );
        assert_eq!(cache.resident_ancestor(patch(3, 0)), Some(patch(2, 0)));
    }
}
