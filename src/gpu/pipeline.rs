//! Shader modules, compute pipelines and small descriptor sets of storage buffers.

use std::sync::Arc;

use ash::vk;

use super::{
    retire::{RetireOnDrop, Retired},
    state::UseState,
    Context, GpuError, Image, VkResultExt,
};

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

/// Map entries for the consecutive `u32` specialization constants in `data` (constant_id 0, 1, ...).
fn specialization_entries(data: &[u8]) -> Vec<vk::SpecializationMapEntry> {
    debug_assert!(data.len() % 4 == 0, "specialization constants are u32s");
    (0..(data.len() / 4) as u32)
        .map(|i| vk::SpecializationMapEntry {
            constant_id: i,
            offset: i * 4,
            size: 4,
        })
        .collect()
}

/// A descriptor set layout of `count` storage buffers at bindings 0..count, for per-dispatch inputs (samples,
/// range table). Sets are allocated per recording with [`super::Recorder::buffer_set`].
pub struct BufferSetLayout {
    /// The Vulkan layout.
    pub layout: vk::DescriptorSetLayout,
    /// Storage buffers it binds.
    pub count: u32,
    _retire: RetireOnDrop,
}

impl BufferSetLayout {
    /// A layout of `count` storage buffers, named `name` for debuggers.
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
        Ok(Self {
            layout,
            count,
            _retire: ctx.retire_on_drop(vec![Retired::SetLayout(layout)]),
        })
    }
}

/// A compute pipeline and its layout, retired when dropped.
pub struct ComputePipeline {
    pub(super) pipeline: vk::Pipeline,
    pub(super) layout: vk::PipelineLayout,
    _retire: RetireOnDrop,
}

/// What a compute pipeline needs, as [`GraphicsDesc`] says it for graphics.
pub struct ComputeDesc<'a> {
    /// Its debug name.
    pub name: &'a str,
    /// The compute shader's SPIR-V.
    pub spirv: &'a [u8],
    /// Its descriptor set layouts, set 0 first.
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    /// Bytes of push constants (0: none).
    pub push_constant_bytes: u32,
    /// The shader's specialization constants: the bytes (`bytemuck::bytes_of`) of a `#[repr(C)]` Pod struct or
    /// array of `u32`s, field k being `constant_id` k; empty for none.
    pub specialization: &'a [u8],
    /// For a shader that relies on full subgroups of exactly this many invocations (Vulkan 1.3
    /// computeFullSubgroups and a required subgroup size; the workgroup size must be a multiple of it).
    pub full_subgroups: Option<u32>,
}

impl ComputePipeline {
    /// Builds the pipeline `desc` says.
    pub fn new(ctx: &Context, desc: &ComputeDesc) -> Result<Self, GpuError> {
        let ComputeDesc {
            name,
            spirv,
            set_layouts,
            push_constant_bytes,
            specialization,
            full_subgroups: subgroup_size,
        } = *desc;
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
        let entries = specialization_entries(specialization);
        let spec = vk::SpecializationInfo::default()
            .map_entries(&entries)
            .data(specialization);
        let mut required = vk::PipelineShaderStageRequiredSubgroupSizeCreateInfo::default()
            .required_subgroup_size(subgroup_size.unwrap_or(0));
        let mut stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        if subgroup_size.is_some() {
            stage = stage
                .flags(vk::PipelineShaderStageCreateFlags::REQUIRE_FULL_SUBGROUPS)
                .push_next(&mut required);
        }
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
        Ok(Self {
            pipeline,
            layout,
            _retire: ctx.retire_on_drop(vec![Retired::Pipeline(pipeline, layout)]),
        })
    }
}

