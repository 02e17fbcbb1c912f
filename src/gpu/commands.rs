//! Everything a [`Recorder`] records into its command buffer but timestamps and debug labels (profiler.rs,
//! context.rs): uploads through staging buffers, copies and fills, barriers (in the uses of gpu/access.rs),
//! dispatches, dynamic rendering and draws. Uploads go through one path: a staging buffer, a copy, a barrier. Recording and submitting the command buffer is submit.rs's job.

use ash::vk;

use super::{
    access::{self, Access, ImageUse},
    pipeline::{Attachment, ComputePipeline, GraphicsPipeline, RenderTarget},
    state::UseState,
    Buffer, BufferDesc, GpuError, Image, MemoryLocation, Recorder,
};

impl Recorder<'_> {
    fn stage(&mut self, name: &str, data: &[u8]) -> Result<vk::Buffer, GpuError> {
        let mut staging = self.ctx.create_buffer(&BufferDesc {
            name: &format!("staging for {name}"),
            size: data.len() as u64,
            uses: &[Access::TransferRead],
            location: MemoryLocation::CpuToGpu,
        })?;
        staging.write(0, data)?;
        let raw = staging.raw;
        self.owned.push(staging);
        Ok(raw)
    }

    /// Copies `data` into `dst` at `offset` through a staging buffer, then makes it visible to shaders.
    pub fn upload_buffer(
        &mut self,
        dst: &Buffer,
        offset: u64,
        data: &[u8],
    ) -> Result<(), GpuError> {
        if data.is_empty() {
            return Ok(());
        }
        if offset + data.len() as u64 > dst.size {
            return Err(GpuError::Invalid(format!(
                "upload of {} bytes at {offset} overflows buffer '{}' of {} bytes",
                data.len(),
                dst.name,
                dst.size
            )));
        }
        let src = self.stage(&dst.name, data)?;
        self.use_buffer(dst, &[Access::TransferWrite]);
        let region = vk::BufferCopy::default()
            .dst_offset(offset)
            .size(data.len() as u64);
        // SAFETY: both buffers are alive until the submission completes (staging is retired after it).
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer(self.cmd, src, dst.raw, &[region])
        };
        self.use_buffer(dst, &[Access::AnyShaderRead]);
        Ok(())
    }

    /// Copies tightly packed texels into array layer `layer` of `dst` through a staging buffer. The image must be in
    /// its layout for [`Access::TransferWrite`] (after a barrier to that use).
    pub fn upload_image_layer(
        &mut self,
        dst: &Image,
        layer: u32,
        data: &[u8],
    ) -> Result<(), GpuError> {
        let layout = Access::TransferWrite.layout(dst.shader_visible());
        let src = self.stage(&dst.name, data)?;
        let region = whole_layers(dst, layer, 1, 0);
        // SAFETY: the image is in `layout` (caller's contract: the barrier before) and alive until completion.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer_to_image(self.cmd, src, dst.raw, layout, &[region])
        };
        Ok(())
    }

    /// Copies the whole of `src` (in its layout for [`Access::TransferRead`]) into `dst` at `offset`, layer after
    /// layer, tightly packed (a transfer write of `dst`: [`Self::use_buffer`]).
    pub fn copy_image_to_buffer(&mut self, src: &Image, dst: &Buffer, offset: u64) {
        self.copy_layers_to_buffer(src, 0..src.layers, dst, offset);
    }

    /// Copies `layers` of `src` (in its layout for [`Access::TransferRead`]) into `dst` at `offset`, layer after
    /// layer, tightly packed (a transfer write of `dst`: [`Self::use_buffer`]).
    pub fn copy_layers_to_buffer(
        &mut self,
        src: &Image,
        layers: std::ops::Range<u32>,
        dst: &Buffer,
        offset: u64,
    ) {
        self.use_buffer(dst, &[Access::TransferWrite]);
        let layout = Access::TransferRead.layout(src.shader_visible());
        let region = whole_layers(src, layers.start, layers.len() as u32, offset);
        // SAFETY: the layout is the caller's contract (the barrier before); both objects outlive the submission.
        unsafe {
            self.ctx
                .device
                .cmd_copy_image_to_buffer(self.cmd, src.raw, layout, dst.raw, &[region])
        };
    }

    /// Copies the first `size` bytes of `src` to `dst`, then makes them visible to the host.
    pub fn copy_buffer(&mut self, src: &Buffer, dst: &Buffer, size: u64) {
        self.use_buffer(src, &[Access::TransferRead]);
        self.use_buffer(dst, &[Access::TransferWrite]);
        let region = vk::BufferCopy::default().size(size);
        // SAFETY: both buffers outlive the submission.
        unsafe {
            self.ctx
                .device
                .cmd_copy_buffer(self.cmd, src.raw, dst.raw, &[region])
        };
        self.use_buffer(dst, &[Access::HostRead]);
    }

    /// Fills all of `buffer` with the `u32` `value` (for buffers the GPU accumulates into, e.g. with atomics): a
    /// transfer write of it ([`Self::use_buffer`]).
    pub fn fill_buffer(&mut self, buffer: &Buffer, value: u32) {
        self.use_buffer(buffer, &[Access::TransferWrite]);
        // SAFETY: recording; the buffer outlives the submission and has TRANSFER_DST usage (validated).
        unsafe {
            self.ctx.device.cmd_fill_buffer(
                self.cmd,
                buffer.raw,
                0,
                buffer.size.max(4).next_multiple_of(4),
                value,
            )
        };
    }

    /// Declares the uses the next commands make of `buffer`, with a barrier from the uses it was last declared for
    /// (gpu/state.rs). Fills and copies declare their own; a dispatch that writes a buffer needs its
    /// [`Access::ComputeWrite`] declared before it. No barrier follows a fresh buffer (nothing to wait for) or the
    /// same uses declared again: commands of one use in a row run without barriers between them, so writes in a row
    /// must touch separate ranges (copies into a readback at their offsets).
    pub fn use_buffer(&mut self, buffer: &Buffer, uses: &[Access]) {
        let before = buffer.state.replace(uses);
        if before == [Access::Nothing] || before == uses {
            return;
        }
        let barrier = [access::buffer_barrier(buffer.raw, &before, uses)];
        self.pipeline_barrier(&vk::DependencyInfo::default().buffer_memory_barriers(&barrier));
    }

    /// Makes each of `images` ready for `uses`, after the uses it was last recorded for (gpu/state.rs), keeping
    /// its contents.
    pub fn use_images(&mut self, images: &[&Image], uses: &[Access]) {
        self.transition_images(images, uses, false);
    }

    /// Declares one pass's uses: `read` of each of `reads`, `write` of each of `writes`, and both of an image in
    /// both lists (an array image whose layers the pass reads in part and writes in part, as a refinement level
    /// reads parents and writes children in one array), each image once and in one barrier.
    pub fn use_images_reading_writing(
        &mut self,
        (reads, read): (&[&Image], Access),
        (writes, write): (&[&Image], Access),
    ) {
        let mut declared: Vec<(&Image, Vec<Access>)> = Vec::new();
        let all = reads
            .iter()
            .map(|i| (*i, read))
            .chain(writes.iter().map(|i| (*i, write)));
        for (image, access) in all {
            match declared.iter_mut().find(|(i, _)| i.raw == image.raw) {
                Some((_, uses)) if !uses.contains(&access) => uses.push(access),
                Some(_) => {}
                None => declared.push((image, vec![access])),
            }
        }
        self.declare(declared.iter().map(|(i, uses)| (*i, &uses[..])), false);
    }

    /// Makes each of `images` ready for `uses`, discarding its contents: an image about to be written whole.
    pub fn overwrite_images(&mut self, images: &[&Image], uses: &[Access]) {
        self.transition_images(images, uses, true);
    }

    fn transition_images(&mut self, images: &[&Image], uses: &[Access], discard: bool) {
        self.declare(images.iter().map(|i| (*i, uses)), discard);
    }

    /// One barrier for each image's transition to its uses.
    fn declare<'i>(
        &mut self,
        declared: impl Iterator<Item = (&'i Image, &'i [Access])>,
        discard: bool,
    ) {
        let barriers: Vec<_> = declared
            .filter_map(|(image, uses)| {
                transition(
                    image.raw,
                    image.range(),
                    image.shader_visible(),
                    &image.state,
                    uses,
                    discard,
                )
            })
            .collect();
        if !barriers.is_empty() {
            self.pipeline_barrier(&vk::DependencyInfo::default().image_memory_barriers(&barriers));
        }
    }

    /// Makes `which` attachment of `target` (whose colour image may be a swapchain's, not one of our [`Image`]s)
    /// ready for `uses`, after the uses it was last recorded for; `discard`: its contents are not kept (it is
    /// about to be cleared).
    pub fn use_attachment(
        &mut self,
        target: &RenderTarget,
        which: Attachment,
        uses: &[Access],
        discard: bool,
    ) {
        let (image, aspect, state) = match which {
            Attachment::Color => (
                target.color_image,
                vk::ImageAspectFlags::COLOR,
                &target.color_state,
            ),
            Attachment::Depth => (
                target.depth_image,
                vk::ImageAspectFlags::DEPTH,
                &target.depth_state,
            ),
        };
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(aspect)
            .level_count(1)
            .layer_count(1);
        if let Some(barrier) = transition(image, range, false, state, uses, discard) {
            self.pipeline_barrier(&vk::DependencyInfo::default().image_memory_barriers(&[barrier]));
        }
    }

    fn pipeline_barrier(&mut self, dependency: &vk::DependencyInfo) {
        // SAFETY: recording; the barriers name live resources.
        unsafe { self.ctx.device.cmd_pipeline_barrier2(self.cmd, dependency) };
    }

    /// Binds `pipeline` with `sets` (from set 0) and `push` constants, and dispatches `groups` workgroups.
    pub fn dispatch(
        &mut self,
        pipeline: &ComputePipeline,
        sets: &[vk::DescriptorSet],
        push: &[u8],
        groups: [u32; 3],
    ) {
        self.bind(
            vk::PipelineBindPoint::COMPUTE,
            (pipeline.pipeline, pipeline.layout),
            sets,
            (vk::ShaderStageFlags::COMPUTE, push),
        );
        // SAFETY: recording; the pipeline is bound.
        unsafe {
            self.ctx()
                .device
                .cmd_dispatch(self.cmd, groups[0], groups[1], groups[2])
        };
    }

    /// Binds a pipeline, its descriptor sets (from set 0) and its push constants for `stages`; empty sets or
    /// constants are skipped.
    fn bind(
        &mut self,
        point: vk::PipelineBindPoint,
        (pipeline, layout): (vk::Pipeline, vk::PipelineLayout),
        sets: &[vk::DescriptorSet],
        (stages, push): (vk::ShaderStageFlags, &[u8]),
    ) {
        let device = &self.ctx().device;
        // SAFETY: recording; sets and constants match the layout (validated by the layer).
        unsafe {
            device.cmd_bind_pipeline(self.cmd, point, pipeline);
            if !sets.is_empty() {
                device.cmd_bind_descriptor_sets(self.cmd, point, layout, 0, sets, &[]);
            }
            if !push.is_empty() {
                device.cmd_push_constants(self.cmd, layout, stages, 0, push);
            }
        }
    }

    /// Begins dynamic rendering into `target` (colour in COLOR_ATTACHMENT_OPTIMAL, depth in
    /// DEPTH_ATTACHMENT_OPTIMAL), clearing both when `clear` (depth to 0: reversed Z), and sets viewport and scissor.
    pub fn begin_rendering(&mut self, target: &RenderTarget, clear: bool) {
        let extent = target.extent;
        let load = if clear {
            vk::AttachmentLoadOp::CLEAR
        } else {
            vk::AttachmentLoadOp::LOAD
        };
        let color = [vk::RenderingAttachmentInfo::default()
            .image_view(target.color_view)
            .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                color: vk::ClearColorValue {
                    float32: target.clear_color,
                },
            })];
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(target.depth_view)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(load)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 0.0,
                    stencil: 0,
                },
            });
        let info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent,
            })
            .layer_count(1)
            .color_attachments(&color)
            .depth_attachment(&depth);
        let device = &self.ctx().device;
        // SAFETY: recording; attachments are in the stated layouts (caller's contract).
        unsafe {
            device.cmd_begin_rendering(self.cmd, &info);
            device.cmd_set_viewport(
                self.cmd,
                0,
                &[vk::Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: extent.width as f32,
                    height: extent.height as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }],
            );
            device.cmd_set_scissor(
                self.cmd,
                0,
                &[vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent,
                }],
            );
        }
    }

    /// Ends the dynamic rendering `begin_rendering` opened.
    pub fn end_rendering(&mut self) {
        // SAFETY: paired with begin_rendering.
        unsafe { self.ctx().device.cmd_end_rendering(self.cmd) };
    }

    /// Draws the instances `instances` of the indexed mesh range `range` of `indices` (u32) with `pipeline`.
    pub fn draw_indexed(
        &mut self,
        pipeline: &GraphicsPipeline,
        sets: &[vk::DescriptorSet],
        push: &[u8],
        indices: &super::Buffer,
        range: std::ops::Range<u32>,
        instances: std::ops::Range<u32>,
    ) {
        if range.is_empty() || instances.is_empty() {
            return;
        }
        self.bind_draw(pipeline, (sets, push), indices);
        let device = &self.ctx().device;
        // SAFETY: recording inside a rendering scope; the pipeline is bound.
        unsafe {
            device.cmd_draw_indexed(
                self.cmd,
                range.end - range.start,
                instances.end - instances.start,
                range.start,
                0,
                instances.start,
            );
        }
    }

    /// Draws `count` indexed draws whose parameters the GPU wrote into `commands` (`VkDrawIndexedIndirectCommand`s
    /// from offset 0), with `pipeline`, `sets` and `push` as [`Recorder::draw_indexed`].
    pub fn draw_indexed_indirect(
        &mut self,
        pipeline: &GraphicsPipeline,
        (sets, push): (&[vk::DescriptorSet], &[u8]),
        indices: &super::Buffer,
        commands: &super::Buffer,
        count: u32,
    ) {
        if count == 0 {
            return;
        }
        self.bind_draw(pipeline, (sets, push), indices);
        let device = &self.ctx().device;
        // SAFETY: recording inside a rendering scope; the pipeline is bound; multiDrawIndirect is enabled.
        unsafe {
            device.cmd_draw_indexed_indirect(
                self.cmd,
                commands.raw,
                0,
                count,
                std::mem::size_of::<vk::DrawIndexedIndirectCommand>() as u32,
            );
        }
    }

    /// Binds a graphics pipeline with its sets and push constants (for every stage that may read them), and the
    /// u32 index buffer `indices`.
    fn bind_draw(
        &mut self,
        pipeline: &GraphicsPipeline,
        (sets, push): (&[vk::DescriptorSet], &[u8]),
        indices: &super::Buffer,
    ) {
        let stages = vk::ShaderStageFlags::VERTEX
            | vk::ShaderStageFlags::GEOMETRY
            | vk::ShaderStageFlags::FRAGMENT;
        self.bind(
            vk::PipelineBindPoint::GRAPHICS,
            (pipeline.pipeline, pipeline.layout),
            sets,
            (stages, push),
        );
        // SAFETY: recording; the buffer holds u32 indices.
        unsafe {
            self.ctx()
                .device
                .cmd_bind_index_buffer(self.cmd, indices.raw, 0, vk::IndexType::UINT32)
        };
    }
}

