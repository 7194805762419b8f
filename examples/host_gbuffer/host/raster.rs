//! The host's G-buffer targets and raster pipeline (dynamic rendering), with its own direct
//! light.

use super::HostDevice;
use super::resources::{HostImage, range};
use super::scene::HostScene;
use glam::{Mat4, Vec3};
use shine::gpu::ash::vk;
use shine_scene::LightKind;
use std::error::Error;

/// How the host stores normals in its G-buffer (A2B10G10R10 UNORM: `n · 0.5 + 0.5`).
pub const NORMAL_FORMAT: vk::Format = vk::Format::A2B10G10R10_UNORM_PACK32;
/// The host's albedo: sRGB-encoded, decoded to linear by the sampler.
pub const ALBEDO_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;
/// r = perceptual roughness, g = metallic.
pub const MATERIAL_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// The host's direct light and shine's indirect light.
pub const RADIANCE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The host's G-buffer, direct-light and GI images, all of one size.
pub struct Targets {
    pub depth: HostImage,
    pub normal: HostImage,
    pub albedo: HostImage,
    pub material: HostImage,
    pub direct: HostImage,
    pub gi: HostImage,
}

impl Targets {
    /// The images for an `extent` frame.
    pub fn new(host: &HostDevice, extent: [u32; 2]) -> Result<Self, Box<dyn Error>> {
        use vk::ImageUsageFlags as U;
        let color = U::COLOR_ATTACHMENT | U::SAMPLED;
        Ok(Self {
            depth: HostImage::new(
                host,
                "host depth",
                vk::Format::D32_SFLOAT,
                extent,
                U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED,
            )?,
            normal: HostImage::new(host, "host normal", NORMAL_FORMAT, extent, color)?,
            albedo: HostImage::new(host, "host albedo", ALBEDO_FORMAT, extent, color)?,
            material: HostImage::new(host, "host material", MATERIAL_FORMAT, extent, color)?,
            direct: HostImage::new(
                host,
                "host direct",
                RADIANCE_FORMAT,
                extent,
                U::COLOR_ATTACHMENT | U::TRANSFER_SRC,
            )?,
            gi: HostImage::new(
                host,
                "host gi",
                RADIANCE_FORMAT,
                extent,
                // Sampled by a host's composite (and a view needs a usage that has views).
                U::TRANSFER_DST | U::TRANSFER_SRC | U::SAMPLED,
            )?,
        })
    }

    /// Destroys every image.
    /// The GI dispatch of the G-buffer rasterised into these targets from `camera`, as frame
    /// `frame_index`: each image in the state the raster left it, UNORM normals, glTF material
    /// channels, the indirect light into `gi` (left ready to copy from).
    pub fn dispatch(
        &self,
        frame_index: u64,
        camera: shine::embed::GiCamera,
    ) -> shine::embed::GiDispatch {
        let color = |i: &HostImage| i.lend(color_written(), sampled_after());
        shine::embed::GiDispatch {
            frame_index,
            camera,
            depth: self.depth.lend(depth_written(), sampled_after()),
            depth_convention: Default::default(),
            normals: color(&self.normal),
            normal_encoding: shine::embed::NormalEncoding::UNORM,
            albedo: color(&self.albedo),
            material: color(&self.material),
            material_channels: shine::embed::MaterialChannels::default(),
            motion: None,
            environment: None,
            diffuse: Some(
                self.gi
                    .lend(shine::embed::ExternalState::UNDEFINED, copy_source()),
            ),
            specular: None,
            debug: None,
            debug_view: shine::embed::DebugView::default(),
        }
    }

    pub fn destroy(self, host: &HostDevice) {
        for image in [
            self.depth,
            self.normal,
            self.albedo,
            self.material,
            self.direct,
            self.gi,
        ] {
            image.destroy(host);
        }
    }
}

/// The host's G-buffer pipeline.
pub struct Raster {
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
}

/// The host's push constants (128 bytes).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DrawConstants {
    view_proj: [[f32; 4]; 4],
    base_color_roughness: [f32; 4],
    light_position_metallic: [f32; 4],
    light_intensity: [f32; 4],
    light_direction_cos_outer: [f32; 4],
}

/// Compiles one of the host's GLSL shaders to SPIR-V with glslang.
fn compile(source: &str, stage: glslang::ShaderStage) -> Result<Vec<u32>, Box<dyn Error>> {
    let compiler = glslang::Compiler::acquire().ok_or("glslang unavailable")?;
    let source = glslang::ShaderSource::from(source.to_string());
    let options = glslang::CompilerOptions {
        source_language: glslang::SourceLanguage::GLSL,
        target: glslang::Target::Vulkan {
            version: glslang::VulkanVersion::Vulkan1_3,
            spirv_version: glslang::SpirvVersion::SPIRV1_5,
        },
        version_profile: None,
        messages: glslang::ShaderMessage::DEFAULT,
    };
    let input = glslang::ShaderInput::new(&source, stage, &options, None, None)?;
    Ok(compiler.create_shader(input)?.compile()?)
}