/// What a graphics pipeline of the terrain renderer needs: vertex, geometry and fragment shaders, dynamic
/// rendering into one colour and one depth attachment, and a few fixed-function choices.
pub struct GraphicsDesc<'a> {
    /// Its debug name.
    pub name: &'a str,
    /// The vertex shader's SPIR-V.
    pub vertex: &'a [u8],
    /// The geometry shader's SPIR-V, if there is one.
    pub geometry: Option<&'a [u8]>,
    /// The fragment shader's SPIR-V.
    pub fragment: &'a [u8],
    /// Its descriptor set layouts, set 0 first.
    pub set_layouts: &'a [vk::DescriptorSetLayout],
    /// Bytes of push constants, visible to every stage (0: none).
    pub push_constant_bytes: u32,
    /// Specialization constants given to every stage, as [`ComputeDesc::specialization`].
    pub specialization: &'a [u8],
    /// The colour attachment's format.
    pub color_format: vk::Format,
    /// The depth attachment's format.
    pub depth_format: vk::Format,
    /// Whether it writes depth.
    pub depth_write: bool,
    /// Depth test: GREATER (reversed Z).
    pub depth_test: bool,
    /// How its colour combines with the attachment's.
    pub blend: Blend,
    /// Draw triangles as lines.
    pub wireframe: bool,
    /// Cull triangles seen from behind (counter-clockwise in framebuffer coordinates is the front): for closed
    /// surfaces, whose back faces are always hidden.
    pub cull_back_faces: bool,
}

/// How a graphics pipeline's colour output combines with the attachment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Replace.
    None,
    /// `source x alpha + destination x (1 - alpha)`: translucent surfaces.
    Alpha,
    /// `source + destination x alpha`: light added in front of what shows through a medium that lets `alpha` of
    /// it through.
    Transmit,
}

/// A graphics pipeline and its layout, retired when dropped.
pub struct GraphicsPipeline {
    pub(super) pipeline: vk::Pipeline,
    pub(super) layout: vk::PipelineLayout,
    _retire: RetireOnDrop,
}

