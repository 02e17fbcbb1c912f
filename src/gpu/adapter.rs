//! Which device: every physical device described (name, type, driver, the features this renderer needs) and one
//! chosen, the `--adapter` filter first, then discrete before integrated, virtual and CPU devices, among those
//! with every required feature.

use ash::vk;

use super::{
    features,
    instance::{create_instance, load_entry, ContextOptions},
    FeatureReport, GpuError, VkResultExt,
};

/// What `riverplanet info` shows of one physical device.
#[derive(Clone, Debug, serde::Serialize)]
pub struct AdapterInfo {
    /// The device's name (`deviceName`).
    pub name: String,
    /// Discrete, integrated, virtual or CPU.
    pub device_type: String,
    /// The Vulkan version it supports, major.minor.patch.
    pub api_version: String,
    /// The driver's name and what it says of its version (`VK_KHR_driver_properties`).
    pub driver_name: String,
    /// See `driver_name`.
    pub driver_info: String,
    /// Which of the features the renderer needs or uses it has.
    pub features: FeatureReport,
    /// Whether the renderer picks this device.
    pub chosen: bool,
}

pub(super) fn graphics_compute_family(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
) -> Option<u32> {
    // SAFETY: plain query.
    let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
    families
        .iter()
        .position(|f| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        })
        .map(|i| i as u32)
}

fn describe(instance: &ash::Instance, physical: vk::PhysicalDevice) -> AdapterInfo {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    // SAFETY: plain query with a chain on this stack frame.
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    let p = props2.properties;
    let v = p.api_version;
    let family = graphics_compute_family(instance, physical);
    AdapterInfo {
        name: p
            .device_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        device_type: format!("{:?}", p.device_type),
        api_version: format!(
            "{}.{}.{}",
            vk::api_version_major(v),
            vk::api_version_minor(v),
            vk::api_version_patch(v)
        ),
        driver_name: driver
            .driver_name_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        driver_info: driver
            .driver_info_as_c_str()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default(),
        features: features::query(instance, physical, family),
        chosen: false,
    }
}

fn type_rank(device_type: &str) -> u32 {
    match device_type {
        "DISCRETE_GPU" => 4,
        "INTEGRATED_GPU" => 3,
        "VIRTUAL_GPU" => 2,
        "CPU" => 1,
        _ => 0,
    }
}

/// Every device's description, its handle, and the index of the chosen one.
pub(super) type Enumeration = (Vec<AdapterInfo>, Vec<vk::PhysicalDevice>, Option<usize>);

/// Lists every device and marks the one `options` chooses: the adapter filter first, then discrete GPUs before
/// integrated, virtual and CPU devices, among devices with every required feature.
pub(super) fn choose(
    instance: &ash::Instance,
    options: &ContextOptions,
) -> Result<Enumeration, GpuError> {
    // SAFETY: plain query.
    let physicals =
        unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let mut infos: Vec<AdapterInfo> = physicals.iter().map(|&p| describe(instance, p)).collect();
    let matches = |info: &AdapterInfo| match &options.adapter {
        Some(f) => info.name.to_lowercase().contains(&f.to_lowercase()),
        None => true,
    };
    let chosen = infos
        .iter()
        .enumerate()
        .filter(|(_, i)| matches(i))
        .max_by_key(|(_, i)| (i.features.all_supported(), type_rank(&i.device_type)))
        .map(|(idx, _)| idx);
    if let Some(idx) = chosen {
        infos[idx].chosen = true;
    }
    Ok((infos, physicals, chosen))
}

