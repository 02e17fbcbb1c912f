//! Named buffers and images on gpu-allocator memory. Dropping one retires it (retire.rs): it is freed, or kept
//! for a later request of the same shape, once the GPU is done with it.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
pub use gpu_allocator::MemoryLocation;

use super::{
    access::{self, Access},
    retire::{BufferMemory, BufferShape, DeletionQueue, ImageMemory, ImageShape, Retired},
    state::UseState,
    Context, GpuError, VkResultExt,
};

/// A buffer request. `name` goes to the debug-utils object name and to the allocation.
#[derive(Clone, Debug)]
pub struct BufferDesc<'a> {
    /// Its debug name.
    pub name: &'a str,
    /// Bytes.
    pub size: u64,
    /// Every way the buffer will be used (its usage flags follow: gpu/access.rs).
    pub uses: &'a [Access],
    /// Device-local, or mapped for upload or readback.
    pub location: MemoryLocation,
}

/// A buffer: `size` bytes as requested, in a Vulkan buffer of its shape's capacity (which may be larger).
pub struct Buffer {
    pub(super) raw: vk::Buffer,
    /// Bytes, as requested.
    pub size: u64,
    /// Its debug name.
    pub name: String,
    allocation: Option<Allocation>,
    shape: BufferShape,
    deletion: Arc<DeletionQueue>,
    /// What it was last declared for (gpu/state.rs).
    pub(super) state: Arc<UseState>,
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(allocation) = self.allocation.take() {
            self.deletion.retire(Retired::Buffer(BufferMemory {
                raw: self.raw,
                allocation,
                shape: self.shape,
            }));
        }
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

    /// Its bytes for writing, if its memory is mapped.
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
    /// Its debug name.
    pub name: &'a str,
    /// Texels across and down.
    pub extent: vk::Extent2D,
    /// Array layers.
    pub layers: u32,
    /// Texel format.
    pub format: vk::Format,
    /// Every way the image will be used (its usage flags follow: gpu/access.rs).
    pub uses: &'a [Access],
    /// View it as a 2D array even with one layer (so shaders can index every patch texture alike).
    pub array: bool,
}

/// An image with its view, its memory, and the use it was last recorded for.
pub struct Image {
    pub(super) raw: vk::Image,
    pub(super) view: vk::ImageView,
    /// Texels across and down.
    pub extent: vk::Extent2D,
    /// Array layers.
    pub layers: u32,
    /// Texel format.
    pub format: vk::Format,
    /// Its debug name.
    pub name: String,
    allocation: Option<Allocation>,
    shape: ImageShape,
    deletion: Arc<DeletionQueue>,
    /// What it was last recorded for (gpu/state.rs).
    pub(super) state: Arc<UseState>,
}

impl Drop for Image {
    fn drop(&mut self) {
        if let Some(allocation) = self.allocation.take() {
            self.deletion.retire(Retired::Image(ImageMemory {
                raw: self.raw,
                view: self.view,
                allocation,
                shape: self.shape,
            }));
        }
    }
}

