//! Validation and debugging: the Khronos validation layer's messages collected (errors fail every GPU test), and
//! names and labels for validation messages and capture tools (RenderDoc).

use std::{
    ffi::{c_void, CStr},
    sync::Mutex,
};

use ash::{ext, vk};

use super::{Context, GpuError, VkResultExt};

pub(super) const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Validation messages collected by the debug messenger. Errors make every GPU test fail.
#[derive(Default)]
pub(super) struct ValidationLog {
    errors: Mutex<Vec<String>>,
    /// Synchronization hazards reported through the bindless set's runtime arrays, which are not counted as errors
    /// (`is_runtime_array_hazard`).
    waived: std::sync::atomic::AtomicUsize,
    /// The raw handles of the bindless sets: a message names the set by handle even where the layer has lost its
    /// name (seen with two renderers on one device in concurrent tests).
    runtime_array_sets: Mutex<Vec<u64>>,
}

/// Whether `message` is a synchronization hazard that validation layers before 1.3.268 report for every element of
/// a runtime descriptor array the pipeline declares, accessed or not (Vulkan-ValidationLayers issue 3450): every
/// dispatch and draw that binds the bindless set would "write" every patch texture. Later layers skip runtime
/// arrays in synchronization validation altogether (pull request 6605), so waiving them checks what they check.
/// The set is recognised by its name or by one of `sets`' raw handles.
fn is_runtime_array_hazard(message: &str, sets: &[u64]) -> bool {
    message.contains("SYNC-HAZARD")
        && (message.contains(&format!("[{}]", super::bindless::SET_NAME))
            || sets
                .iter()
                .any(|h| message.contains(&format!("VkDescriptorSet 0x{h:x}["))))
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // Never unwind across FFI: a panic here is caught and dropped.
    let _ = std::panic::catch_unwind(|| {
        // SAFETY: the layer passes valid callback data for the duration of the call.
        let message = unsafe { data.as_ref() }
            .and_then(|d| unsafe { d.message_as_c_str() })
            .map(|m| m.to_string_lossy().into_owned())
            .unwrap_or_default();
        // SAFETY: `user` is the boxed ValidationLog owned by the Context, alive until the messenger is destroyed.
        let validation_log = unsafe { (user as *const ValidationLog).as_ref() };
        if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
            let sets = validation_log
                .and_then(|log| log.runtime_array_sets.lock().ok().map(|s| s.clone()))
                .unwrap_or_default();
            if is_runtime_array_hazard(&message, &sets) {
                log::debug!("[vulkan {kind:?}] waived (runtime descriptor array): {message}");
                if let Some(log) = validation_log {
                    log.waived
                        .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                }
                return;
            }
            log::error!("[vulkan {kind:?}] {message}");
            if let Some(log) = validation_log {
                if let Ok(mut errors) = log.errors.lock() {
                    errors.push(message);
                }
            }
        } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
            log::warn!("[vulkan {kind:?}] {message}");
        } else {
            log::debug!("[vulkan {kind:?}] {message}");
        }
    });
    vk::FALSE
}

/// The debug messenger that reports the layer's warnings and errors into `log`, which must stay where it is
/// (boxed) until the messenger is destroyed.
pub(super) fn messenger(
    entry: &ash::Entry,
    instance: &ash::Instance,
    log: &ValidationLog,
) -> Result<(ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT), GpuError> {
    let debug = ext::debug_utils::Instance::new(entry, instance);
    let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
        .message_severity(
            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
        )
        .message_type(
            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
        )
        .pfn_user_callback(Some(debug_callback))
        .user_data(log as *const ValidationLog as *mut c_void);
    // SAFETY: the user data box outlives the messenger (destroyed first in Drop).
    let messenger = unsafe { debug.create_debug_utils_messenger(&info, None) }
        .vk("vkCreateDebugUtilsMessengerEXT")?;
    Ok((debug, messenger))
}

impl Context {
    /// Whether the validation layer is active (and its errors are being collected).
    pub fn validation_enabled(&self) -> bool {
        self.validation_enabled
    }

    /// Registers a bindless set, whose runtime arrays' synchronization hazards are waived (`is_runtime_array_hazard`).
    pub(crate) fn register_runtime_array_set(&self, set: vk::DescriptorSet) {
        if let Ok(mut sets) = self.validation_log.runtime_array_sets.lock() {
            sets.push(vk::Handle::as_raw(set));
        }
    }

    /// Synchronization hazards waived so far because they were reported through the bindless set's runtime arrays
    /// (`is_runtime_array_hazard`).
    pub fn waived_validation_messages(&self) -> usize {
        self.validation_log
            .waived
            .load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Validation errors reported so far. GPU tests assert this is empty.
    pub fn validation_errors(&self) -> Vec<String> {
        self.validation_log
            .errors
            .lock()
            .map(|e| e.clone())
            .unwrap_or_default()
    }

    /// Gives `handle` a name for validation messages and capture tools (RenderDoc).
    pub fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // SAFETY: the handle belongs to this device; naming failure is harmless, so the result is ignored.
        let _ = unsafe { debug.set_debug_utils_object_name(&info) };
    }

    /// Opens a debug label region in `cmd` (shown by capture tools); close it with [`Self::end_label`].
    pub fn begin_label(&self, cmd: vk::CommandBuffer, name: &str) {
        let Some(debug) = &self.debug_device else {
            return;
        };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        // SAFETY: cmd is recording.
        unsafe { debug.cmd_begin_debug_utils_label(cmd, &label) };
    }

    /// Closes the label `begin_label` opened (nothing without the debug-utils extension).
    pub fn end_label(&self, cmd: vk::CommandBuffer) {
        if let Some(debug) = &self.debug_device {
            // SAFETY: paired with begin_label on a recording command buffer.
            unsafe { debug.cmd_end_debug_utils_label(cmd) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runtime_array_hazards_are_recognised_by_the_set_name_or_its_handle() {
        let named = "Validation Error: [ SYNC-HAZARD-WRITE-AFTER-WRITE ] ... VkDescriptorSet 0x11[bindless set], \
                     type: VK_DESCRIPTOR_TYPE_STORAGE_IMAGE";
        let unnamed = "Validation Error: [ SYNC-HAZARD-WRITE-AFTER-WRITE ] ... VkDescriptorSet 0x110000000011[], \
                       type: VK_DESCRIPTOR_TYPE_STORAGE_IMAGE";
        assert!(is_runtime_array_hazard(named, &[]));
        assert!(!is_runtime_array_hazard(unnamed, &[]));
        assert!(is_runtime_array_hazard(unnamed, &[0x110000000011]));
        assert!(!is_runtime_array_hazard(unnamed, &[0x11]));
        let other =
            "Validation Error: [ VUID-vkCmdDraw-None-02699 ] VkDescriptorSet 0x110000000011[]";
        assert!(!is_runtime_array_hazard(other, &[0x110000000011]));
    }
}
