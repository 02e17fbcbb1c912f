//! The one synchronisation vocabulary (after vk-sync's access types, as kajiya uses them): every way a command
//! uses a resource is an [`Access`], which knows its pipeline stages, its memory access and, for images, its
//! layout. A barrier names the uses before it and the uses after it, and a buffer or image is created for the uses
//! it will have; only this module spells stage, access and usage flags.
//!
//! Layouts follow one rule: an image that shaders read or write (storage or sampled usage: the patch textures, the
//! atmosphere's table) stays in GENERAL from its first use on, written by compute shaders and copies and read by
//! every stage without a layout change between passes; attachments move between the optimal layouts of their uses.

use ash::vk;

/// How a command uses a resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// No use to wait for, or to be waited for.
    Nothing,
    /// Written by a copy or fill command.
    TransferWrite,
    /// Read by a copy command.
    TransferRead,
    /// Written as a storage buffer or image by a compute shader.
    ComputeWrite,
    /// Read as a storage buffer or image by a compute shader.
    ComputeRead,
    /// Sampled by a compute shader.
    ComputeSampled,
    /// Sampled by the vertex, geometry or fragment shaders.
    GraphicsSampled,
    /// Read as a storage buffer by a vertex shader.
    VertexShaderRead,
    /// Written as a storage buffer by a vertex shader.
    VertexShaderWrite,
    /// Read as the parameters of an indirect draw.
    IndirectCommands,
    /// Read as the index buffer of a draw.
    IndexRead,
    /// Read by any shader of any stage (what an upload must be visible to when its reader is not known).
    AnyShaderRead,
    /// Written (and blended) as a colour attachment.
    ColorAttachment,
    /// Tested and written as a depth attachment.
    DepthAttachment,
    /// Read by the host after the GPU has finished.
    HostRead,
    /// Handed to the presentation engine (after the last use of a swapchain image in a frame).
    Present,
}

impl Access {
    /// The pipeline stages of this use (a semaphore wait names them too).
    pub(crate) fn stages(self) -> vk::PipelineStageFlags2 {
        self.masks().0
    }

