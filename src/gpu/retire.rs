//! Deferred destruction and reuse. A dropped buffer or image (or pipeline, layout, sampler or pool, through
//! `RetireOnDrop`) is retired: freed only after the GPU has finished every submission made before it was dropped,
//! and the submission of any recording open when it was dropped (Granite's per-frame lists, keyed here by
//! timeline-semaphore value). Dropping is retiring, so none can leak by being forgotten, and no owner calls
//! `destroy`. A retired buffer or image whose GPU work is done is kept (the latest, up to [`RECYCLED_BYTES`]) for
//! the next request of the same shape (kajiya's transient resource cache): the frame loop's staging, instance and
//! per-dispatch buffers come back instead of being created again. Slots and texture layers handed back wait in a
//! `Released` queue the same way.

use std::{
    collections::VecDeque,
    sync::{
        atomic::{AtomicU64, Ordering},
        Arc, Mutex,
    },
};

use ash::vk;
use gpu_allocator::vulkan::{Allocation, Allocator};
use gpu_allocator::MemoryLocation;

use super::Context;

/// The most memory kept for reuse; beyond it, the longest kept buffers and images are freed.
pub const RECYCLED_BYTES: u64 = 64 << 20;

/// What a buffer must be to serve a request: its usage, memory and capacity class (memory.rs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct BufferShape {
    pub(super) usage: vk::BufferUsageFlags,
    pub(super) location: MemoryLocation,
    pub(super) capacity: u64,
}

/// What an image must be to serve a request.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ImageShape {
    pub(super) extent: vk::Extent2D,
    pub(super) format: vk::Format,
    pub(super) layers: u32,
    pub(super) array: bool,
    pub(super) usage: vk::ImageUsageFlags,
}

/// A buffer's handle and memory, without its name and requested size.
pub(super) struct BufferMemory {
    pub(super) raw: vk::Buffer,
    pub(super) allocation: Allocation,
    pub(super) shape: BufferShape,
}

/// An image's handles and memory.
pub(super) struct ImageMemory {
    pub(super) raw: vk::Image,
    pub(super) view: vk::ImageView,
    pub(super) allocation: Allocation,
    pub(super) shape: ImageShape,
}

/// A GPU object waiting to be destroyed (or, a buffer or image, to be reused).
pub(super) enum Retired {
    Buffer(BufferMemory),
    Image(ImageMemory),
    Pool(vk::CommandPool),
    DescriptorPool(vk::DescriptorPool),
    QueryPool(vk::QueryPool),
    Pipeline(vk::Pipeline, vk::PipelineLayout),
    SetLayout(vk::DescriptorSetLayout),
    Sampler(vk::Sampler),
}

/// GPU objects retired when their owner drops (see [`Context::retire_on_drop`]).
pub(super) struct RetireOnDrop {
    items: Vec<Retired>,
    deletion: Arc<DeletionQueue>,
}

impl RetireOnDrop {
    /// Adds an object just created, so that a failure further on retires it with the rest.
    pub(super) fn push(&mut self, item: Retired) {
        self.items.push(item);
    }
}

impl Drop for RetireOnDrop {
    fn drop(&mut self) {
        for item in self.items.drain(..) {
            self.deletion.retire(item);
        }
    }
}

/// Objects retired and when they may be destroyed.
#[derive(Default)]
struct Pending {
    /// Each with the timeline value that must complete first.
    tagged: Vec<(u64, Retired)>,
    /// Retired while a recording was open: that recording may use them, and its submission's value is not known
    /// yet, so they wait for every open recording to be submitted (or abandoned) and take the value then.
    awaiting: Vec<Retired>,
    /// Recordings begun and not yet submitted or dropped.
    open: usize,
}

/// Buffers and images the GPU is done with, kept for reuse, in the order they were retired (only those two kinds).
#[derive(Default)]
struct Recycled {
    kept: VecDeque<Retired>,
    bytes: u64,
}

impl Recycled {
    fn push(&mut self, item: Retired) {
        self.bytes += item.bytes();
        self.kept.push_back(item);
    }

    /// Takes out the kept object that `matches` accepts with the least `key`, if any.
    fn take(
        &mut self,
        matches: impl Fn(&Retired) -> bool,
        key: impl Fn(&Retired) -> u64,
    ) -> Option<Retired> {
        let (at, _) = (self.kept.iter().enumerate())
            .filter(|(_, item)| matches(item))
            .min_by_key(|(_, item)| key(item))?;
        let item = self.kept.remove(at)?;
        self.bytes -= item.bytes();
        Some(item)
    }

