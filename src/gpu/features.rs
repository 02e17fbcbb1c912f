//! The device features riverplanet requires, negotiated in one place (wgpu-hal's `PhysicalDeviceFeatures`):
//! queried once, reported by `riverplanet info`, enabled exactly as listed, and a missing one is an error naming it.
//! One optional feature is enabled where the device has it (`Context::pipeline_statistics`): pipeline statistics
//! queries, with which the profiler counts fragments.

use ash::vk;

/// One required capability and whether the device has it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FeatureCheck {
    /// The feature's Vulkan name.
    pub name: &'static str,
    /// Whether the device has it.
    pub supported: bool,
}

/// The required features of one physical device, each yes/no.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FeatureReport {
    /// Every required feature, in the order they are enabled.
    pub checks: Vec<FeatureCheck>,
}

impl FeatureReport {
    /// Whether the device has every required feature.
    pub fn all_supported(&self) -> bool {
        self.checks.iter().all(|c| c.supported)
    }

    /// The required features the device lacks.
    pub fn missing(&self) -> Vec<&'static str> {
        self.checks
            .iter()
            .filter(|c| !c.supported)
            .map(|c| c.name)
            .collect()
    }
}

/// Queries `physical` for every required feature. `queue_family` is the family that will be used.
pub fn query(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    queue_family: Option<u32>,
) -> FeatureReport {
    let mut v12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut v13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut f2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut v12)
        .push_next(&mut v13);
    // SAFETY: `physical` comes from this instance; the chain lives on this stack frame.
    unsafe { instance.get_physical_device_features2(physical, &mut f2) };
    let core = f2.features;
    // SAFETY: as above.
    let props = unsafe { instance.get_physical_device_properties(physical) };
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    let family = queue_family.and_then(|i| families.get(i as usize));
    let api_ok = props.api_version >= vk::API_VERSION_1_3;
    let subgroup = subgroup_properties(instance, physical);
    let subgroup_ops = vk::SubgroupFeatureFlags::BASIC
        | vk::SubgroupFeatureFlags::BALLOT
        | vk::SubgroupFeatureFlags::ARITHMETIC;

    let b = |x: vk::Bool32| x == vk::TRUE;
    let checks = vec![
        ("Vulkan 1.3", api_ok),
        ("graphics+compute queue", family.is_some()),
        ("geometryShader", b(core.geometry_shader)),
        ("fillModeNonSolid (wireframe)", b(core.fill_mode_non_solid)),
        (
            "multiDrawIndirect + drawIndirectFirstInstance (water culled per quadrant)",
            b(core.multi_draw_indirect) && b(core.draw_indirect_first_instance),
        ),
        (
            "vertexPipelineStoresAndAtomics (vertex capture)",
            b(core.vertex_pipeline_stores_and_atomics),
        ),
        ("descriptorIndexing", b(v12.descriptor_indexing)),
        ("runtimeDescriptorArray", b(v12.runtime_descriptor_array)),
        (
            "descriptorBindingPartiallyBound",
            b(v12.descriptor_binding_partially_bound),
        ),
        (
            "descriptorBindingVariableDescriptorCount",
            b(v12.descriptor_binding_variable_descriptor_count),
        ),
        (
            "descriptorBindingSampledImageUpdateAfterBind",
            b(v12.descriptor_binding_sampled_image_update_after_bind),
        ),
        (
            "descriptorBindingStorageImageUpdateAfterBind",
            b(v12.descriptor_binding_storage_image_update_after_bind),
        ),
        (
            "descriptorBindingStorageBufferUpdateAfterBind",
            b(v12.descriptor_binding_storage_buffer_update_after_bind),
        ),
        (
            "shaderSampledImageArrayNonUniformIndexing",
            b(v12.shader_sampled_image_array_non_uniform_indexing),
        ),
        (
            "shaderStorageImageArrayNonUniformIndexing",
            b(v12.shader_storage_image_array_non_uniform_indexing),
        ),
        (
            "shaderStorageBufferArrayNonUniformIndexing",
            b(v12.shader_storage_buffer_array_non_uniform_indexing),
        ),
        ("timelineSemaphore", b(v12.timeline_semaphore)),
        ("hostQueryReset", b(v12.host_query_reset)),
        ("scalarBlockLayout", b(v12.scalar_block_layout)),
        ("synchronization2", b(v13.synchronization2)),
        ("dynamicRendering", b(v13.dynamic_rendering)),
        (
            "maintenance4 (LocalSizeId in SPIR-V 1.6)",
            b(v13.maintenance4),
        ),
        (
            "subgroup ballot + arithmetic in compute",
            subgroup
                .supported_stages
                .contains(vk::ShaderStageFlags::COMPUTE)
                && subgroup.supported_operations.contains(subgroup_ops),
        ),
        (
            "computeFullSubgroups + requiredSubgroupSize",
            b(v13.subgroup_size_control)
                && b(v13.compute_full_subgroups)
                && subgroup
                    .required_size_stages
                    .contains(vk::ShaderStageFlags::COMPUTE),
        ),
        (
            "timestamps on the queue",
            family.is_some_and(|f| f.timestamp_valid_bits > 0)
                && props.limits.timestamp_period > 0.0,
        ),
    ];
    FeatureReport {
        checks: checks
            .into_iter()
            .map(|(name, supported)| FeatureCheck { name, supported })
            .collect(),
    }
}

