//! Compute and graphics pipelines whose layouts come from build-time reflection: descriptor set
//! layouts, push-constant ranges and workgroup sizes are never written by hand.

use crate::device::Device;
use crate::error::{Error, Result, VkContext};
use crate::retire::Garbage;
use crate::shader::{BindingDesc, ShaderDesc, ShaderStage};
use ash::vk;

/// A binding of a pipeline, merged over its stages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LayoutBinding {
    /// The reflected binding.
    pub desc: BindingDesc,
    /// Every stage that declares it.
    pub stages: vk::ShaderStageFlags,
}

/// The reflected layout shared by every pipeline kind. Destroyed (deferred) when dropped.
pub struct PipelineLayout {
    device: Device,
    /// Name for messages (the shader names).
    pub name: String,
    /// Vulkan pipeline layout.
    pub raw: vk::PipelineLayout,
    /// One set layout per set index 0..=max set.
    pub set_layouts: Vec<vk::DescriptorSetLayout>,
    /// Bindings merged over stages, sorted by (set, binding).
    pub bindings: Vec<LayoutBinding>,
    /// Push-constant bytes (0 when none) and the stages that read them.
    pub push_constants: (u32, vk::ShaderStageFlags),
}

impl PipelineLayout {
    fn new(device: &Device, shaders: &[&ShaderDesc]) -> Result<Self> {
        let name = shaders.iter().map(|s| s.name).collect::<Vec<_>>().join("+");
        let mut bindings: Vec<LayoutBinding> = Vec::new();
        let mut push_size = 0;
        let mut push_stages = vk::ShaderStageFlags::empty();
        for shader in shaders {
            let stage = shader.stage.flags();
            for b in shader.bindings {
                match bindings
                    .iter_mut()
                    .find(|x| x.desc.set == b.set && x.desc.binding == b.binding)
                {
                    Some(existing)
                        if existing.desc.kind.vk() == b.kind.vk()
                            && existing.desc.count == b.count =>
                    {
                        existing.stages |= stage;
                    }
                    Some(existing) => {
                        return Err(Error::Binding {
                            pipeline: name,
                            message: format!(
                                "set {} binding {} is `{}` ({:?}) in one stage and `{}` ({:?}) in another",
                                b.set,
                                b.binding,
                                existing.desc.name,
                                existing.desc.kind,
                                b.name,
                                b.kind
                            ),
                        });
                    }
                    None => bindings.push(LayoutBinding {
                        desc: *b,
                        stages: stage,
                    }),
                }
            }
            if shader.push_constant_size > 0 {
                push_size = push_size.max(shader.push_constant_size);
                push_stages |= stage;
            }
        }
        bindings.sort_by_key(|b| (b.desc.set, b.desc.binding));
        let max_push = device.limits().max_push_constants_size;
        if push_size > max_push {
            return Err(Error::Binding {
                pipeline: name,
                message: format!(
                    "push constants of {push_size} bytes exceed the device limit of {max_push}"
                ),
            });
        }

        let set_count = bindings.last().map_or(0, |b| b.desc.set + 1);
        // Built empty first so that Drop cleans up whatever an error leaves behind.
        let mut layout = Self {
            device: device.clone(),
            name,
            raw: vk::PipelineLayout::null(),
            set_layouts: Vec::with_capacity(set_count as usize),
            bindings,
            push_constants: (push_size, push_stages),
        };
        let raw_device = device.raw();
        for set in 0..set_count {
            let vk_bindings: Vec<_> = layout
                .bindings
                .iter()
                .filter(|b| b.desc.set == set)
                .map(|b| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.desc.binding)
                        .descriptor_type(b.desc.kind.vk())
                        .descriptor_count(b.desc.count)
                        .stage_flags(b.stages)
                })
                .collect();
            let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(&vk_bindings);
            // SAFETY: valid create info on a live device.
            let set_layout = unsafe { raw_device.create_descriptor_set_layout(&info, None) }
                .ctx(&format!("creating set layouts of `{}`", layout.name))?;
            layout.set_layouts.push(set_layout);
        }
        let ranges = [vk::PushConstantRange {
            stage_flags: push_stages,
            offset: 0,
            size: push_size,
        }];
        let info = vk::PipelineLayoutCreateInfo::default()
            .set_layouts(&layout.set_layouts)
            .push_constant_ranges(if push_size > 0 { &ranges } else { &[] });
        // SAFETY: valid create info on a live device.
        layout.raw = unsafe { raw_device.create_pipeline_layout(&info, None) }
            .ctx(&format!("creating the layout of `{}`", layout.name))?;
        Ok(layout)
    }
}

impl Drop for PipelineLayout {
    fn drop(&mut self) {
        self.device.defer(Garbage::PipelineLayout(
            self.raw,
            std::mem::take(&mut self.set_layouts),
        ));
    }
}

/// Creates a shader module for the duration of pipeline creation.
struct Module<'a> {
    device: &'a ash::Device,
    raw: vk::ShaderModule,
}

