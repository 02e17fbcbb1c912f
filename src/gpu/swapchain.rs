//! Presentation to a window: the surface, the swapchain with its image views, and acquire/present with binary
//! semaphores. Out-of-date and suboptimal swapchains are reported so the caller can recreate them (resize).

use std::{ffi::CStr, sync::Arc};

use ash::{khr, vk};
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};

use super::{
    pipeline::RenderTarget, state::UseState, Access, Context, GpuError, Image, VkResultExt,
};

/// The instance extensions a window on `display` needs.
pub fn surface_extensions(display: RawDisplayHandle) -> Result<Vec<&'static CStr>, GpuError> {
    let names = ash_window::enumerate_required_extensions(display)
        .vk("vkEnumerateInstanceExtensionProperties")?;
    // SAFETY: ash-window returns pointers to static NUL-terminated extension names.
    Ok(names
        .iter()
        .map(|&p| unsafe { CStr::from_ptr(p) })
        .collect())
}

/// A window's Vulkan surface.
pub struct Surface {
    loader: khr::surface::Instance,
    raw: vk::SurfaceKHR,
}

impl Surface {
    /// Creates a surface for a window. The window must outlive the surface.
    pub fn new(
        ctx: &Context,
        display: RawDisplayHandle,
        window: RawWindowHandle,
    ) -> Result<Self, GpuError> {
        // SAFETY: the handles come from a live window (caller's contract).
        let raw =
            unsafe { ash_window::create_surface(&ctx.entry, &ctx.instance, display, window, None) }
                .vk("vkCreate*SurfaceKHR")?;
        let loader = khr::surface::Instance::new(&ctx.entry, &ctx.instance);
        // SAFETY: plain query.
        let supported = unsafe {
            loader.get_physical_device_surface_support(ctx.physical, ctx.queue_family, raw)
        }
        .vk("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !supported {
            unsafe { loader.destroy_surface(raw, None) };
            return Err(GpuError::MissingFeature {
                device: ctx.adapter.name.clone(),
                missing: "presentation to this window from the graphics queue".into(),
            });
        }
        Ok(Self { loader, raw })
    }

    /// Destroys the surface; its swapchain must be destroyed first.
    pub fn destroy(self) {
        // SAFETY: the swapchain using it was destroyed first.
        unsafe { self.loader.destroy_surface(self.raw, None) };
    }
}

/// The images a window presents, with their views and what each was last used for.
pub struct Swapchain {
    loader: khr::swapchain::Device,
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    views: Vec<vk::ImageView>,
    /// What each image was last recorded for (gpu/state.rs).
    states: Vec<Arc<UseState>>,
    /// The images' format and size.
    pub format: vk::Format,
    /// See `format`.
    pub extent: vk::Extent2D,
    /// Acquire semaphores, used in turn: one more than the most frames in flight, so the one acquired next is never
    /// still awaited by a queued frame.
    acquired: Vec<vk::Semaphore>,
    next_acquired: usize,
    rendered: Vec<vk::Semaphore>,
}

/// The colour format the viewer renders in.
pub const SWAPCHAIN_FORMAT: vk::Format = vk::Format::B8G8R8A8_UNORM;

impl Swapchain {
    /// The target of a frame drawn into image `index` (from `acquire`) with `depth`, cleared to `clear_color`.
    /// The image comes back from the presentation engine with its contents undefined, and the acquire semaphore is
    /// waited for at colour output: its first barrier waits there.
    pub fn target(&self, index: u32, depth: &Image, clear_color: [f32; 4]) -> RenderTarget {
        let state = self.states[index as usize].clone();
        state.set(&[Access::ColorAttachment]);
        RenderTarget {
            color_image: self.images[index as usize],
            color_view: self.views[index as usize],
            color_state: state,
            depth_image: depth.raw,
            depth_view: depth.view,
            depth_state: depth.state.clone(),
            extent: self.extent,
            clear_color,
        }
    }

