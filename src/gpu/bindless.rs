//! The global descriptor-indexed set (kajiya, Sascha Willems' `descriptorindexing`): every patch texture lives in a
//! slot of one runtime array, read with `nonuniformEXT` from any shader. Binding 0 is the storage-image view of a
//! slot (compute kernels write river data), binding 1 the sampled view of the same slot (vertex and fragment
//! shaders read it). Both are PARTIALLY_BOUND and UPDATE_AFTER_BIND; binding 1 has a variable descriptor count.

use ash::vk;

use super::{
    retire::{Released, RetireOnDrop, Retired},
    Access, Context, GpuError, Image, VkResultExt,
};

/// The debug name of the set, which validation messages quote.
pub(crate) const SET_NAME: &str = "bindless set";

/// The set's binding of storage-image views (what compute passes write).
pub const STORAGE_IMAGES: u32 = 0;
/// The set's binding of sampled views of the same slots (what shaders read).
pub const SAMPLED_IMAGES: u32 = 1;

/// One descriptor set of image slots every pipeline binds, indexed by slot number in the shaders
/// (descriptor indexing): a patch texture takes a slot instead of a descriptor set of its own.
pub struct Bindless {
    /// The set's layout, shared by every pipeline layout.
    pub layout: vk::DescriptorSetLayout,
    /// The set.
    pub set: vk::DescriptorSet,
    sampler: vk::Sampler,
    /// Slots in all.
    pub capacity: u32,
    free: Vec<u32>,
    /// Released slots with the timeline value after which no submitted frame reads them: a frame still in
    /// flight may read a slot's descriptor, which must not be rewritten until that frame has finished.
    released: Released<u32>,
    _retire: RetireOnDrop,
}

/// A slot index in the bindless arrays, as shaders see it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Slot(pub u32);

/// Layers a [`SlotLayer`] can address in one slot's array image: the least `maxImageArrayLayers` Vulkan
/// guarantees, so an array image of patch textures fits every device.
pub const LAYERS_PER_SLOT: u32 = 256;

/// Where a patch texture lies: an array image's slot and the first of the texture's layers in it. Shaders take
/// it as one number, `slot * LAYERS_PER_SLOT + layer` (glsl/slot_layers.glsl); an image of its own is its slot's
/// layer 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SlotLayer {
    /// The array image's slot.
    pub slot: Slot,
    /// The texture's first layer in it (below [`LAYERS_PER_SLOT`]).
    pub layer: u32,
}

impl SlotLayer {
    /// The first layer of the image at `slot`: a texture with an image of its own.
    pub fn whole(slot: Slot) -> Self {
        Self { slot, layer: 0 }
    }

    /// The number shaders decode (glsl/slot_layers.glsl).
    pub fn shader_index(self) -> u32 {
        debug_assert!(self.layer < LAYERS_PER_SLOT);
        self.slot.0 * LAYERS_PER_SLOT + self.layer
    }
}

impl Bindless {
    /// Creates the set with `capacity` slots (clamped to the device's update-after-bind limits).
    pub fn new(ctx: &Context, capacity: u32) -> Result<Self, GpuError> {
        let mut props12 = vk::PhysicalDeviceVulkan12Properties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut props12);
        // SAFETY: plain query.
        unsafe {
            ctx.instance
                .get_physical_device_properties2(ctx.physical, &mut props2)
        };
        let limit = props12
            .max_descriptor_set_update_after_bind_storage_images
            .min(props12.max_descriptor_set_update_after_bind_sampled_images)
            .min(props12.max_per_stage_descriptor_update_after_bind_storage_images)
            .min(props12.max_per_stage_descriptor_update_after_bind_sampled_images);
        let capacity = capacity.min(limit).max(1);

