//! The context: instance, logical device, queue, memory allocator and deferred deletion, created in that order and
//! destroyed in reverse. Choosing the device is adapter.rs's job; the debug messenger and object names debug.rs's.

use std::{ffi::CStr, mem::ManuallyDrop, sync::Mutex};

use ash::{ext, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::{
    adapter::{choose, graphics_compute_family, AdapterInfo},
    debug::{self, ValidationLog, VALIDATION_LAYER},
    features,
    memory::DeletionQueue,
    submit::Timeline,
    GpuError, VkResultExt,
};

/// How to create a [`Context`].
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

/// The device and everything needed to use it. Shared by reference; internally synchronised.
pub struct Context {
    pub(crate) entry: ash::Entry,
    pub instance: ash::Instance,
    debug_instance: Option<ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    pub(super) debug_device: Option<ext::debug_utils::Device>,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub queue_family: u32,
    queue: Mutex<vk::Queue>,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) deletion: std::sync::Arc<DeletionQueue>,
    pub(crate) timeline: Timeline,
    pub properties: vk::PhysicalDeviceProperties,
    pub subgroup: features::SubgroupProperties,
    pub timestamp_valid_bits: u32,
    pub(super) validation_log: Box<ValidationLog>,
    pub(super) validation_enabled: bool,
    pub adapter: AdapterInfo,
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

impl Context {
    /// Creates the instance and device. Fails with a named error when no device or a required feature is missing.
    pub fn new(options: &ContextOptions) -> Result<Self, GpuError> {
        let entry = load_entry()?;
        let (instance, validation_enabled) = create_instance(&entry, options)?;
        // The context gets its own handle to the loader: this one keeps libvulkan loaded until the instance is
        // destroyed on the error path (dropping the only Entry first unloads the library under the call, which
        // crashed every command on a device that was present but unusable).
        match Self::with_instance(entry.clone(), instance.clone(), validation_enabled, options) {
            Ok(ctx) => Ok(ctx),
            Err(e) => {
                // SAFETY: with_instance destroyed everything it created before failing; `entry` is still loaded.
                unsafe { instance.destroy_instance(None) };
                drop(entry);
                Err(e)
            }
        }
    }

    fn with_instance(
        entry: ash::Entry,
        instance: ash::Instance,
        validation_enabled: bool,
        options: &ContextOptions,
    ) -> Result<Self, GpuError> {
        let (infos, physicals, chosen) = choose(&instance, options)?;
        for info in &infos {
            log::info!(
                "device: {} ({}, Vulkan {}, driver {} {}){}",
                info.name,
                info.device_type,
                info.api_version,
                info.driver_name,
                info.driver_info,
                if info.chosen { " <- chosen" } else { "" }
            );
        }
        let Some(idx) = chosen else {
            return Err(match &options.adapter {
                Some(filter) if !infos.is_empty() => GpuError::NoMatchingAdapter {
                    filter: filter.clone(),
                    available: infos
                        .iter()
                        .map(|i| i.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", "),
                },
                _ => GpuError::NoDevice,
            });
        };
        let adapter = infos[idx].clone();
        if !adapter.features.all_supported() {
            return Err(GpuError::MissingFeature {
                device: adapter.name.clone(),
                missing: adapter.features.missing().join(", "),
            });
        }
        if let (true, Some(reason)) = (options.draws, super::adapter::cannot_draw(&adapter)) {
            return Err(GpuError::CannotDraw {
                device: adapter.name.clone(),
                reason,
            });
        }
        let physical = physicals[idx];
        let queue_family =
            graphics_compute_family(&instance, physical).ok_or(GpuError::NoDevice)?;

        let validation_log = Box::<ValidationLog>::default();
        let (debug_instance, messenger) = if validation_enabled {
            let (debug, messenger) = debug::messenger(&entry, &instance, &validation_log)?;
            (Some(debug), messenger)
        } else {
            (None, vk::DebugUtilsMessengerEXT::null())
        };

        let mut enabled = features::EnabledFeatures::required();
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let mut device_exts: Vec<*const i8> = vec![];
        if options.swapchain {
            device_exts.push(ash::khr::swapchain::NAME.as_ptr());
        }
        let mut features2 = vk::PhysicalDeviceFeatures2::default()
            .features(enabled.core)
            .push_next(&mut enabled.v12)
            .push_next(&mut enabled.v13);
        let device_info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&device_exts)
            .push_next(&mut features2);
        // SAFETY: every pointer in `device_info` outlives the call; features were checked above.
        let device = unsafe { instance.create_device(physical, &device_info, None) };
        let device = match device.vk("vkCreateDevice") {
            Ok(d) => d,
            Err(e) => {
                if let Some(debug) = &debug_instance {
                    // SAFETY: created above, unused elsewhere.
                    unsafe { debug.destroy_debug_utils_messenger(messenger, None) };
                }
                return Err(e);
            }
        };
        // SAFETY: family index 0 of the family we created.
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let properties = unsafe { instance.get_physical_device_properties(physical) };
        let subgroup = features::subgroup_properties(&instance, physical);
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let timestamp_valid_bits = families[queue_family as usize].timestamp_valid_bits;

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })
        .map_err(|source| GpuError::Allocation {
            name: "allocator".into(),
            source,
        })?;
        let timeline = Timeline::new(&device)?;
        let debug_device =
            validation_enabled.then(|| ext::debug_utils::Device::new(&instance, &device));
        log::info!(
            "using '{}' (validation {})",
            adapter.name,
            if validation_enabled { "on" } else { "off" }
        );
        Ok(Self {
            entry,
            instance,
            debug_instance,
            messenger,
            debug_device,
            physical,
            device,
            queue_family,
            queue: Mutex::new(queue),
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            deletion: std::sync::Arc::new(DeletionQueue::new(timeline.last.clone())),
            timeline,
            properties,
            subgroup,
            timestamp_valid_bits,
            validation_log,
            validation_enabled,
            adapter,
        })
    }

    pub(crate) fn queue(&self) -> std::sync::MutexGuard<'_, vk::Queue> {
        self.queue.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Waits until the device is idle and frees everything retired. For shutdown and tests, not per frame.
    pub fn wait_idle(&self) -> Result<(), GpuError> {
        let _queue = self.queue();
        // SAFETY: the queue lock is held, so no submission races with the wait.
        unsafe { self.device.device_wait_idle() }.vk("vkDeviceWaitIdle")?;
        drop(_queue);
        self.collect_garbage();
        Ok(())
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        // Shutdown order: wait idle, flush deferred deletions, drop the allocator (it reports leaks),
        // destroy device, messenger, instance.
        if let Err(e) = self.wait_idle() {
            log::error!("shutdown: {e}");
        }
        self.deletion.flush_all(&self.device, &self.allocator);
        self.timeline.destroy(&self.device);
        // SAFETY: nothing else uses the allocator after this point.
        let allocator = unsafe { ManuallyDrop::take(&mut self.allocator) };
        if let Ok(allocator) = allocator.into_inner() {
            allocator.report_memory_leaks(log::Level::Warn);
            drop(allocator);
        }
        // SAFETY: all child objects were destroyed above; reverse creation order.
        unsafe {
            self.device.destroy_device(None);
            if let Some(debug) = &self.debug_instance {
                debug.destroy_debug_utils_messenger(self.messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
