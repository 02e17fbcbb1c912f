//! Named buffers and images on gpu-allocator memory, and deferred destruction: a dropped buffer or image (or
//! pipeline, layout, sampler or pool, through [`RetireOnDrop`]) is freed only after the GPU has finished every
//! submission made before it was dropped, and the submission of any recording open when it was dropped (Granite's
//! per-frame lists, keyed here by timeline-semaphore value). Dropping is retiring, so none can leak by being
//! forgotten, and no owner calls `destroy`.

use std::sync::{atomic::AtomicU64, Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme, Allocator};
pub use gpu_allocator::MemoryLocation;

use super::{
    access::{self, Access},
    Context, GpuError, VkResultExt,
};

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

/// A buffer request. `name` goes to the debug-utils object name and to the allocation.
#[derive(Clone, Debug)]
pub struct BufferDesc<'a> {
    pub name: &'a str,
    pub size: u64,
    /// Every way the buffer will be used (its usage flags follow: gpu/access.rs).
    pub uses: &'a [Access],
    pub location: MemoryLocation,
}

pub struct Buffer {
    pub(super) raw: vk::Buffer,
    pub size: u64,
    pub name: String,
    allocation: Option<Allocation>,
    deletion: Arc<DeletionQueue>,
}

impl Drop for Buffer {
    fn drop(&mut self) {
        self.deletion
            .retire(Retired::Buffer(self.raw, self.allocation.take()));
    }
}

impl Buffer {
    /// The mapped bytes of a host-visible buffer.
    pub fn mapped(&self) -> Option<&[u8]> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..self.size as usize])
    }

    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size as usize;
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .map(|s| &mut s[..size])
    }

    /// Writes `data` at `offset` into a host-visible buffer; errors if the buffer is not mapped or too small.
    pub fn write<T: bytemuck::Pod>(&mut self, offset: usize, data: &[T]) -> Result<(), GpuError> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        let end = offset + bytes.len();
        let Some(len) = self.mapped().map(<[u8]>::len) else {
            let name = &self.name;
            return Err(GpuError::Invalid(format!(
                "buffer '{name}' is not host-visible"
            )));
        };
        if end > len {
            return Err(GpuError::Invalid(format!(
                "write of {} bytes at {offset} overflows buffer '{}' of {len} bytes",
                bytes.len(),
                self.name
            )));
        }
        if let Some(dst) = self.mapped_mut() {
            dst[offset..end].copy_from_slice(bytes);
        }
        Ok(())
    }
}

/// An image request: 2D, with `layers` array layers and one mip level.
#[derive(Clone, Debug)]
pub struct ImageDesc<'a> {
    pub name: &'a str,
    pub extent: vk::Extent2D,
    pub layers: u32,
    pub format: vk::Format,
    /// Every way the image will be used (its usage flags follow: gpu/access.rs).
    pub uses: &'a [Access],
    /// View it as a 2D array even with one layer (so shaders can index every patch texture alike).
    pub array: bool,
}

pub struct Image {
    pub(super) raw: vk::Image,
    pub(super) view: vk::ImageView,
    pub extent: vk::Extent2D,
    pub layers: u32,
    pub format: vk::Format,
    pub name: String,
    usage: vk::ImageUsageFlags,
    allocation: Option<Allocation>,
    deletion: Arc<DeletionQueue>,
}

impl Drop for Image {
    fn drop(&mut self) {
        self.deletion
            .retire(Retired::Image(self.raw, self.view, self.allocation.take()));
    }
}

impl Image {
    /// Whether shaders read or write it (storage or sampled usage): such images stay in GENERAL (gpu/access.rs).
    pub fn shader_visible(&self) -> bool {
        self.usage
            .intersects(vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED)
    }

    /// The subresource range of the whole image.
    pub fn range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(aspect(self.format))
            .level_count(1)
            .layer_count(self.layers)
    }
}