impl Raster {
    /// The pipeline: world-space vertices (position, normal), depth tested, four colour
    /// targets (normal, albedo, material, direct).
    pub fn new(host: &HostDevice) -> Result<Self, Box<dyn Error>> {
        let vert = compile(include_str!("gbuffer.vert"), glslang::ShaderStage::Vertex)?;
        let frag = compile(include_str!("gbuffer.frag"), glslang::ShaderStage::Fragment)?;
        let d = &host.device;
        // SAFETY: plain object creation; modules are destroyed once the pipeline exists.
        unsafe {
            let vert =
                d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&vert), None)?;
            let frag =
                d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&frag), None)?;
            let push = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
                .size(std::mem::size_of::<DrawConstants>() as u32)];
            let layout = d.create_pipeline_layout(
                &vk::PipelineLayoutCreateInfo::default().push_constant_ranges(&push),
                None,
            )?;
            let stages = [
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::VERTEX)
                    .module(vert)
                    .name(c"main"),
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(vk::ShaderStageFlags::FRAGMENT)
                    .module(frag)
                    .name(c"main"),
            ];
            let bindings = [vk::VertexInputBindingDescription {
                binding: 0,
                stride: 24,
                input_rate: vk::VertexInputRate::VERTEX,
            }];
            let attributes = [
                vk::VertexInputAttributeDescription {
                    location: 0,
                    binding: 0,
                    format: vk::Format::R32G32B32_SFLOAT,
                    offset: 0,
                },
                vk::VertexInputAttributeDescription {
                    location: 1,
                    binding: 0,
                    format: vk::Format::R32G32B32_SFLOAT,
                    offset: 12,
                },
            ];
            let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&bindings)
                .vertex_attribute_descriptions(&attributes);
            let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
                .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
            let viewport = vk::PipelineViewportStateCreateInfo::default()
                .viewport_count(1)
                .scissor_count(1);
            let raster = vk::PipelineRasterizationStateCreateInfo::default()
                .cull_mode(vk::CullModeFlags::NONE)
                .line_width(1.0);
            let multisample = vk::PipelineMultisampleStateCreateInfo::default()
                .rasterization_samples(vk::SampleCountFlags::TYPE_1);
            let depth = vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(true)
                .depth_compare_op(vk::CompareOp::LESS_OR_EQUAL);
            let blend = [vk::PipelineColorBlendAttachmentState::default()
                .color_write_mask(vk::ColorComponentFlags::RGBA); 4];
            let blend_state = vk::PipelineColorBlendStateCreateInfo::default().attachments(&blend);
            let dynamic_states = [vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
            let dynamic =
                vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
            let formats = [
                NORMAL_FORMAT,
                ALBEDO_FORMAT,
                MATERIAL_FORMAT,
                RADIANCE_FORMAT,
            ];
            let mut rendering = vk::PipelineRenderingCreateInfo::default()
                .color_attachment_formats(&formats)
                .depth_attachment_format(vk::Format::D32_SFLOAT);
            let info = vk::GraphicsPipelineCreateInfo::default()
                .stages(&stages)
                .vertex_input_state(&vertex_input)
                .input_assembly_state(&assembly)
                .viewport_state(&viewport)
                .rasterization_state(&raster)
                .multisample_state(&multisample)
                .depth_stencil_state(&depth)
                .color_blend_state(&blend_state)
                .dynamic_state(&dynamic)
                .layout(layout)
                .push_next(&mut rendering);
            let pipeline = d
                .create_graphics_pipelines(vk::PipelineCache::null(), &[info], None)
                .map_err(|(_, e)| e)?[0];
            d.destroy_shader_module(vert, None);
            d.destroy_shader_module(frag, None);
            Ok(Self { pipeline, layout })
        }
    }

    /// Records the G-buffer and direct light of `scene` seen through `view_proj` into
    /// `targets` (left in attachment layouts: [`Raster::written`] says which).
    pub fn record(
        &self,
        host: &HostDevice,
        cb: vk::CommandBuffer,
        targets: &Targets,
        scene: &HostScene,
        view_proj: Mat4,
    ) {
        let d = &host.device;
        let [w, h] = targets.depth.extent;
        let color_images = [
            &targets.normal,
            &targets.albedo,
            &targets.material,
            &targets.direct,
        ];
        let mut barriers: Vec<vk::ImageMemoryBarrier2> = color_images
            .iter()
            .map(|i| {
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                    .dst_stage_mask(vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT)
                    .dst_access_mask(vk::AccessFlags2::COLOR_ATTACHMENT_WRITE)
                    .old_layout(vk::ImageLayout::UNDEFINED)
                    .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .image(i.image)
                    .subresource_range(range(vk::ImageAspectFlags::COLOR))
            })
            .collect();
        barriers.push(
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_stage_mask(
                    vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
                        | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
                )
                .dst_access_mask(vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
                .image(targets.depth.image)
                .subresource_range(range(vk::ImageAspectFlags::DEPTH)),
        );
        let attachments: Vec<vk::RenderingAttachmentInfo> = color_images
            .iter()
            .map(|i| {
                vk::RenderingAttachmentInfo::default()
                    .image_view(i.view)
                    .image_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
                    .load_op(vk::AttachmentLoadOp::CLEAR)
                    .store_op(vk::AttachmentStoreOp::STORE)
                    .clear_value(vk::ClearValue::default())
            })
            .collect();
        let depth = vk::RenderingAttachmentInfo::default()
            .image_view(targets.depth.view)
            .image_layout(vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            });
        let area = vk::Rect2D {
            offset: vk::Offset2D::default(),
            extent: vk::Extent2D {
                width: w,
                height: h,
            },
        };
        let light = scene.light.filter(|l| l.light_kind().is_some());
        let (position, intensity, direction, cos_outer) = match light {
            Some(l) => {
                let kind = l.light_kind();
                let c = Vec3::from(l.color) * l.intensity;
                let cos_outer = if kind == Some(LightKind::Spot) {
                    l.outer_cone_angle.cos()
                } else {
                    -1.0
                };
                (
                    Vec3::from(l.position),
                    c,
                    Vec3::from(l.direction),
                    cos_outer,
                )
            }
            None => (Vec3::ZERO, Vec3::ZERO, Vec3::NEG_Y, -1.0),
        };
        // SAFETY: every handle belongs to the host's device and outlives the submission.
        unsafe {
            d.cmd_pipeline_barrier2(
                cb,
                &vk::DependencyInfo::default().image_memory_barriers(&barriers),
            );
            d.cmd_begin_rendering(
                cb,
                &vk::RenderingInfo::default()
                    .render_area(area)
                    .layer_count(1)
                    .color_attachments(&attachments)
                    .depth_attachment(&depth),
            );
            d.cmd_set_viewport(
                cb,
                0,
                &[vk::Viewport {
                    x: 0.0,
                    y: 0.0,
                    width: w as f32,
                    height: h as f32,
                    min_depth: 0.0,
                    max_depth: 1.0,
                }],
            );
            d.cmd_set_scissor(cb, 0, &[area]);
            d.cmd_bind_pipeline(cb, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
            d.cmd_bind_vertex_buffers(cb, 0, &[scene.vertices.buffer], &[0]);
            d.cmd_bind_index_buffer(cb, scene.indices.buffer, 0, vk::IndexType::UINT32);
            for draw in &scene.draws {
                let constants = DrawConstants {
                    view_proj: view_proj.to_cols_array_2d(),
                    base_color_roughness: Vec3::from(draw.base_color)
                        .extend(draw.roughness)
                        .to_array(),
                    light_position_metallic: position.extend(draw.metallic).to_array(),
                    light_intensity: intensity.extend(0.0).to_array(),
                    light_direction_cos_outer: direction.extend(cos_outer).to_array(),
                };
                d.cmd_push_constants(
                    cb,
                    self.layout,
                    vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                    0,
                    bytemuck::bytes_of(&constants),
                );
                d.cmd_draw_indexed(cb, draw.index_count, 1, draw.first_index, 0, 0);
            }
            d.cmd_end_rendering(cb);
        }
    }

    /// Destroys the pipeline.
    pub fn destroy(self, host: &HostDevice) {
        // SAFETY: the GPU is done with it.
        unsafe {
            host.device.destroy_pipeline(self.pipeline, None);
            host.device.destroy_pipeline_layout(self.layout, None);
        }
    }
}

/// The state [`Raster::record`] leaves a colour target in.
pub fn color_written() -> shine::graph::ExternalState {
    shine::graph::ExternalState::new(
        vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    )
}

/// The state [`Raster::record`] leaves the depth target in.
pub fn depth_written() -> shine::graph::ExternalState {
    shine::graph::ExternalState::new(
        vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS
            | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
        vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
        vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
    )
}

/// Where shine leaves the host's inputs: read by shaders, next used by the host's next frame
/// (which starts them from UNDEFINED).
pub fn sampled_after() -> shine::graph::ExternalState {
    shine::graph::ExternalState::new(
        vk::PipelineStageFlags2::ALL_COMMANDS,
        vk::AccessFlags2::MEMORY_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    )
}

/// Where shine leaves the GI image: ready for the host's copy to the CPU.
pub fn copy_source() -> shine::graph::ExternalState {
    shine::graph::ExternalState::new(
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    )
}