    /// The stages and memory accesses of this use.
    fn masks(self) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
        use vk::{AccessFlags2 as A, PipelineStageFlags2 as S};
        let graphics_shaders = S::VERTEX_SHADER | S::GEOMETRY_SHADER | S::FRAGMENT_SHADER;
        match self {
            Access::Nothing => (S::NONE, A::NONE),
            // ALL_TRANSFER: the spec puts fills in the CLEAR stage, older validation layers in COPY.
            Access::TransferWrite => (S::ALL_TRANSFER, A::TRANSFER_WRITE),
            Access::TransferRead => (S::ALL_TRANSFER, A::TRANSFER_READ),
            Access::ComputeWrite => (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            Access::ComputeRead => (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ),
            Access::ComputeSampled => (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            Access::GraphicsSampled => (graphics_shaders, A::SHADER_SAMPLED_READ),
            Access::VertexShaderRead => (S::VERTEX_SHADER, A::SHADER_STORAGE_READ),
            Access::VertexShaderWrite => (S::VERTEX_SHADER, A::SHADER_STORAGE_WRITE),
            Access::IndirectCommands => (S::DRAW_INDIRECT, A::INDIRECT_COMMAND_READ),
            Access::IndexRead => (S::INDEX_INPUT, A::INDEX_READ),
            Access::AnyShaderRead => (S::ALL_COMMANDS, A::SHADER_READ | A::SHADER_STORAGE_READ),
            Access::ColorAttachment => (
                S::COLOR_ATTACHMENT_OUTPUT,
                A::COLOR_ATTACHMENT_WRITE | A::COLOR_ATTACHMENT_READ,
            ),
            Access::DepthAttachment => (
                S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS,
                A::DEPTH_STENCIL_ATTACHMENT_WRITE | A::DEPTH_STENCIL_ATTACHMENT_READ,
            ),
            Access::HostRead => (S::HOST, A::HOST_READ),
            Access::Present => (S::BOTTOM_OF_PIPE, A::NONE),
        }
    }

    /// The buffer usage flags this use needs (none for the host's).
    fn buffer_usage(self) -> vk::BufferUsageFlags {
        use vk::BufferUsageFlags as U;
        match self {
            Access::TransferWrite => U::TRANSFER_DST,
            Access::TransferRead => U::TRANSFER_SRC,
            Access::ComputeWrite
            | Access::ComputeRead
            | Access::VertexShaderRead
            | Access::VertexShaderWrite
            | Access::AnyShaderRead => U::STORAGE_BUFFER,
            Access::IndirectCommands => U::INDIRECT_BUFFER,
            Access::IndexRead => U::INDEX_BUFFER,
            _ => U::empty(),
        }
    }

    /// The image usage flags this use needs.
    fn image_usage(self) -> vk::ImageUsageFlags {
        use vk::ImageUsageFlags as U;
        match self {
            Access::TransferWrite => U::TRANSFER_DST,
            Access::TransferRead => U::TRANSFER_SRC,
            Access::ComputeWrite | Access::ComputeRead => U::STORAGE,
            Access::ComputeSampled | Access::GraphicsSampled => U::SAMPLED,
            Access::ColorAttachment => U::COLOR_ATTACHMENT,
            Access::DepthAttachment => U::DEPTH_STENCIL_ATTACHMENT,
            _ => U::empty(),
        }
    }

    /// The layout an attachment (an image no shader reads) has for this use.
    fn optimal_layout(self) -> vk::ImageLayout {
        match self {
            Access::Nothing => vk::ImageLayout::UNDEFINED,
            Access::TransferWrite => vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            Access::TransferRead => vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            Access::ColorAttachment => vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            Access::DepthAttachment => vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
            Access::Present => vk::ImageLayout::PRESENT_SRC_KHR,
            _ => vk::ImageLayout::GENERAL,
        }
    }

    /// The layout of an image for this use: GENERAL for images shaders use (module doc), else the optimal one.
    pub(crate) fn layout(self, shader_visible: bool) -> vk::ImageLayout {
        if shader_visible && self != Access::Nothing {
            vk::ImageLayout::GENERAL
        } else {
            self.optimal_layout()
        }
    }
}

/// The usage flags a buffer needs for all of `uses`.
pub(crate) fn buffer_usage(uses: &[Access]) -> vk::BufferUsageFlags {
    uses.iter()
        .fold(vk::BufferUsageFlags::empty(), |u, a| u | a.buffer_usage())
}

/// The usage flags an image needs for all of `uses`.
pub(crate) fn image_usage(uses: &[Access]) -> vk::ImageUsageFlags {
    uses.iter()
        .fold(vk::ImageUsageFlags::empty(), |u, a| u | a.image_usage())
}

/// The stages and accesses of one side of a barrier. Only writes need to be made available, so the source side
/// keeps the write accesses alone (reads before a barrier need just the execution dependency).
fn side(accesses: &[Access], source: bool) -> (vk::PipelineStageFlags2, vk::AccessFlags2) {
    accesses.iter().fold(
        (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE),
        |(stages, access), a| {
            let (s, m) = a.masks();
            (stages | s, access | if source { m & WRITES } else { m })
        },
    )
}

/// The accesses that write.
const WRITES: vk::AccessFlags2 = vk::AccessFlags2::from_raw(
    vk::AccessFlags2::TRANSFER_WRITE.as_raw()
        | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw()
        | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE.as_raw()
        | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
);

/// Whether every one of `accesses` reads a resource's contents and none writes them: reads like these may run
/// together, as a render graph's read-only uses combine.
pub(crate) fn reads_only(accesses: &[Access]) -> bool {
    !accesses.is_empty()
        && accesses.iter().all(|&a| {
            !matches!(a, Access::Nothing | Access::Present) && (a.masks().1 & WRITES).is_empty()
        })
}

/// A barrier of the whole of `buffer` between the uses `before` and `after`.
pub(crate) fn buffer_barrier(
    buffer: vk::Buffer,
    before: &[Access],
    after: &[Access],
) -> vk::BufferMemoryBarrier2<'static> {
    let (src_stage, src_access) = side(before, true);
    let (dst_stage, dst_access) = side(after, false);
    vk::BufferMemoryBarrier2::default()
        .buffer(buffer)
        .size(vk::WHOLE_SIZE)
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
}