/// A copy between layers `first..first + count` of `image` (whole, colour) and tightly packed texels at `offset`.
fn whole_layers(image: &Image, first: u32, count: u32, offset: u64) -> vk::BufferImageCopy {
    vk::BufferImageCopy::default()
        .buffer_offset(offset)
        .image_subresource(
            vk::ImageSubresourceLayers::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .base_array_layer(first)
                .layer_count(count),
        )
        .image_extent(vk::Extent3D {
            width: image.extent.width,
            height: image.extent.height,
            depth: 1,
        })
}

/// The barrier of `image` from the uses `state` last recorded to `uses`, which it records. Reads after reads in
/// one layout join the reads recorded, as a render graph's read-only uses combine: no barrier where they were
/// recorded already, else one that makes the last write visible to the new reads too (the barrier before the
/// first reads made it available; this one chains after them).
fn transition(
    image: vk::Image,
    range: vk::ImageSubresourceRange,
    shader_visible: bool,
    state: &UseState,
    uses: &[Access],
    discard: bool,
) -> Option<vk::ImageMemoryBarrier2<'static>> {
    let recorded = state.get();
    let layout = |accesses: &[Access]| accesses.first().map(|a| a.layout(shader_visible));
    let same_layout = layout(&recorded) == layout(uses);
    if !discard && same_layout && access::reads_only(&recorded) && access::reads_only(uses) {
        let new: Vec<Access> = uses
            .iter()
            .copied()
            .filter(|a| !recorded.contains(a))
            .collect();
        if new.is_empty() {
            return None;
        }
        let joined: Vec<Access> = recorded.iter().chain(&new).copied().collect();
        state.replace(&joined);
        return Some(access::image_barrier(
            image,
            range,
            shader_visible,
            &ImageUse {
                before: &recorded,
                after: &new,
                discard,
            },
        ));
    }
    let before = state.replace(uses);
    Some(access::image_barrier(
        image,
        range,
        shader_visible,
        &ImageUse {
            before: &before,
            after: uses,
            discard,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads after reads join the reads recorded: a barrier only for a read not recorded yet (which must see the
    /// last write), none for one recorded; the next write waits for every read joined.
    #[test]
    fn reads_join_and_the_next_write_waits_for_all_of_them() {
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(1)
            .layer_count(1);
        let state = UseState::fresh();
        let next = |uses: &[Access], discard: bool| {
            transition(vk::Image::null(), range, true, &state, uses, discard)
        };
        assert!(next(&[Access::ComputeWrite], true).is_some());
        let drawn = [Access::GraphicsSampled, Access::ComputeSampled];
        let to_draw = next(&drawn, false).expect("the write is made visible");
        assert_eq!(
            to_draw.src_access_mask,
            vk::AccessFlags2::SHADER_STORAGE_WRITE
        );
        let loaded = next(&[Access::ComputeRead], false).expect("a new kind of read");
        assert_eq!(loaded.src_access_mask, vk::AccessFlags2::NONE);
        assert_eq!(
            loaded.dst_access_mask,
            vk::AccessFlags2::SHADER_STORAGE_READ
        );
        assert!(next(&[Access::ComputeSampled], false).is_none());
        assert_eq!(
            state.get(),
            vec![
                Access::GraphicsSampled,
                Access::ComputeSampled,
                Access::ComputeRead
            ]
        );
        let rewrite = next(&[Access::ComputeWrite], false).expect("a write after reads");
        assert!(rewrite.src_stage_mask.contains(
            vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COMPUTE_SHADER
        ));
    }
}
