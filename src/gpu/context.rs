//! The context: instance, logical device, queue, memory allocator and deferred deletion, created in that order and
//! destroyed in reverse. The instance and the options are instance.rs's, choosing the device adapter.rs's; the debug messenger and object names debug.rs's.

use std::{mem::ManuallyDrop, sync::Mutex};

use ash::{ext, vk};
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::{
    adapter::{choose, graphics_compute_family, AdapterInfo},
    debug::{self, ValidationLog},
    features,
    instance::{create_instance, load_entry, ContextOptions},
    retire::DeletionQueue,
    submit::Timeline,
    GpuError, VkResultExt,
};

/// The device and everything needed to use it. Shared by reference; internally synchronised.
pub struct Context {
    pub(super) entry: ash::Entry,
    pub(super) instance: ash::Instance,
    debug_instance: Option<ext::debug_utils::Instance>,
    messenger: vk::DebugUtilsMessengerEXT,
    pub(super) debug_device: Option<ext::debug_utils::Device>,
    pub(super) physical: vk::PhysicalDevice,
    pub(super) device: ash::Device,
    /// The queue family of the one queue, which does graphics, compute and transfers.
    pub queue_family: u32,
    queue: Mutex<vk::Queue>,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    pub(crate) deletion: std::sync::Arc<DeletionQueue>,
    pub(crate) timeline: Timeline,
    /// The device's properties and limits.
    pub properties: vk::PhysicalDeviceProperties,
    /// Its subgroups' size and operations.
    pub subgroup: features::SubgroupProperties,
    /// The bits of the queue's timestamps that count (0: no timestamps).
    pub timestamp_valid_bits: u32,
    /// Whether pipeline statistics queries are enabled (an optional feature): the profiler then counts each
    /// scope's fragment shader invocations too.
    pub pipeline_statistics: bool,
    pub(super) validation_log: Box<ValidationLog>,
    pub(super) validation_enabled: bool,
    /// What `riverplanet info` shows of the device.
    pub adapter: AdapterInfo,
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
        // SAFETY: `physical` comes from this instance.
        let pipeline_statistics = unsafe { instance.get_physical_device_features(physical) }
            .pipeline_statistics_query
            == vk::TRUE;
        enabled.core.pipeline_statistics_query = pipeline_statistics as vk::Bool32;
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
            pipeline_statistics,
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