impl Image {
    /// Whether shaders read or write it (storage or sampled usage): such images stay in GENERAL (gpu/access.rs).
    pub fn shader_visible(&self) -> bool {
        self.shape
            .usage
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

/// The least capacity of a buffer: the frame loop's many small buffers (staging, per-dispatch inputs, masks) all
/// take this one shape, so any of them serves any other once retired.
const MIN_CAPACITY: u64 = 64 << 10;

/// The capacity of a buffer made for a request of `size` bytes: at least [`MIN_CAPACITY`], and above it rounded up
/// to an eighth of the power of two below (at most 12.5 % more), so that requests of nearby sizes share a shape.
fn capacity_class(size: u64) -> u64 {
    let size = size.max(MIN_CAPACITY);
    let step = (1u64 << (63 - size.leading_zeros())) / 8;
    size.div_ceil(step) * step
}

/// The aspect of an image of `format`: depth for the depth format this renderer uses, colour otherwise.
fn aspect(format: vk::Format) -> vk::ImageAspectFlags {
    if format == vk::Format::D32_SFLOAT {
        vk::ImageAspectFlags::DEPTH
    } else {
        vk::ImageAspectFlags::COLOR
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

    /// A buffer for `desc`: one kept for reuse if one fits (retire.rs), else a new one of the request's capacity
    /// class.
    pub fn create_buffer(&self, desc: &BufferDesc) -> Result<Buffer, GpuError> {
        let shape = BufferShape {
            usage: access::buffer_usage(desc.uses),
            location: desc.location,
            capacity: capacity_class(desc.size),
        };
        let memory = match self.deletion.reuse_buffer(&shape) {
            Some(memory) => memory,
            None => self.new_buffer(desc.name, shape)?,
        };
        self.set_name(memory.raw, desc.name);
        Ok(Buffer {
            raw: memory.raw,
            size: desc.size,
            name: desc.name.to_string(),
            allocation: Some(memory.allocation),
            shape: memory.shape,
            deletion: self.deletion.clone(),
            state: UseState::fresh(),
        })
    }

    fn new_buffer(&self, name: &str, shape: BufferShape) -> Result<BufferMemory, GpuError> {
        let info = vk::BufferCreateInfo::default()
            .size(shape.capacity)
            .usage(shape.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: valid create info; the buffer is destroyed through the deletion queue.
        let raw = unsafe { self.device.create_buffer(&info, None) }.vk("vkCreateBuffer")?;
        let requirements = unsafe { self.device.get_buffer_memory_requirements(raw) };
        let allocation = match self.allocate(name, requirements, shape.location, true) {
            Ok(a) => a,
            Err(e) => {
                unsafe { self.device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        self.deletion.note_created();
        let memory = BufferMemory {
            raw,
            allocation,
            shape,
        };
        // SAFETY: fresh allocation satisfying the buffer's requirements.
        let bound = unsafe {
            self.device.bind_buffer_memory(
                raw,
                memory.allocation.memory(),
                memory.allocation.offset(),
            )
        };
        if let Err(e) = bound.vk("vkBindBufferMemory") {
            self.deletion.retire(Retired::Buffer(memory));
            return Err(e);
        }
        Ok(memory)
    }

    /// An image for `desc`: one kept for reuse if its shape matches (its contents undefined, as a new one's), else
    /// a new one.
    pub fn create_image(&self, desc: &ImageDesc) -> Result<Image, GpuError> {
        let shape = ImageShape {
            extent: desc.extent,
            format: desc.format,
            layers: desc.layers,
            array: desc.array,
            usage: access::image_usage(desc.uses),
        };
        let memory = match self.deletion.reuse_image(&shape) {
            Some(memory) => memory,
            None => self.new_image(desc.name, shape)?,
        };
        self.set_name(memory.raw, desc.name);
        self.set_name(memory.view, desc.name);
        Ok(Image {
            raw: memory.raw,
            view: memory.view,
            extent: desc.extent,
            layers: desc.layers,
            format: desc.format,
            name: desc.name.to_string(),
            allocation: Some(memory.allocation),
            shape,
            deletion: self.deletion.clone(),
            state: UseState::fresh(),
        })
    }

    fn new_image(&self, name: &str, shape: ImageShape) -> Result<ImageMemory, GpuError> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(shape.format)
            .extent(vk::Extent3D {
                width: shape.extent.width,
                height: shape.extent.height,
                depth: 1,
            })
            .mip_levels(1)
            .array_layers(shape.layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(shape.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        // SAFETY: valid create info.
        let raw = unsafe { self.device.create_image(&info, None) }.vk("vkCreateImage")?;
        let requirements = unsafe { self.device.get_image_memory_requirements(raw) };
        let allocation = match self.allocate(name, requirements, MemoryLocation::GpuOnly, false) {
            Ok(a) => a,
            Err(e) => {
                unsafe { self.device.destroy_image(raw, None) };
                return Err(e);
            }
        };
        self.deletion.note_created();
        let mut memory = ImageMemory {
            raw,
            view: vk::ImageView::null(),
            allocation,
            shape,
        };
        // SAFETY: fresh allocation satisfying the image's requirements.
        let bound = unsafe {
            self.device.bind_image_memory(
                raw,
                memory.allocation.memory(),
                memory.allocation.offset(),
            )
        };
        let view_type = if shape.layers > 1 || shape.array {
            vk::ImageViewType::TYPE_2D_ARRAY
        } else {
            vk::ImageViewType::TYPE_2D
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(view_type)
            .format(shape.format)
            .subresource_range(
                vk::ImageSubresourceRange::default()
                    .aspect_mask(aspect(shape.format))
                    .level_count(1)
                    .layer_count(shape.layers),
            );
        let view = bound.vk("vkBindImageMemory").and_then(|()| {
            // SAFETY: the image is bound to memory.
            unsafe { self.device.create_image_view(&view_info, None) }.vk("vkCreateImageView")
        });
        match view {
            Ok(view) => {
                memory.view = view;
                Ok(memory)
            }
            Err(e) => {
                // Destroying a null view is a no-op.
                self.deletion.retire(Retired::Image(memory));
                Err(e)
            }
        }
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
}