    /// Takes out the longest kept objects until at most `bytes` are kept: what was retired last is the most likely
    /// to be asked for again.
    fn trim(&mut self, bytes: u64) -> Vec<Retired> {
        let mut out = Vec::new();
        while self.bytes > bytes {
            let Some(item) = self.kept.pop_front() else {
                break;
            };
            self.bytes -= item.bytes();
            out.push(item);
        }
        out
    }
}

impl Retired {
    /// The memory a kept buffer or image holds.
    fn bytes(&self) -> u64 {
        match self {
            Retired::Buffer(b) => b.allocation.size(),
            Retired::Image(i) => i.allocation.size(),
            _ => 0,
        }
    }
}

/// Resources waiting for the GPU to finish with them, and those kept for reuse. With no recording open, what is
/// retired waits for the last submission (`submitted`, shared with the timeline); with recordings open, for the last
/// of their submissions: an object dropped after a command that uses it was recorded lives until that command has
/// run.
pub(crate) struct DeletionQueue {
    pending: Mutex<Pending>,
    recycled: Mutex<Recycled>,
    submitted: Arc<AtomicU64>,
    /// Buffers and images created (not reused) so far.
    created: AtomicU64,
}

impl DeletionQueue {
    pub(crate) fn new(submitted: Arc<AtomicU64>) -> Self {
        Self {
            pending: Mutex::new(Pending::default()),
            recycled: Mutex::new(Recycled::default()),
            submitted,
            created: AtomicU64::new(0),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Pending> {
        self.pending.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn lock_recycled(&self) -> std::sync::MutexGuard<'_, Recycled> {
        self.recycled.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(super) fn retire(&self, item: Retired) {
        let mut pending = self.lock();
        if pending.open == 0 {
            let after = self.submitted.load(Ordering::Acquire);
            pending.tagged.push((after, item));
        } else {
            pending.awaiting.push(item);
        }
    }

    /// A recording began: what is retired from now on may be used by it.
    pub(super) fn recording_opened(&self) {
        self.lock().open += 1;
    }

    /// A recording was submitted (after the timeline took its value) or abandoned. When none is left open, what
    /// waited for them takes the last submitted value.
    pub(super) fn recording_closed(&self) {
        let mut pending = self.lock();
        pending.open = pending.open.saturating_sub(1);
        if pending.open == 0 && !pending.awaiting.is_empty() {
            let after = self.submitted.load(Ordering::Acquire);
            let awaiting = std::mem::take(&mut pending.awaiting);
            pending
                .tagged
                .extend(awaiting.into_iter().map(|item| (after, item)));
        }
    }

    /// The smallest kept buffer of `shape`'s usage and memory that holds its capacity and at most four times it (a
    /// frame's buffers grow and shrink with what it draws), if there is one.
    pub(super) fn reuse_buffer(&self, shape: &BufferShape) -> Option<BufferMemory> {
        let fits = |item: &Retired| {
            matches!(item, Retired::Buffer(b) if b.shape.usage == shape.usage
                && b.shape.location == shape.location
                && (shape.capacity..=4 * shape.capacity).contains(&b.shape.capacity))
        };
        match self.lock_recycled().take(fits, Retired::bytes)? {
            Retired::Buffer(buffer) => Some(buffer),
            _ => None,
        }
    }

    /// A kept image of `shape`, if there is one.
    pub(super) fn reuse_image(&self, shape: &ImageShape) -> Option<ImageMemory> {
        let fits = |item: &Retired| matches!(item, Retired::Image(i) if i.shape == *shape);
        match self.lock_recycled().take(fits, Retired::bytes)? {
            Retired::Image(image) => Some(image),
            _ => None,
        }
    }

    pub(super) fn note_created(&self) {
        self.created.fetch_add(1, Ordering::Relaxed);
    }

    /// Frees every resource whose guarding submission has completed, keeping buffers and images for reuse (the
    /// latest within [`RECYCLED_BYTES`]).
    pub(super) fn collect(
        &self,
        device: &ash::Device,
        allocator: &Mutex<Allocator>,
        completed: u64,
    ) {
        let ready: Vec<Retired> = {
            let mut pending = self.lock();
            let (ready, keep): (Vec<_>, Vec<_>) =
                pending.tagged.drain(..).partition(|(v, _)| *v <= completed);
            pending.tagged = keep;
            ready.into_iter().map(|(_, r)| r).collect()
        };
        let mut freed = Vec::new();
        {
            let mut recycled = self.lock_recycled();
            for item in ready {
                match item {
                    Retired::Buffer(_) | Retired::Image(_) => recycled.push(item),
                    item => freed.push(item),
                }
            }
            freed.extend(recycled.trim(RECYCLED_BYTES));
        }
        destroy(device, allocator, freed);
    }

    /// Frees what is kept for reuse.
    pub(super) fn release_recycled(&self, device: &ash::Device, allocator: &Mutex<Allocator>) {
        let recycled = std::mem::take(&mut *self.lock_recycled());
        destroy(device, allocator, recycled.kept.into());
    }

    /// Frees everything, awaiting, pending or kept (at the context's end, with the device idle).
    pub(crate) fn flush_all(&self, device: &ash::Device, allocator: &Mutex<Allocator>) {
        let items: Vec<Retired> = {
            let mut pending = self.lock();
            let awaiting = std::mem::take(&mut pending.awaiting);
            let tagged = std::mem::take(&mut pending.tagged);
            tagged
                .into_iter()
                .map(|(_, item)| item)
                .chain(awaiting)
                .collect()
        };
        destroy(device, allocator, items);
        self.release_recycled(device, allocator);
    }
}

/// Destroys `items` and frees their memory.
fn destroy(device: &ash::Device, allocator: &Mutex<Allocator>, items: Vec<Retired>) {
    if items.is_empty() {
        return;
    }
    let mut allocator = allocator.lock().unwrap_or_else(|e| e.into_inner());
    for item in items {
        // SAFETY: the GPU finished every submission that could use these objects (timeline value reached, or the
        // device is idle).
        unsafe {
            match item {
                Retired::Buffer(b) => {
                    device.destroy_buffer(b.raw, None);
                    let _ = allocator.free(b.allocation);
                }
                Retired::Image(i) => {
                    device.destroy_image_view(i.view, None);
                    device.destroy_image(i.raw, None);
                    let _ = allocator.free(i.allocation);
                }
                Retired::Pool(p) => device.destroy_command_pool(p, None),
                Retired::DescriptorPool(p) => device.destroy_descriptor_pool(p, None),
                Retired::QueryPool(q) => device.destroy_query_pool(q, None),
                Retired::Pipeline(p, l) => {
                    device.destroy_pipeline(p, None);
                    device.destroy_pipeline_layout(l, None);
                }
                Retired::SetLayout(l) => device.destroy_descriptor_set_layout(l, None),
                Retired::Sampler(s) => device.destroy_sampler(s, None),
            }
        }
    }
}

impl Context {
    /// A guard that retires `items` (through the deletion queue, as a dropped buffer is) when it drops: the
    /// owner of pipelines, layouts, samplers and pools holds one, and needs no `destroy` call.
    pub(super) fn retire_on_drop(&self, items: Vec<Retired>) -> RetireOnDrop {
        RetireOnDrop {
            items,
            deletion: self.deletion.clone(),
        }
    }

    /// Objects retired and not yet destroyed or kept for reuse (the GPU may still use them).
    pub fn retired_objects(&self) -> usize {
        let pending = self.deletion.lock();
        pending.tagged.len() + pending.awaiting.len()
    }

    /// Buffers and images kept for reuse.
    pub fn recycled_objects(&self) -> usize {
        self.deletion.lock_recycled().kept.len()
    }

    /// Buffers and images created so far (a reused one is not created again): the frame loop creates none once
    /// warm.
    pub fn created_resources(&self) -> u64 {
        self.deletion.created.load(Ordering::Relaxed)
    }

    /// Frees retired resources whose submissions have completed. Cheap; call once per frame.
    pub fn collect_garbage(&self) {
        let completed = self.timeline.completed(&self.device).unwrap_or(0);
        self.deletion
            .collect(&self.device, &self.allocator, completed);
    }

    /// Frees the buffers and images kept for reuse (after a large job, to return their memory).
    pub fn release_recycled(&self) {
        self.collect_garbage();
        self.deletion
            .release_recycled(&self.device, &self.allocator);
    }
}

/// Things handed back while submitted work may still read them (bindless slots, texture layers), each with the
/// timeline value of the last submission made then: free again once that value has completed.
pub(crate) struct Released<T>(VecDeque<(u64, T)>);

impl<T> Default for Released<T> {
    fn default() -> Self {
        Self(VecDeque::new())
    }
}

impl<T> Released<T> {
    /// Hands `item` back after every submission made so far.
    pub(crate) fn push(&mut self, ctx: &Context, item: T) {
        self.0.push_back((ctx.timeline.last_submitted(), item));
    }

    /// Moves what the GPU is done with into `free`.
    pub(crate) fn reclaim_into(&mut self, ctx: &Context, free: &mut Vec<T>) {
        // A failed query (device loss) reclaims nothing; the next submission reports the loss.
        let completed = ctx.timeline.completed(&ctx.device).unwrap_or(0);
        while self.0.front().is_some_and(|(value, _)| *value <= completed) {
            if let Some((_, item)) = self.0.pop_front() {
                free.push(item);
            }
        }
    }

    /// Things still read by submitted work.
    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }
}