    /// A swapchain of `SWAPCHAIN_FORMAT` for `surface`, sized to the surface (or `width x height` when the
    /// surface leaves it to us), FIFO presentation.
    pub fn new(
        ctx: &Context,
        surface: &Surface,
        width: u32,
        height: u32,
    ) -> Result<Self, GpuError> {
        // SAFETY: plain queries.
        let caps = unsafe {
            surface
                .loader
                .get_physical_device_surface_capabilities(ctx.physical, surface.raw)
        }
        .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let formats = unsafe {
            surface
                .loader
                .get_physical_device_surface_formats(ctx.physical, surface.raw)
        }
        .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let format = formats
            .iter()
            .find(|f| f.format == SWAPCHAIN_FORMAT)
            .copied()
            .ok_or_else(|| GpuError::MissingFeature {
                device: ctx.adapter.name.clone(),
                missing: format!("surface format {SWAPCHAIN_FORMAT:?} (has {:?})", formats),
            })?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        let count = if caps.max_image_count > 0 {
            (caps.min_image_count + 1).min(caps.max_image_count)
        } else {
            caps.min_image_count + 1
        };
        let loader = khr::swapchain::Device::new(&ctx.instance, &ctx.device);
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.raw)
            .min_image_count(count)
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::COLOR_ATTACHMENT)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(vk::PresentModeKHR::FIFO)
            .clipped(true);
        // SAFETY: valid create info.
        let raw = unsafe { loader.create_swapchain(&info, None) }.vk("vkCreateSwapchainKHR")?;
        let images = unsafe { loader.get_swapchain_images(raw) }.vk("vkGetSwapchainImagesKHR")?;
        let mut views = Vec::with_capacity(images.len());
        for (k, &image) in images.iter().enumerate() {
            let view_info = vk::ImageViewCreateInfo::default()
                .image(image)
                .view_type(vk::ImageViewType::TYPE_2D)
                .format(format.format)
                .subresource_range(
                    vk::ImageSubresourceRange::default()
                        .aspect_mask(vk::ImageAspectFlags::COLOR)
                        .level_count(1)
                        .layer_count(1),
                );
            let view = unsafe { ctx.device.create_image_view(&view_info, None) }
                .vk("vkCreateImageView")?;
            ctx.set_name(view, &format!("swapchain view {k}"));
            views.push(view);
        }
        let semaphore = || unsafe {
            ctx.device
                .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
        };
        let acquired = (0..=super::frames::MAX_FRAMES_IN_FLIGHT)
            .map(|_| semaphore().vk("vkCreateSemaphore"))
            .collect::<Result<_, _>>()?;
        let rendered = (0..images.len())
            .map(|_| semaphore().vk("vkCreateSemaphore"))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            loader,
            raw,
            states: images.iter().map(|_| UseState::fresh()).collect(),
            images,
            views,
            format: format.format,
            extent,
            acquired,
            next_acquired: 0,
            rendered,
        })
    }

    /// The next image: (index, semaphore signalled when it is ready, semaphore to signal when rendered), or `None`
    /// when the swapchain must be recreated.
    pub fn acquire(&mut self) -> Result<Option<(u32, vk::Semaphore, vk::Semaphore)>, GpuError> {
        let acquired = self.acquired[self.next_acquired];
        self.next_acquired = (self.next_acquired + 1) % self.acquired.len();
        // SAFETY: the semaphore is unsignalled: the frame that waited on it is more frames back than a frame ring
        // holds, and the ring has waited for it.
        match unsafe {
            self.loader
                .acquire_next_image(self.raw, u64::MAX, acquired, vk::Fence::null())
        } {
            Ok((index, false)) => Ok(Some((index, acquired, self.rendered[index as usize]))),
            Ok((_, true)) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(None),
            Err(result) => Err(GpuError::Vk {
                call: "vkAcquireNextImageKHR",
                result,
            }),
        }
    }

    /// Presents `index` after its rendered semaphore; `false` when the swapchain must be recreated.
    pub fn present(&self, ctx: &Context, index: u32) -> Result<bool, GpuError> {
        let swapchains = [self.raw];
        let indices = [index];
        let waits = [self.rendered[index as usize]];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&waits)
            .swapchains(&swapchains)
            .image_indices(&indices);
        let queue = ctx.queue();
        // SAFETY: queue access is serialised by the lock.
        match unsafe { self.loader.queue_present(*queue, &info) } {
            Ok(false) => Ok(true),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(result) => Err(GpuError::Vk {
                call: "vkQueuePresentKHR",
                result,
            }),
        }
    }

    /// Destroys the swapchain (after the device is idle).
    pub fn destroy(self, ctx: &Context) {
        // SAFETY: the caller waited for the device to be idle.
        unsafe {
            for v in self.views {
                ctx.device.destroy_image_view(v, None);
            }
            for s in self.acquired {
                ctx.device.destroy_semaphore(s, None);
            }
            for s in self.rendered {
                ctx.device.destroy_semaphore(s, None);
            }
            self.loader.destroy_swapchain(self.raw, None);
        }
    }
}