/// What happens to an image at a barrier: the uses before and after it, and whether its contents may be
/// discarded (they are then not kept through the layout change: an image about to be cleared or overwritten).
#[derive(Clone, Copy, Debug)]
pub(crate) struct ImageUse<'a> {
    pub before: &'a [Access],
    pub after: &'a [Access],
    pub discard: bool,
}

/// A barrier of every subresource in `range` of `image` for `usage`; `shader_visible` picks the layouts (module
/// doc). The uses on each side must agree on the layout.
pub(crate) fn image_barrier(
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    shader_visible: bool,
    usage: &ImageUse,
) -> vk::ImageMemoryBarrier2<'static> {
    let layout = |accesses: &[Access]| {
        let first = accesses
            .first()
            .map_or(vk::ImageLayout::UNDEFINED, |a| a.layout(shader_visible));
        debug_assert!(
            accesses.iter().all(|a| a.layout(shader_visible) == first),
            "uses {accesses:?} need different layouts"
        );
        first
    };
    let (src_stage, src_access) = side(usage.before, true);
    let (dst_stage, dst_access) = side(usage.after, false);
    vk::ImageMemoryBarrier2::default()
        .image(image)
        .subresource_range(range)
        .old_layout(if usage.discard {
            vk::ImageLayout::UNDEFINED
        } else {
            layout(usage.before)
        })
        .new_layout(layout(usage.after))
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_barrier_makes_only_writes_available_and_waits_for_every_use_after() {
        let b = buffer_barrier(
            vk::Buffer::null(),
            &[Access::ComputeRead, Access::ComputeWrite],
            &[Access::IndirectCommands, Access::VertexShaderRead],
        );
        assert_eq!(b.src_stage_mask, vk::PipelineStageFlags2::COMPUTE_SHADER);
        assert_eq!(b.src_access_mask, vk::AccessFlags2::SHADER_STORAGE_WRITE);
        assert_eq!(
            b.dst_stage_mask,
            vk::PipelineStageFlags2::DRAW_INDIRECT | vk::PipelineStageFlags2::VERTEX_SHADER
        );
        assert_eq!(
            b.dst_access_mask,
            vk::AccessFlags2::INDIRECT_COMMAND_READ | vk::AccessFlags2::SHADER_STORAGE_READ
        );
    }

    #[test]
    fn shader_visible_images_stay_general_and_attachments_take_optimal_layouts() {
        let range = vk::ImageSubresourceRange::default();
        let sampled = ImageUse {
            before: &[Access::TransferWrite],
            after: &[Access::GraphicsSampled],
            discard: false,
        };
        let b = image_barrier(vk::Image::null(), range, true, &sampled);
        assert_eq!(
            (b.old_layout, b.new_layout),
            (vk::ImageLayout::GENERAL, vk::ImageLayout::GENERAL)
        );
        let readback = ImageUse {
            before: &[Access::ColorAttachment],
            after: &[Access::TransferRead],
            discard: false,
        };
        let b = image_barrier(vk::Image::null(), range, false, &readback);
        assert_eq!(b.old_layout, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL);
        assert_eq!(b.new_layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        let cleared = ImageUse {
            before: &[Access::ColorAttachment],
            after: &[Access::ColorAttachment],
            discard: true,
        };
        let b = image_barrier(vk::Image::null(), range, false, &cleared);
        assert_eq!(b.old_layout, vk::ImageLayout::UNDEFINED);
        // The wait for the earlier frame's writes (or the swapchain's acquire) stays.
        assert_eq!(
            b.src_stage_mask,
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT
        );
    }
}