impl<'a> Module<'a> {
    fn new(device: &'a ash::Device, shader: &ShaderDesc) -> Result<Self> {
        let info = vk::ShaderModuleCreateInfo::default().code(shader.spirv);
        // SAFETY: SPIR-V validated by naga at build time.
        let raw = unsafe { device.create_shader_module(&info, None) }
            .ctx(&format!("creating shader module `{}`", shader.name))?;
        Ok(Self { device, raw })
    }
}

impl Drop for Module<'_> {
    fn drop(&mut self) {
        // SAFETY: modules may be destroyed once pipelines using them exist.
        unsafe { self.device.destroy_shader_module(self.raw, None) };
    }
}

/// A compute pipeline built from one reflected shader.
pub struct ComputePipeline {
    device: Device,
    shader: &'static ShaderDesc,
    layout: PipelineLayout,
    raw: vk::Pipeline,
}

impl ComputePipeline {
    /// Builds the pipeline and its layout from the shader's reflection.
    pub fn new(device: &Device, shader: &'static ShaderDesc) -> Result<Self> {
        if shader.stage != ShaderStage::Compute {
            return Err(Error::InvalidUsage(format!(
                "`{}` is a {:?} shader, not a compute shader",
                shader.name, shader.stage
            )));
        }
        let layout = PipelineLayout::new(device, &[shader])?;
        let module = Module::new(device.raw(), shader)?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module.raw)
            .name(shader.entry);
        let info = [vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout.raw)];
        // SAFETY: valid create info on a live device.
        let result = unsafe {
            device
                .raw()
                .create_compute_pipelines(device.pipeline_cache(), &info, None)
        };
        let raw = match result {
            Ok(p) => p.first().copied().unwrap_or_default(),
            Err((_, e)) => {
                return Err(Error::vk(
                    format!("creating compute pipeline `{}`", shader.name),
                    e,
                ));
            }
        };
        device.set_name(raw, shader.name);
        Ok(Self {
            device: device.clone(),
            shader,
            layout,
            raw,
        })
    }

    /// The Vulkan pipeline.
    pub fn raw(&self) -> vk::Pipeline {
        self.raw
    }

    /// The reflected layout.
    pub fn layout(&self) -> &PipelineLayout {
        &self.layout
    }

    /// The shader it runs.
    pub fn shader(&self) -> &'static ShaderDesc {
        self.shader
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        self.device.defer(Garbage::Pipeline(self.raw));
    }
}

/// Blending of one colour target.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Blend {
    /// Overwrite.
    Replace,
    /// dst + src on colour and alpha: accumulation by splatting (paper 002).
    Additive,
    /// Premultiplied-alpha over.
    PremultipliedAlpha,
}

impl Blend {
    fn state(self) -> vk::PipelineColorBlendAttachmentState {
        let base = vk::PipelineColorBlendAttachmentState::default()
            .color_write_mask(vk::ColorComponentFlags::RGBA);
        match self {
            Self::Replace => base,
            Self::Additive => base
                .blend_enable(true)
                .src_color_blend_factor(vk::BlendFactor::ONE)
                .dst_color_blend_factor(vk::BlendFactor::ONE)
                .color_blend_op(vk::BlendOp::ADD)
                .src_alpha_blend_factor(vk::BlendFactor::ONE)
                .dst_alpha_blend_factor(vk::BlendFactor::ONE)
                .alpha_blend_op(vk::BlendOp::ADD),
            Self::PremultipliedAlpha => base
                .blend_enable(true)
                .src_color_blend_factor(vk::BlendFactor::ONE)
                .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
                .color_blend_op(vk::BlendOp::ADD)
                .src_alpha_blend_factor(vk::BlendFactor::ONE)
                .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
                .alpha_blend_op(vk::BlendOp::ADD),
        }
    }
}

/// One vertex buffer binding: stride and, per shader location, the byte offset.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct VertexBufferLayout {
    /// Bytes between consecutive vertices (or instances).
    pub stride: u32,
    /// Per-instance instead of per-vertex.
    pub per_instance: bool,
    /// `(location, offset)` pairs; formats come from the shader's reflection.
    pub attributes: Vec<(u32, u32)>,
}

/// Depth test and write state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct DepthState {
    /// Depth attachment format.
    pub format: vk::Format,
    /// Compare op (the test is enabled unless `ALWAYS` with no write).
    pub compare: vk::CompareOp,
    /// Whether depth is written.
    pub write: bool,
}

/// Everything a graphics pipeline needs beyond its shaders' reflection.
#[derive(Clone, Debug)]
pub struct GraphicsPipelineDesc {
    /// Vertex shader.
    pub vertex: &'static ShaderDesc,
    /// Fragment shader (none for depth-only passes).
    pub fragment: Option<&'static ShaderDesc>,
    /// Vertex buffer bindings, in binding order.
    pub vertex_buffers: Vec<VertexBufferLayout>,
    /// Primitive topology.
    pub topology: vk::PrimitiveTopology,
    /// Face culling.
    pub cull_mode: vk::CullModeFlags,
    /// Colour attachment formats and blending, in attachment order.
    pub color_targets: Vec<(vk::Format, Blend)>,
    /// Depth attachment, if any.
    pub depth: Option<DepthState>,
    /// Constant and slope depth bias (shadow maps), if any.
    pub depth_bias: Option<(f32, f32)>,
}

