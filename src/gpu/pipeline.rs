//! Shader modules, compute pipelines and small descriptor sets of storage buffers.

use ash::vk;

use super::{Context, GpuError, Recorder, VkResultExt};

/// Creates a shader module from SPIR-V bytes produced by build.rs.
pub fn shader_module(
    ctx: &Context,
    spirv: &[u8],
    name: &str,
) -> Result<vk::ShaderModule, GpuError> {
    let words = ash::util::read_spv(&mut std::io::Cursor::new(spirv))
        .map_err(|e| GpuError::Invalid(format!("SPIR-V of {name} is malformed: {e}")))?;
    let info = vk::ShaderModuleCreateInfo::default().code(&words);
    // SAFETY: the words are valid SPIR-V from shaderc (validated by the layer when enabled).
    let module =
        unsafe { ctx.device.create_shader_module(&info, None) }.vk("vkCreateShaderModule")?;
    ctx.set_name(module, name);
    Ok(module)
}

/// A descriptor set layout of `count` storage buffers at bindings 0..count, for per-dispatch inputs (samples,
/// range table). Sets are allocated per recording with [`Recorder::buffer_set`].
pub struct BufferSetLayout {
    pub layout: vk::DescriptorSetLayout,
    pub count: u32,
}

impl BufferSetLayout {
    pub fn new(ctx: &Context, count: u32, name: &str) -> Result<Self, GpuError> {
        let bindings: Vec<_> = (0..count)
            .map(|b| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::ALL)
            })
            .collect();
        let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings);
        // SAFETY: valid create info.
        let layout = unsafe { ctx.device.create_descriptor_set_layout(&info, None) }
            .vk("vkCreateDescriptorSetLayout")?;
        ctx.set_name(layout, name);
        Ok(Self { layout, count })
    }

    pub fn destroy(self, ctx: &Context) {
        // SAFETY: called after all work using the layout completed.
        unsafe { ctx.device.destroy_descriptor_set_layout(self.layout, None) };
    }
}

/// A compute pipeline and its layout.
pub struct ComputePipeline {
    pub pipeline: vk::Pipeline,
    pub layout: vk::PipelineLayout,
}

impl ComputePipeline {
    /// Builds a pipeline from SPIR-V with the given set layouts, push-constant size, and `u32` specialization
    /// constants (constant_id 0, 1, ...).
    pub fn new(
        ctx: &Context,
        spirv: &[u8],
        name: &str,
        set_layouts: &[vk::DescriptorSetLayout],
        push_constant_bytes: u32,
        specialization: &[u32],
    ) -> Result<Self, GpuError> {
        let module = shader_module(ctx, spirv, name)?;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .size(push_constant_bytes)];
        let layout_info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(set_layouts)
            .push_constant_ranges(if push_constant_bytes > 0 {
                &ranges
            } else {
                &[]
            });
        // SAFETY: valid create info.
        let layout = unsafe { ctx.device.create_pipeline_layout(&layout_info, None) };
        let layout = match layout.vk("vkCreatePipelineLayout") {
            Ok(l) => l,
            Err(e) => {
                unsafe { ctx.device.destroy_shader_module(module, None) };
                return Err(e);
            }
        };
        let entries: Vec<_> = (0..specialization.len() as u32)
            .map(|i| vk::SpecializationMapEntry {
                constant_id: i,
                offset: i * 4,
                size: 4,
            })
            .collect();
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(bytemuck::cast_slice(specialization));
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout)];
        let result = unsafe {
            ctx.device
                .create_compute_pipelines(vk::PipelineCache::null(), &info, None)
        };
        unsafe { ctx.device.destroy_shader_module(module, None) };
        let pipeline = match result {
            Ok(p) => p[0],
            Err((_, e)) => {
                unsafe { ctx.device.destroy_pipeline_layout(layout, None) };
                return Err(GpuError::Vk {
                    call: "vkCreateComputePipelines",
                    result: e,
                });
            }
        };
        ctx.set_name(pipeline, name);
        Ok(Self { pipeline, layout })
    }

    pub fn destroy(self, ctx: &Context) {
        // SAFETY: called after all work using the pipeline completed.
        unsafe {
            ctx.device.destroy_pipeline(self.pipeline, None);
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

impl Recorder<'_> {
    /// Binds `pipeline` with `sets` (from set 0) and `push` constants, and dispatches `groups` workgroups.
    pub fn dispatch(
        &mut self,
        pipeline: &ComputePipeline,
        sets: &[vk::DescriptorSet],
        push: &[u8],
        groups: [u32; 3],
    ) {
        let device = &self.ctx().device;
        // SAFETY: recording; sets match the pipeline layout (validated by the layer).
        unsafe {
            device.cmd_bind_pipeline(self.cmd, vk::PipelineBindPoint::COMPUTE, pipeline.pipeline);
            if !sets.is_empty() {
                device.cmd_bind_descriptor_sets(
                    self.cmd,
                    vk::PipelineBindPoint::COMPUTE,
                    pipeline.layout,
                    0,
                    sets,
                    &[],
                );
            }
            if !push.is_empty() {
                device.cmd_push_constants(
                    self.cmd,
                    pipeline.layout,
                    vk::ShaderStageFlags::COMPUTE,
                    0,
                    push,
                );
            }
            device.cmd_dispatch(self.cmd, groups[0], groups[1], groups[2]);
        }
    }
}