/// The feature structs to chain into `VkDeviceCreateInfo`, with exactly the required features enabled.
pub struct EnabledFeatures {
    /// Vulkan 1.0 features.
    pub core: vk::PhysicalDeviceFeatures,
    /// Vulkan 1.2 features.
    pub v12: vk::PhysicalDeviceVulkan12Features<'static>,
    /// Vulkan 1.3 features.
    pub v13: vk::PhysicalDeviceVulkan13Features<'static>,
}

impl EnabledFeatures {
    /// Exactly the features riverplanet requires, enabled.
    pub fn required() -> Self {
        Self {
            core: vk::PhysicalDeviceFeatures::default()
                .geometry_shader(true)
                .fill_mode_non_solid(true)
                .multi_draw_indirect(true)
                .draw_indirect_first_instance(true)
                .vertex_pipeline_stores_and_atomics(true),
            v12: vk::PhysicalDeviceVulkan12Features::default()
                .descriptor_indexing(true)
                .runtime_descriptor_array(true)
                .descriptor_binding_partially_bound(true)
                .descriptor_binding_variable_descriptor_count(true)
                .descriptor_binding_sampled_image_update_after_bind(true)
                .descriptor_binding_storage_image_update_after_bind(true)
                .descriptor_binding_storage_buffer_update_after_bind(true)
                .shader_sampled_image_array_non_uniform_indexing(true)
                .shader_storage_image_array_non_uniform_indexing(true)
                .shader_storage_buffer_array_non_uniform_indexing(true)
                .timeline_semaphore(true)
                .host_query_reset(true)
                .scalar_block_layout(true),
            v13: vk::PhysicalDeviceVulkan13Features::default()
                .synchronization2(true)
                .dynamic_rendering(true)
                .maintenance4(true)
                .subgroup_size_control(true)
                .compute_full_subgroups(true),
        }
    }
}

/// What the device's subgroups can do, and their largest size (the tiled river kernel shares samples across a
/// subgroup and requires full subgroups of that size).
#[derive(Clone, Copy, Debug, Default)]
pub struct SubgroupProperties {
    /// Stages with subgroup operations.
    pub supported_stages: vk::ShaderStageFlags,
    /// The subgroup operations there are.
    pub supported_operations: vk::SubgroupFeatureFlags,
    /// Stages that can require a subgroup size.
    pub required_size_stages: vk::ShaderStageFlags,
    /// The largest subgroup size.
    pub max_size: u32,
    /// Subgroups a compute workgroup may hold: with a required subgroup size, workgroups are limited to this many
    /// subgroups of that size.
    pub max_workgroup_subgroups: u32,
}

/// Queries the subgroup properties of `physical`.
pub fn subgroup_properties(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
) -> SubgroupProperties {
    let mut v11 = vk::PhysicalDeviceVulkan11Properties::default();
    let mut v13 = vk::PhysicalDeviceVulkan13Properties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default()
        .push_next(&mut v11)
        .push_next(&mut v13);
    // SAFETY: plain query with a chain on this stack frame.
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    SubgroupProperties {
        supported_stages: v11.subgroup_supported_stages,
        supported_operations: v11.subgroup_supported_operations,
        required_size_stages: v13.required_subgroup_size_stages,
        max_size: v13.max_subgroup_size,
        max_workgroup_subgroups: v13.max_compute_workgroup_subgroups,
    }
}