/// Lists the devices without creating one (for `riverplanet info`). Returns the instance version too.
pub fn enumerate(options: &ContextOptions) -> Result<(String, Vec<AdapterInfo>), GpuError> {
    let entry = load_entry()?;
    // SAFETY: plain query.
    let version = unsafe { entry.try_enumerate_instance_version() }
        .vk("vkEnumerateInstanceVersion")?
        .unwrap_or(vk::API_VERSION_1_0);
    let (instance, _) = create_instance(
        &entry,
        &ContextOptions {
            validation: false,
            ..options.clone()
        },
    )?;
    let result = choose(&instance, options).map(|(infos, _, _)| infos);
    // SAFETY: nothing was created from this instance.
    unsafe { instance.destroy_instance(None) };
    let version = format!(
        "{}.{}.{}",
        vk::api_version_major(version),
        vk::api_version_minor(version),
        vk::api_version_patch(version)
    );
    Ok((version, result?))
}

/// The vector width lavapipe (llvmpipe) compiles shaders for, from its device name ("llvmpipe (LLVM 15.0.6, 256
/// bits)"): `LP_NATIVE_VECTOR_WIDTH` where set, else what the CPU offers (128 without AVX2).
fn lavapipe_vector_bits(adapter: &AdapterInfo) -> Option<u32> {
    if adapter.driver_name != "llvmpipe" {
        return None;
    }
    let (before, _) = adapter.name.split_once(" bits")?;
    before.rsplit([' ', ',']).next()?.parse().ok()
}

/// Refuses, before any work, the device a drawing context would choose if it cannot draw (`cannot_draw`), for
/// commands that build a planet before they create their context (the viewer).
pub fn check_can_draw(options: &ContextOptions) -> Result<(), GpuError> {
    let (_, adapters) = enumerate(options)?;
    match adapters.iter().find(|a| a.chosen) {
        Some(adapter) => match cannot_draw(adapter) {
            Some(reason) => Err(GpuError::CannotDraw {
                device: adapter.name.clone(),
                reason,
            }),
            None => Ok(()),
        },
        None => Ok(()),
    }
}

/// Why `adapter` cannot draw this renderer, if it cannot: lavapipe with vectors narrower than 256 bits corrupts
/// its heap drawing the terrain and the water and aborts on the first frame (a Mesa fault, docs/rendering.md,
/// "Vertex capture"; issue 16). Its compute paths work, so only contexts that draw refuse it.
pub fn cannot_draw(adapter: &AdapterInfo) -> Option<String> {
    lavapipe_vector_bits(adapter)
        .filter(|&bits| bits < 256)
        .map(|bits| {
            format!(
                "lavapipe with {bits}-bit vectors corrupts its heap drawing the terrain (a Mesa fault, \
                 docs/rendering.md, \"Vertex capture\"); unset LP_NATIVE_VECTOR_WIDTH, or on a CPU without AVX2 use \
                 another driver; compute-only commands (bench kernel, generate, export) still run"
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adapter(driver_name: &str, name: &str) -> AdapterInfo {
        AdapterInfo {
            name: name.into(),
            device_type: "CPU".into(),
            api_version: "1.3.0".into(),
            driver_name: driver_name.into(),
            driver_info: String::new(),
            features: FeatureReport { checks: Vec::new() },
            chosen: true,
        }
    }

    #[test]
    fn lavapipe_with_narrow_vectors_cannot_draw_and_nothing_else_is_refused() {
        let narrow = adapter("llvmpipe", "llvmpipe (LLVM 15.0.6, 128 bits)");
        let reason = cannot_draw(&narrow).unwrap();
        assert!(
            reason.contains("128-bit") && reason.contains("LP_NATIVE_VECTOR_WIDTH"),
            "{reason}"
        );
        assert!(cannot_draw(&adapter("llvmpipe", "llvmpipe (LLVM 15.0.6, 256 bits)")).is_none());
        assert!(cannot_draw(&adapter("llvmpipe", "llvmpipe (LLVM 15.0.6, 512 bits)")).is_none());
        assert!(cannot_draw(&adapter("llvmpipe", "llvmpipe")).is_none());
        assert!(cannot_draw(&adapter("NVIDIA", "NVIDIA H200 (128 bits)")).is_none());
    }
}
