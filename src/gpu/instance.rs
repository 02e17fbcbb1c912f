//! The Vulkan instance: loading the loader, the options a context is made with, and the instance with the
//! validation layer and the extensions they ask for. Both choosing a device (adapter.rs, on a throwaway instance)
//! and creating the context (context.rs) start here.

use std::ffi::CStr;

use ash::{ext, vk};

use super::{debug::VALIDATION_LAYER, GpuError, VkResultExt};

/// How to create a [`super::Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Enable the Khronos validation layer and collect its errors.
    pub validation: bool,
    /// With `validation`: also synchronization validation (hazards between commands, across submissions).
    pub synchronization_validation: bool,
    /// Choose the first device whose name contains this (case-insensitive).
    pub adapter: Option<String>,
    /// Extra instance extensions (surface extensions for a window).
    pub instance_extensions: Vec<&'static CStr>,
    /// Enable `VK_KHR_swapchain` on the device.
    pub swapchain: bool,
    /// The context will draw (not only compute): a device known to break drawing is refused
    /// (`adapter::cannot_draw`) before any work.
    pub draws: bool,
}

impl ContextOptions {
    /// Options from the environment: `RIVERPLANET_VALIDATION` (0/1, or `sync` for synchronization validation too;
    /// default on in debug builds) and `RIVERPLANET_ADAPTER`.
    pub fn from_env() -> Self {
        let setting = std::env::var("RIVERPLANET_VALIDATION");
        let validation = match setting.as_deref() {
            Ok("0") | Ok("false") | Ok("off") => false,
            Ok(_) => true,
            Err(_) => cfg!(debug_assertions),
        };
        Self {
            validation,
            synchronization_validation: setting.as_deref() == Ok("sync"),
            adapter: std::env::var("RIVERPLANET_ADAPTER")
                .ok()
                .filter(|s| !s.is_empty()),
            ..Default::default()
        }
    }
}

pub(super) fn load_entry() -> Result<ash::Entry, GpuError> {
    // SAFETY: loading libvulkan runs its initialisers; nothing else of ours runs concurrently with it here.
    unsafe { ash::Entry::load() }.map_err(|e| GpuError::Loader(e.to_string()))
}

pub(super) fn create_instance(
    entry: &ash::Entry,
    options: &ContextOptions,
) -> Result<(ash::Instance, bool), GpuError> {
    // SAFETY: plain queries on a loaded entry.
    let layers = unsafe { entry.enumerate_instance_layer_properties() }
        .vk("vkEnumerateInstanceLayerProperties")?;
    let has_validation = layers
        .iter()
        .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER));
    let validation = options.validation && has_validation;
    if options.validation && !has_validation {
        log::warn!("validation requested but VK_LAYER_KHRONOS_validation is not installed (vulkan-validationlayers)");
    }
    let exts = unsafe { entry.enumerate_instance_extension_properties(None) }
        .vk("vkEnumerateInstanceExtensionProperties")?;
    let has_debug_utils = exts
        .iter()
        .any(|e| e.extension_name_as_c_str() == Ok(ext::debug_utils::NAME));

    let mut ext_names: Vec<*const i8> = options
        .instance_extensions
        .iter()
        .map(|e| e.as_ptr())
        .collect();
    if has_debug_utils {
        ext_names.push(ext::debug_utils::NAME.as_ptr());
    }
    let layer_names: Vec<*const i8> = if validation {
        vec![VALIDATION_LAYER.as_ptr()]
    } else {
        vec![]
    };
    let sync_validation = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
    let mut features =
        vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync_validation);
    // The layer provides VK_EXT_validation_features, through which synchronization validation is enabled.
    let sync = validation && options.synchronization_validation;
    if sync {
        ext_names.push(ext::validation_features::NAME.as_ptr());
    }
    let app = vk::ApplicationInfo::default()
        .application_name(c"riverplanet")
        .engine_name(c"riverplanet")
        .api_version(vk::API_VERSION_1_3);
    let mut info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_extension_names(&ext_names)
        .enabled_layer_names(&layer_names);
    if sync {
        info = info.push_next(&mut features);
    }
    // SAFETY: every pointer in `info` outlives the call.
    let instance = unsafe { entry.create_instance(&info, None) }.vk("vkCreateInstance")?;
    Ok((instance, validation && has_debug_utils))
}