/// A graphics pipeline for dynamic rendering; viewport and scissor are dynamic.
pub struct GraphicsPipeline {
    device: Device,
    layout: PipelineLayout,
    raw: vk::Pipeline,
}

impl GraphicsPipeline {
    /// Builds the pipeline; vertex attribute formats come from the vertex shader's reflection.
    pub fn new(device: &Device, desc: &GraphicsPipelineDesc) -> Result<Self> {
        let mut shaders = vec![desc.vertex];
        shaders.extend(desc.fragment);
        let name = shaders.iter().map(|s| s.name).collect::<Vec<_>>().join("+");
        if desc.vertex.stage != ShaderStage::Vertex
            || desc
                .fragment
                .is_some_and(|f| f.stage != ShaderStage::Fragment)
        {
            return Err(Error::InvalidUsage(format!(
                "`{name}`: expected a vertex shader and a fragment shader"
            )));
        }

        let mut attributes = Vec::new();
        let mut buffers = Vec::new();
        for (binding, layout) in desc.vertex_buffers.iter().enumerate() {
            buffers.push(vk::VertexInputBindingDescription {
                binding: binding as u32,
                stride: layout.stride,
                input_rate: if layout.per_instance {
                    vk::VertexInputRate::INSTANCE
                } else {
                    vk::VertexInputRate::VERTEX
                },
            });
            for &(location, offset) in &layout.attributes {
                let input = desc
                    .vertex
                    .vertex_inputs
                    .iter()
                    .find(|i| i.location == location)
                    .ok_or_else(|| Error::Binding {
                        pipeline: name.clone(),
                        message: format!("the vertex shader has no input at location {location}"),
                    })?;
                attributes.push(vk::VertexInputAttributeDescription {
                    location,
                    binding: binding as u32,
                    format: input.format,
                    offset,
                });
            }
        }
        if let Some(missing) = desc
            .vertex
            .vertex_inputs
            .iter()
            .find(|i| !attributes.iter().any(|a| a.location == i.location))
        {
            return Err(Error::Binding {
                pipeline: name,
                message: format!(
                    "vertex input at location {} has no vertex buffer attribute",
                    missing.location
                ),
            });
        }

        let layout = PipelineLayout::new(device, &shaders)?;
        let vertex_module = Module::new(device.raw(), desc.vertex)?;
        let fragment_module = desc
            .fragment
            .map(|f| Module::new(device.raw(), f))
            .transpose()?;
        let mut stages = vec![
            vk::PipelineShaderStageCreateInfo::default()
                .stage(vk::ShaderStageFlags::VERTEX)
                .module(vertex_module.raw)
                .name(desc.vertex.entry),
        ];
        if let (Some(module), Some(shader)) = (&fragment_module, desc.fragment) {
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(module.raw)
                    .name(shader.entry),
            );
        }
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&buffers)
            .vertex_attribute_descriptions(&attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default().topology(desc.topology);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let mut raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(desc.cull_mode)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .line_width(1.0);
        if let Some((constant, slope)) = desc.depth_bias {
            raster = raster
                .depth_bias_enable(true)
                .depth_bias_constant_factor(constant)
                .depth_bias_slope_factor(slope);
        }
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::TYPE_1);
        let depth_stencil = match desc.depth {
            Some(d) => vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(d.write)
                .depth_compare_op(d.compare),
            None => vk::PipelineDepthStencilStateCreateInfo::default(),
        };
        let blends: Vec<_> = desc.color_targets.iter().map(|(_, b)| b.state()).collect();
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blends);
        let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let color_formats: Vec<_> = desc.color_targets.iter().map(|(f, _)| *f).collect();
        let mut rendering = vk::PipelineRenderingCreateInfo::default()
            .color_attachment_formats(&color_formats)
            .depth_attachment_format(desc.depth.map_or(vk::Format::UNDEFINED, |d| d.format));
        let info = [vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth_stencil)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout.raw)
            .push_next(&mut rendering)];
        // SAFETY: valid create info on a live device; every pointer outlives the call.
        let result = unsafe {
            device
                .raw()
                .create_graphics_pipelines(device.pipeline_cache(), &info, None)
        };
        let raw = match result {
            Ok(p) => p.first().copied().unwrap_or_default(),
            Err((_, e)) => {
                return Err(Error::vk(format!("creating graphics pipeline `{name}`"), e));
            }
        };
        device.set_name(raw, &name);
        Ok(Self {
            device: device.clone(),
            layout,
            raw,
        })
    }

    /// The Vulkan pipeline.
    pub fn raw(&self) -> vk::Pipeline {
        self.raw
    }

    /// The reflected layout.
    pub fn layout(&self) -> &PipelineLayout {
        &self.layout
    }
}

impl Drop for GraphicsPipeline {
    fn drop(&mut self) {
        self.device.defer(Garbage::Pipeline(self.raw));
    }
}