/// The aspect of an image of `format`: depth for the depth format this renderer uses, colour otherwise.
fn aspect(format: vk::Format) -> vk::ImageAspectFlags {
    if format == vk::Format::D32_SFLOAT {
        vk::ImageAspectFlags::DEPTH
    } else {
        vk::ImageAspectFlags::COLOR
    }
}

/// A GPU object waiting to be destroyed.
pub(super) enum Retired {
    Buffer(vk::Buffer, Option<Allocation>),
    Image(vk::Image, vk::ImageView, Option<Allocation>),
    Pool(vk::CommandPool),
    DescriptorPool(vk::DescriptorPool),
    QueryPool(vk::QueryPool),
    Pipeline(vk::Pipeline, vk::PipelineLayout),
    SetLayout(vk::DescriptorSetLayout),
    Sampler(vk::Sampler),
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

/// Resources waiting for the GPU to finish with them. With no recording open, what is retired waits for the last
/// submission (`submitted`, shared with the timeline); with recordings open, for the last of their submissions:
/// an object dropped after a command that uses it was recorded lives until that command has run.
pub(crate) struct DeletionQueue {
    pending: Mutex<Pending>,
    submitted: Arc<AtomicU64>,
}

impl DeletionQueue {
    pub(crate) fn new(submitted: Arc<AtomicU64>) -> Self {
        Self {
            pending: Mutex::new(Pending::default()),
            submitted,
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Pending> {
        self.pending.lock().unwrap_or_else(|e| e.into_inner())
    }

    pub(super) fn retire(&self, item: Retired) {
        let mut pending = self.lock();
        if pending.open == 0 {
            let after = self.submitted.load(std::sync::atomic::Ordering::Acquire);
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
            let after = self.submitted.load(std::sync::atomic::Ordering::Acquire);
            let awaiting = std::mem::take(&mut pending.awaiting);
            pending
                .tagged
                .extend(awaiting.into_iter().map(|item| (after, item)));
        }
    }

    /// How many objects wait to be destroyed.
    pub(super) fn len(&self) -> usize {
        let pending = self.lock();
        pending.tagged.len() + pending.awaiting.len()
    }

    /// Frees every resource whose guarding submission has completed.
    fn collect(&self, device: &ash::Device, allocator: &Mutex<Allocator>, completed: u64) {
        let ready: Vec<Retired> = {
            let mut pending = self.lock();
            let (ready, keep): (Vec<_>, Vec<_>) =
                pending.tagged.drain(..).partition(|(v, _)| *v <= completed);
            pending.tagged = keep;
            ready.into_iter().map(|(_, r)| r).collect()
        };
        if ready.is_empty() {
            return;
        }
        let mut allocator = allocator.lock().unwrap_or_else(|e| e.into_inner());
        for item in ready {
            // SAFETY: the GPU finished every submission that could use these objects (timeline value reached).
            unsafe {
                match item {
                    Retired::Buffer(b, a) => {
                        device.destroy_buffer(b, None);
                        if let Some(a) = a {
                            let _ = allocator.free(a);
                        }
                    }
                    Retired::Image(i, v, a) => {
                        device.destroy_image_view(v, None);
                        device.destroy_image(i, None);
                        if let Some(a) = a {
                            let _ = allocator.free(a);
                        }
                    }
                    Retired::Pool(p) => device.destroy_command_pool(p, None),
                    Retired::DescriptorPool(p) => device.destroy_descriptor_pool(p, None),
                    Retired::QueryPool(q) => device.destroy_query_pool(q, None),
                    Retired::Pipeline(p, l) => {
                        device.destroy_pipeline(p, None);
                        device.destroy_pipeline_layout(l, None);
                    }
                    Retired::SetLayout(l) => device.destroy_descriptor_set_layout(l, None),
                    Retired::Sampler(x) => device.destroy_sampler(x, None),
                }
            }
        }
    }

    /// Frees everything, awaiting or not (at the context's end, with the device idle).
    pub(crate) fn flush_all(&self, device: &ash::Device, allocator: &Mutex<Allocator>) {
        {
            let mut pending = self.lock();
            let awaiting = std::mem::take(&mut pending.awaiting);
            pending
                .tagged
                .extend(awaiting.into_iter().map(|item| (0, item)));
        }
        self.collect(device, allocator, u64::MAX);
    }
}

impl Context {
    fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Allocation, GpuError> {
        self.allocator
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| GpuError::Allocation {
                name: name.to_string(),
                source,
            })
    }

    pub fn create_buffer(&self, desc: &BufferDesc) -> Result<Buffer, GpuError> {
        let info = vk::BufferCreateInfo::default()
            .size(desc.size.max(4))
            .usage(access::buffer_usage(desc.uses))
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid create info; the buffer is destroyed through the deletion queue.
        let raw = unsafe { self.device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let requirements = unsafe { self.device.get_buffer_memory_requirements(raw) };
        let allocation = match self.allocate(desc.name, requirements, desc.location, true) {
            Ok(a) => a,
            Err(e) => {
                unsafe { self.device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        // SAFETY: fresh allocation satisfying the buffer's requirements.
        unsafe {
            self.device
                .bind_buffer_memory(raw, allocation.memory(), allocation.offset())
        }
        .vk("vkBindBufferMemory")?;
        self.set_name(raw, desc.name);
        Ok(Buffer {
            raw,
            size: desc.size,
            name: desc.name.to_string(),
            allocation: Some(allocation),
            deletion: self.deletion.clone(),
        })
    }

    pub fn create_image(&self, desc: &ImageDesc) -> Result<Image, GpuError> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent.width,
                height: desc.extent.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(desc.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(access::image_usage(desc.uses))
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info.
        let raw = unsafe { self.device.create_image(&info, None) }.vk("vkCreateImage")?;
        let requirements = unsafe { self.device.get_image_memory_requirements(raw) };
        let allocation =
            match self.allocate(desc.name, requirements, MemoryLocation::GpuOnly, false) {
                Ok(a) => a,
                Err(e) => {
                    unsafe { self.device.destroy_image(raw, None) };
                    return Err(e);
                }
            };
        unsafe {
            self.device
                .bind_image_memory(raw, allocation.memory(), allocation.offset())
        }
        .vk("vkBindImageMemory")?;
        let view_type = if desc.layers > 1 || desc.array {
            vk::ImageViewType::TYPE_2D_ARRAY
        } else {
            vk::ImageViewType::TYPE_2D
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(view_type)
            .format(desc.format)
            .subresource_range(
                vk::ImageSubresourceRange::default()
                    .aspect_mask(aspect(desc.format))
                    .level_count(1)
                    .layer_count(desc.layers),
            );
        let view =
            unsafe { self.device.create_image_view(&view_info, None) }.vk("vkCreateImageView")?;
        self.set_name(raw, desc.name);
        self.set_name(view, desc.name);
        Ok(Image {
            raw,
            view,
            extent: desc.extent,
            layers: desc.layers,
            format: desc.format,
            name: desc.name.to_string(),
            usage: access::image_usage(desc.uses),
            allocation: Some(allocation),
            deletion: self.deletion.clone(),
        })
    }

    /// A guard that retires `items` (through the deletion queue, as a dropped buffer is) when it drops: the
    /// owner of pipelines, layouts, samplers and pools holds one, and needs no `destroy` call.
    pub(super) fn retire_on_drop(&self, items: Vec<Retired>) -> RetireOnDrop {
        RetireOnDrop {
            items,
            deletion: self.deletion.clone(),
        }
    }

    /// Objects retired and not yet destroyed (the GPU may still use them).
    pub fn retired_objects(&self) -> usize {
        self.deletion.len()
    }

    /// How many buffers and images hold memory (live, or retired and not yet freed): for leak checks.
    pub fn live_allocations(&self) -> usize {
        self.allocator
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .generate_report()
            .allocations
            .len()
    }

    /// Frees retired resources whose submissions have completed. Cheap; call once per frame.
    pub fn collect_garbage(&self) {
        let completed = self.timeline.completed(&self.device).unwrap_or(0);
        self.deletion
            .collect(&self.device, &self.allocator, completed);
    }
}