impl GraphicsPipeline {
    /// Builds the pipeline `desc` says.
    pub fn new(ctx: &Context, desc: &GraphicsDesc) -> Result<Self, GpuError> {
        let stages_all = vk::ShaderStageFlags::VERTEX
            | vk::ShaderStageFlags::GEOMETRY
            | vk::ShaderStageFlags::FRAGMENT;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(stages_all)
            .size(desc.push_constant_bytes)];
        let layout_info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(desc.set_layouts)
            .push_constant_ranges(if desc.push_constant_bytes > 0 {
                &ranges
            } else {
                &[]
            });
        // SAFETY: valid create info.
        let layout = unsafe { ctx.device.create_pipeline_layout(&layout_info, None) }
            .vk("vkCreatePipelineLayout")?;
        let mut modules = Vec::new();
        let mut make = |spirv: &[u8], stage: &str| -> Result<vk::ShaderModule, GpuError> {
            let m = shader_module(ctx, spirv, &format!("{} {stage}", desc.name))?;
            modules.push(m);
            Ok(m)
        };
        let result = (|| {
            let vertex = make(desc.vertex, "vertex")?;
            let geometry = desc.geometry.map(|g| make(g, "geometry")).transpose()?;
            let fragment = make(desc.fragment, "fragment")?;
            let entries = specialization_entries(desc.specialization);
            let spec = vk::SpecializationInfo::default()
                .map_entries(&entries)
                .data(desc.specialization);
            let stage = |s: vk::ShaderStageFlags, m: vk::ShaderModule| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(s)
                    .module(m)
                    .name(c"main")
                    .specialization_info(&spec)
            };
            let mut stages = vec![stage(vk::ShaderStageFlags::VERTEX, vertex)];
            if let Some(g) = geometry {
                stages.push(stage(vk::ShaderStageFlags::GEOMETRY, g));
            }
            stages.push(stage(vk::ShaderStageFlags::FRAGMENT, fragment));
            let vertex_input = vk::PipelineVertexInputStateCreateInfo::default();
            let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
                .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
            let viewport = vk::PipelineViewportStateCreateInfo::default()
                .viewport_count(1)
                .scissor_count(1);
            let raster = vk::PipelineRasterizationStateCreateInfo::default()
                .polygon_mode(if desc.wireframe {
                    vk::PolygonMode::LINE
                } else {
                    vk::PolygonMode::FILL
                })
                .cull_mode(if desc.cull_back_faces {
                    vk::CullModeFlags::BACK
                } else {
                    vk::CullModeFlags::NONE
                })
                .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
                .line_width(1.0);
            let multisample = vk::PipelineMultisampleStateCreateInfo::default()
                .rasterization_samples(vk::SampleCountFlags::TYPE_1);
            let depth = vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(desc.depth_test)
                .depth_write_enable(desc.depth_write)
                .depth_compare_op(vk::CompareOp::GREATER_OR_EQUAL);
            let blend_factors = |src, dst| {
                vk::PipelineColorBlendAttachmentState::default()
                    .blend_enable(true)
                    .src_color_blend_factor(src)
                    .dst_color_blend_factor(dst)
                    .color_blend_op(vk::BlendOp::ADD)
                    .src_alpha_blend_factor(vk::BlendFactor::ZERO)
                    .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                    .alpha_blend_op(vk::BlendOp::ADD)
                    .color_write_mask(vk::ColorComponentFlags::RGBA)
            };
            let blend_attachment = [match desc.blend {
                Blend::None => vk::PipelineColorBlendAttachmentState::default()
                    .color_write_mask(vk::ColorComponentFlags::RGBA),
                Blend::Alpha => blend_factors(
                    vk::BlendFactor::SRC_ALPHA,
                    vk::BlendFactor::ONE_MINUS_SRC_ALPHA,
                ),
                Blend::Transmit => blend_factors(vk::BlendFactor::ONE, vk::BlendFactor::SRC_ALPHA),
            }];
            let blend =
                vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend_attachment);
            let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
            let dynamic =
                vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
            let color_formats = [desc.color_format];
            let mut rendering = vk::PipelineRenderingCreateInfo::default()
                .color_attachment_formats(&color_formats)
                .depth_attachment_format(desc.depth_format);
            let info = [vk::GraphicsPipelineCreateInfo::default()
                .stages(&stages)
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&assembly)
                .viewport_state(&viewport)
                .rasterization_state(&raster)
                .multisample_state(&multisample)
                .depth_stencil_state(&depth)
                .color_blend_state(&blend)
                .dynamic_state(&dynamic)
                .layout(layout)
                .push_next(&mut rendering)];
            // SAFETY: every pointer in `info` lives until the call returns.
            unsafe {
                ctx.device
                    .create_graphics_pipelines(vk::PipelineCache::null(), &info, None)
            }
            .map(|p| p[0])
            .map_err(|(_, e)| GpuError::Vk {
                call: "vkCreateGraphicsPipelines",
                result: e,
            })
        })();
        for m in modules {
            // SAFETY: modules are not needed after pipeline creation.
            unsafe { ctx.device.destroy_shader_module(m, None) };
        }
        match result {
            Ok(pipeline) => {
                ctx.set_name(pipeline, desc.name);
                Ok(Self {
                    pipeline,
                    layout,
                    _retire: ctx.retire_on_drop(vec![Retired::Pipeline(pipeline, layout)]),
                })
            }
            Err(e) => {
                unsafe { ctx.device.destroy_pipeline_layout(layout, None) };
                Err(e)
            }
        }
    }
}

/// The attachments of one rendering pass: a colour image (one of our [`Image`]s, or a swapchain's image, which is
/// not) and a depth image, made by [`RenderTarget::new`] or [`super::swapchain::Swapchain::target`]; each
/// attachment shares its image's state (gpu/state.rs).
#[derive(Clone, Debug)]
pub struct RenderTarget {
    pub(super) color_image: vk::Image,
    pub(super) color_view: vk::ImageView,
    pub(super) color_state: Arc<UseState>,
    pub(super) depth_image: vk::Image,
    pub(super) depth_view: vk::ImageView,
    pub(super) depth_state: Arc<UseState>,
    pub(super) extent: vk::Extent2D,
    pub(super) clear_color: [f32; 4],
}

/// Which attachment of a [`RenderTarget`] a barrier is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Attachment {
    /// The colour image.
    Color,
    /// The depth image.
    Depth,
}

impl RenderTarget {
    /// Our `color` and `depth` images (of one size), the colour cleared to `clear_color`.
    pub fn new(color: &Image, depth: &Image, clear_color: [f32; 4]) -> Self {
        Self {
            color_image: color.raw,
            color_view: color.view,
            color_state: color.state.clone(),
            depth_image: depth.raw,
            depth_view: depth.view,
            depth_state: depth.state.clone(),
            extent: color.extent,
            clear_color,
        }
    }

    /// Its size in pixels.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }
}