        let stages = vk::ShaderStageFlags::COMPUTE
            | vk::ShaderStageFlags::VERTEX
            | vk::ShaderStageFlags::GEOMETRY
            | vk::ShaderStageFlags::FRAGMENT;
        let bindings = [
            vk::DescriptorSetLayoutBinding::default()
                .binding(STORAGE_IMAGES)
                .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                .descriptor_count(capacity)
                .stage_flags(stages),
            vk::DescriptorSetLayoutBinding::default()
                .binding(SAMPLED_IMAGES)
                .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
                .descriptor_count(capacity)
                .stage_flags(stages),
        ];
        let common = vk::DescriptorBindingFlags::PARTIALLY_BOUND
            | vk::DescriptorBindingFlags::UPDATE_AFTER_BIND;
        let flags = [
            common,
            common | vk::DescriptorBindingFlags::VARIABLE_DESCRIPTOR_COUNT,
        ];
        let mut flag_info =
            vk::DescriptorSetLayoutBindingFlagsCreateInfo::default().binding_flags(&flags);
        let layout_info = vk::DescriptorSetLayoutCreateInfo::default()
            .flags(vk::DescriptorSetLayoutCreateFlags::UPDATE_AFTER_BIND_POOL)
            .bindings(&bindings)
            .push_next(&mut flag_info);
        // SAFETY: valid create infos; each object is retired when the set drops (or creation fails further on).
        let layout = unsafe { ctx.device.create_descriptor_set_layout(&layout_info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        let mut retire = ctx.retire_on_drop(vec![Retired::SetLayout(layout)]);
        ctx.set_name(layout, "bindless layout");
        let sizes = [
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::STORAGE_IMAGE,
                descriptor_count: capacity,
            },
            vk::DescriptorPoolSize {
                ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                descriptor_count: capacity,
            },
        ];
        let pool_info = vk::DescriptorPoolCreateInfo::default()
            .flags(vk::DescriptorPoolCreateFlags::UPDATE_AFTER_BIND)
            .max_sets(1)
            .pool_sizes(&sizes);
        let pool = unsafe { ctx.device.create_descriptor_pool(&pool_info, None) }
            .vk("vkCreateDescriptorPool")?;
        retire.push(Retired::DescriptorPool(pool));
        let counts = [capacity];
        let mut variable = vk::DescriptorSetVariableDescriptorCountAllocateInfo::default()
            .descriptor_counts(&counts);
        let layouts = [layout];
        let alloc = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(pool)
            .set_layouts(&layouts)
            .push_next(&mut variable);
        let set = unsafe { ctx.device.allocate_descriptor_sets(&alloc) }
            .vk("vkAllocateDescriptorSets")?[0];
        ctx.set_name(set, SET_NAME);
        ctx.register_runtime_array_set(set);
        let sampler_info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE);
        let sampler =
            unsafe { ctx.device.create_sampler(&sampler_info, None) }.vk("vkCreateSampler")?;
        retire.push(Retired::Sampler(sampler));
        ctx.set_name(sampler, "bindless linear clamp sampler");
        Ok(Self {
            layout,
            set,
            sampler,
            capacity,
            free: (0..capacity).rev().collect(),
            released: Default::default(),
            _retire: retire,
        })
    }

    /// Takes a free slot (reclaiming released ones whose frames have finished when none is left), or `None` when
    /// all are in use or still read by frames in flight.
    pub fn allocate(&mut self, ctx: &Context) -> Option<Slot> {
        if self.free.is_empty() {
            self.released.reclaim_into(ctx, &mut self.free);
        }
        self.free.pop().map(Slot)
    }

    /// Returns a slot once every submission made so far has completed. Its old descriptors stay until
    /// overwritten; PARTIALLY_BOUND makes that legal.
    pub fn release(&mut self, ctx: &Context, slot: Slot) {
        debug_assert!(!self.free.contains(&slot.0));
        self.released.push(ctx, slot.0);
    }

    /// Slots released but still read by frames in flight.
    pub fn pending_release(&self) -> usize {
        self.released.len()
    }

    /// Points `slot` at `image`: as a storage image (if `storage`) and as a sampled image, in the layout shaders
    /// find it in (GENERAL: gpu/access.rs).
    pub fn write(&self, ctx: &Context, slot: Slot, image: &Image, storage: bool) {
        let layout = Access::GraphicsSampled.layout(image.shader_visible());
        let storage_info = [vk::DescriptorImageInfo::default()
            .image_view(image.view)
            .image_layout(layout)];
        let sampled_info = [vk::DescriptorImageInfo::default()
            .image_view(image.view)
            .image_layout(layout)
            .sampler(self.sampler)];
        let mut writes = vec![vk::WriteDescriptorSet::default()
            .dst_set(self.set)
            .dst_binding(SAMPLED_IMAGES)
            .dst_array_element(slot.0)
            .descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER)
            .image_info(&sampled_info)];
        if storage {
            writes.push(
                vk::WriteDescriptorSet::default()
                    .dst_set(self.set)
                    .dst_binding(STORAGE_IMAGES)
                    .dst_array_element(slot.0)
                    .descriptor_type(vk::DescriptorType::STORAGE_IMAGE)
                    .image_info(&storage_info),
            );
        }
        // SAFETY: UPDATE_AFTER_BIND permits updates while the set is bound; the slot is not used by pending work.
        unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
    }
}
