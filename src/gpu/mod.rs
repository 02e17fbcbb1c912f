//! The Vulkan backend: the only module that imports `ash`. It knows nothing of planets.
//!
//! One file per concern, as in wgpu-hal: [`access`] (the synchronisation vocabulary: every barrier names uses, not
//! stage and access flags), [`instance`] (the loader, the instance and the options a context is made with), [`adapter`] (describing the
//! devices and choosing one), [`context`] (device, queue, allocator), `debug` (validation messages, object names, labels),
//! [`features`] (the one negotiated feature struct), [`memory`] (named buffers and images), [`retire`] (deferred deletion and reuse),
//! [`commands`] (everything recorded into a command buffer: uploads, copies, barriers, dispatches, draws), [`submit`]
//! (command buffers, timeline-semaphore submissions), [`frames`] (the ring of
//! frame contexts that keeps frames in flight), [`bindless`] (the global descriptor-indexed set), [`pipeline`]
//! (shader modules and pipelines), [`profiler`] (timestamp scopes), [`swapchain`] (window presentation), [`overlay`]
//! (egui's triangles, for the viewer).

pub mod access;
pub mod adapter;
pub mod bindless;
pub mod commands;
pub mod context;
mod debug;
pub mod features;
pub mod frames;
pub mod instance;
pub mod layers;
pub mod memory;
pub mod overlay;
pub mod pipeline;
pub mod profiler;
pub mod retire;
mod state;
pub mod submit;
pub mod swapchain;

pub use access::Access;
pub use adapter::AdapterInfo;
/// The plain Vulkan value types the layers above describe resources and frames with; they name no flags and call
/// no Vulkan (synchronisation and usage are said in [`Access`]es).
pub use ash::vk::{
    DescriptorSet, DescriptorSetLayout, DrawIndexedIndirectCommand, Extent2D, Format, Semaphore,
};
pub use context::Context;
pub use features::FeatureReport;
pub use instance::ContextOptions;
pub use memory::{Buffer, BufferDesc, Image, ImageDesc, MemoryLocation};
pub use profiler::{Profiler, ScopeTiming};
pub use submit::{Recorder, SubmissionId};

use ash::vk;

/// Everything that can go wrong in the backend. The failing Vulkan call travels with its result.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// libvulkan.so.1 cannot be loaded (the loader's message).
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}; install libvulkan1 and a driver (tools/setup)")]
    Loader(String),
    /// A Vulkan call returned an error.
    #[error("{call} failed: {result}")]
    Vk {
        /// The call.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// The device was lost (VK_ERROR_DEVICE_LOST).
    #[error("the GPU device was lost during {call}; restart the program (driver reset or crash)")]
    DeviceLost {
        /// The call that found it lost.
        call: &'static str,
    },
    /// No Vulkan device at all.
    #[error("no Vulkan device found; install a driver (tools/setup installs Mesa lavapipe)")]
    NoDevice,
    /// `--adapter` matches no device.
    #[error("no Vulkan device name contains '{filter}' (--adapter / RIVERPLANET_ADAPTER); devices: {available}")]
    NoMatchingAdapter {
        /// The text asked for.
        filter: String,
        /// The devices there are.
        available: String,
    },
    /// The device lacks a required feature (gpu/features.rs).
    #[error("device '{device}' lacks required Vulkan feature(s): {missing}")]
    MissingFeature {
        /// The device's name.
        device: String,
        /// The features it lacks.
        missing: String,
    },
    /// The device runs compute but is known to fail drawing (adapter.rs `cannot_draw`: lavapipe with narrow vectors).
    #[error("device '{device}' cannot draw this renderer: {reason}")]
    CannotDraw {
        /// The device's name.
        device: String,
        /// What it lacks.
        reason: String,
    },
    /// gpu-allocator could not allocate.
    #[error("GPU memory allocation for '{name}' failed: {source}")]
    Allocation {
        /// The resource's name.
        name: String,
        /// gpu-allocator's error.
        #[source]
        source: gpu_allocator::AllocationError,
    },
    /// A request that cannot be met (a job too large, no free bindless slot, a buffer that is not host-visible).
    #[error("invalid request: {0}")]
    Invalid(String),
}

/// Attaches the name of the Vulkan call to a `VkResult`, and turns device loss into its own error.
pub(crate) trait VkResultExt<T> {
    fn vk(self, call: &'static str) -> Result<T, GpuError>;
}

impl<T> VkResultExt<T> for Result<T, vk::Result> {
    fn vk(self, call: &'static str) -> Result<T, GpuError> {
        self.map_err(|result| match result {
            vk::Result::ERROR_DEVICE_LOST => GpuError::DeviceLost { call },
            result => GpuError::Vk { call, result },
        })
    }
}
