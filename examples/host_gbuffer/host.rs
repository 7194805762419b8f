//! A minimal host engine, written as an engine would be and sharing nothing with shine but the
//! Vulkan device: its own instance (validation on), device, queue, command pool and
//! gpu-allocator; its own GLSL compiled at run time; its own images; its own G-buffer raster
//! pipeline (dynamic rendering) with its own direct light. `examples/host_gbuffer/main.rs` and
//! `tests/embedding.rs` drive it.

#![allow(dead_code)] // The example and the tests each use a part.

use ash::vk;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use shine::gpu::ash;
use shine_scene::{LightKind, Scene};
use std::error::Error;
use std::ffi::{CStr, c_void};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

/// Errors and warnings the validation layer reported to the host's messenger.
pub static VALIDATION_MESSAGES: AtomicU32 = AtomicU32::new(0);

unsafe extern "system" fn on_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    if severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
    ) {
        VALIDATION_MESSAGES.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the loader passes valid callback data; p_message is NUL-terminated.
        let text = unsafe { data.as_ref() }
            .filter(|d| !d.p_message.is_null())
            .map(|d| {
                unsafe { CStr::from_ptr(d.p_message) }
                    .to_string_lossy()
                    .into_owned()
            })
            .unwrap_or_default();
        eprintln!("[host validation] {text}");
    }
    vk::FALSE
}

/// The host's Vulkan objects.
pub struct HostDevice {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub physical: vk::PhysicalDevice,
    pub device: ash::Device,
    pub family: u32,
    pub queue: vk::Queue,
    pub pool: vk::CommandPool,
    /// The host's allocator (shine may be handed it); `None` only while dropping.
    allocator: Option<Arc<Mutex<Allocator>>>,
    /// Whether the validation layer is on.
    pub validation: bool,
}

impl HostDevice {
    /// An instance (with the validation layer where installed), the first device with a
    /// graphics+compute queue, created with shine's requirements plus `extra` enabled.
    pub fn new(enable_shine_requirements: bool) -> Result<Self, Box<dyn Error>> {
        // SAFETY: plain object creation; destroyed in Drop in reverse order.
        unsafe {
            let entry = ash::Entry::load()?;
            let layer = c"VK_LAYER_KHRONOS_validation";
            let validation = entry
                .enumerate_instance_layer_properties()?
                .iter()
                .any(|l| l.layer_name_as_c_str() == Ok(layer));
            let layers: Vec<*const i8> = if validation {
                vec![layer.as_ptr()]
            } else {
                vec![]
            };
            let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
            let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
            let instance = entry.create_instance(
                &vk::InstanceCreateInfo::default()
                    .application_info(&app)
                    .enabled_layer_names(&layers)
                    .enabled_extension_names(&extensions),
                None,
            )?;
            let debug = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let messenger = debug.create_debug_utils_messenger(
                &vk::DebugUtilsMessengerCreateInfoEXT::default()
                    .message_severity(
                        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                    )
                    .message_type(
                        vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                            | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                            | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                    )
                    .pfn_user_callback(Some(on_message)),
                None,
            )?;
            let physical = *instance
                .enumerate_physical_devices()?
                .first()
                .ok_or("no Vulkan device")?;
            let family = instance
                .get_physical_device_queue_family_properties(physical)
                .iter()
                .position(|f| {
                    f.queue_flags
                        .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                })
                .ok_or("no graphics+compute queue")? as u32;
            let priorities = [1.0];
            let queues = [vk::DeviceQueueCreateInfo::default()
                .queue_family_index(family)
                .queue_priorities(&priorities)];
            let mut features13 = if enable_shine_requirements {
                shine::gpu::Device::requirements()
                    .enable_vulkan13(vk::PhysicalDeviceVulkan13Features::default())
            } else {
                // Dynamic rendering only: the host's raster needs it, shine also needs
                // synchronization2.
                vk::PhysicalDeviceVulkan13Features::default().dynamic_rendering(true)
            };
            let device = instance.create_device(
                physical,
                &vk::DeviceCreateInfo::default()
                    .queue_create_infos(&queues)
                    .push_next(&mut features13),
                None,
            )?;
            let queue = device.get_device_queue(family, 0);
            let pool = device.create_command_pool(
                &vk::CommandPoolCreateInfo::default()
                    .queue_family_index(family)
                    .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER),
                None,
            )?;
            let allocator = Allocator::new(&AllocatorCreateDesc {
                instance: instance.clone(),
                device: device.clone(),
                physical_device: physical,
                debug_settings: Default::default(),
                buffer_device_address: false,
                allocation_sizes: Default::default(),
            })?;
            Ok(Self {
                entry,
                instance,
                messenger: Some((debug, messenger)),
                physical,
                device,
                family,
                queue,
                pool,
                allocator: Some(Arc::new(Mutex::new(allocator))),
                validation,
            })
        }
    }

    /// The host's allocator.
    pub fn allocator(&self) -> Arc<Mutex<Allocator>> {
        self.allocator.clone().expect("alive until drop")
    }

    /// A primary command buffer from the host's pool, begun for one submission.
    pub fn begin(&self) -> Result<vk::CommandBuffer, Box<dyn Error>> {
        // SAFETY: the pool belongs to this device.
        unsafe {
            let cb = self.device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(self.pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )?[0];
            self.device.begin_command_buffer(
                cb,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )?;
            Ok(cb)
        }
    }

    /// Ends `cb`, submits it and waits for it: the host's own submission of a frame.
    pub fn submit_and_wait(&self, cb: vk::CommandBuffer) -> Result<(), Box<dyn Error>> {
        // SAFETY: `cb` was begun by `begin`; the fence is waited for before it is destroyed.
        unsafe {
            self.device.end_command_buffer(cb)?;
            let fence = self
                .device
                .create_fence(&vk::FenceCreateInfo::default(), None)?;
            let cbs = [cb];
            self.device.queue_submit(
                self.queue,
                &[vk::SubmitInfo::default().command_buffers(&cbs)],
                fence,
            )?;
            self.device.wait_for_fences(&[fence], true, u64::MAX)?;
            self.device.destroy_fence(fence, None);
            self.device.free_command_buffers(self.pool, &cbs);
        }
        Ok(())
    }

    /// The host's device lent to shine (`allocator`: shine also allocates from the host's).
    pub fn lend(&self, share_allocator: bool) -> shine::gpu::RawDevice {
        shine::gpu::RawDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical_device: self.physical,
            device: self.device.clone(),
            queue_family_index: self.family,
            queue: self.queue,
            debug_utils: false,
            enabled: shine::gpu::EnabledFeatures::required(),
            allocator: share_allocator.then(|| self.allocator()),
        }
    }
}

impl Drop for HostDevice {
    fn drop(&mut self) {
        // SAFETY: every child object is gone (the documented teardown order: shine first,
        // then the host's images, then this); the allocator's last reference goes before the
        // device.
        unsafe {
            let _ = self.device.device_wait_idle();
            self.device.destroy_command_pool(self.pool, None);
            drop(self.allocator.take());
            self.device.destroy_device(None);
            if let Some((debug, messenger)) = self.messenger.take() {
                debug.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

/// An image the host allocated itself, with a view of its one mip and layer.
pub struct HostImage {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: [u32; 2],
    pub usage: vk::ImageUsageFlags,
    allocation: Option<Allocation>,
}

impl HostImage {
    /// A 2D image of `format`, `extent` and `usage`, in device memory from the host's
    /// allocator.
    pub fn new(
        host: &HostDevice,
        name: &str,
        format: vk::Format,
        extent: [u32; 2],
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, Box<dyn Error>> {
        let depth = matches!(format, vk::Format::D32_SFLOAT);
        // SAFETY: plain object creation on the host's device; destroyed by `destroy`.
        unsafe {
            let image = host.device.create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width: extent[0],
                        height: extent[1],
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .usage(usage),
                None,
            )?;
            let requirements = host.device.get_image_memory_requirements(image);
            let allocation = host
                .allocator()
                .lock()
                .unwrap()
                .allocate(&AllocationCreateDesc {
                    name,
                    requirements,
                    location: MemoryLocation::GpuOnly,
                    linear: false,
                    allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                })?;
            host.device
                .bind_image_memory(image, allocation.memory(), allocation.offset())?;
            let aspect = if depth {
                vk::ImageAspectFlags::DEPTH
            } else {
                vk::ImageAspectFlags::COLOR
            };
            let view = host.device.create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(range(aspect)),
                None,
            )?;
            Ok(Self {
                image,
                view,
                format,
                extent,
                usage,
                allocation: Some(allocation),
            })
        }
    }

    /// The image as shine sees it, coming from `before` and left in `after`.
    pub fn lend(
        &self,
        before: shine::graph::ExternalState,
        after: shine::graph::ExternalState,
    ) -> shine::HostTarget {
        shine::HostTarget {
            image: self.image,
            view: self.view,
            format: self.format,
            extent: self.extent,
            usage: self.usage,
            before,
            after,
        }
    }

    /// Destroys the image (the GPU must be done with it).
    pub fn destroy(mut self, host: &HostDevice) {
        // SAFETY: made on this device by `new`; the caller says the GPU is done with it.
        unsafe {
            host.device.destroy_image_view(self.view, None);
            host.device.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = host.allocator().lock().unwrap().free(a);
        }
    }
}

/// The whole of a one-mip, one-layer image of `aspect`.
fn range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// A host-visible buffer from the host's allocator.
pub struct HostBuffer {
    pub buffer: vk::Buffer,
    allocation: Option<Allocation>,
}

impl HostBuffer {
    /// A buffer of `size` bytes for `usage`, in `location` memory.
    pub fn new(
        host: &HostDevice,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, Box<dyn Error>> {
        // SAFETY: plain object creation; destroyed by `destroy`.
        unsafe {
            let buffer = host.device.create_buffer(
                &vk::BufferCreateInfo::default().size(size).usage(usage),
                None,
            )?;
            let requirements = host.device.get_buffer_memory_requirements(buffer);
            let allocation = host
                .allocator()
                .lock()
                .unwrap()
                .allocate(&AllocationCreateDesc {
                    name,
                    requirements,
                    location,
                    linear: true,
                    allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                })?;
            host.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())?;
            Ok(Self {
                buffer,
                allocation: Some(allocation),
            })
        }
    }

    /// The mapped bytes (host-visible buffers).
    pub fn bytes(&mut self) -> &mut [u8] {
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .expect("host-visible")
    }

    /// Destroys the buffer (the GPU must be done with it).
    pub fn destroy(mut self, host: &HostDevice) {
        // SAFETY: made on this device; the caller says the GPU is done with it.
        unsafe { host.device.destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            let _ = host.allocator().lock().unwrap().free(a);
        }
    }
}

/// The host's copy of a scene's geometry: world-space vertices (position, normal), indices,
/// and one draw per primitive with its material.
pub struct HostScene {
    pub vertices: HostBuffer,
    pub indices: HostBuffer,
    pub draws: Vec<Draw>,
    /// The first light (the host lights with it directly).
    pub light: Option<shine_scene::Light>,
}

/// One primitive: its index range and material.
pub struct Draw {
    pub first_index: u32,
    pub index_count: u32,
    pub base_color: [f32; 3],
    pub roughness: f32,
    pub metallic: f32,
}

impl HostScene {
    /// Flattens `scene` at rest into host-visible vertex and index buffers.
    pub fn new(host: &HostDevice, scene: &Scene) -> Result<Self, Box<dyn Error>> {
        let world = scene.rest_world_transforms();
        let mut vertices: Vec<[f32; 6]> = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut draws = Vec::new();
        for (node, m) in scene.nodes.iter().zip(&world) {
            let Some(mesh) = node.mesh.and_then(|i| scene.meshes.get(i)) else {
                continue;
            };
            let normal_matrix = m.inverse().transpose();
            for p in &mesh.primitives {
                let base = vertices.len() as u32;
                for (i, pos) in p.positions.iter().enumerate() {
                    let wp = m.transform_point3(*pos);
                    let n = p.normals.get(i).copied().unwrap_or(Vec3::Y);
                    let wn = normal_matrix.transform_vector3(n).normalize_or(Vec3::Y);
                    vertices.push([wp.x, wp.y, wp.z, wn.x, wn.y, wn.z]);
                }
                let material = scene.materials.get(p.material as usize);
                draws.push(Draw {
                    first_index: indices.len() as u32,
                    index_count: p.indices.len() as u32,
                    base_color: material.map_or([0.8; 3], |m| {
                        [m.base_color[0], m.base_color[1], m.base_color[2]]
                    }),
                    roughness: material.map_or(1.0, |m| m.roughness),
                    metallic: material.map_or(0.0, |m| m.metallic),
                });
                indices.extend(p.indices.iter().map(|i| i + base));
            }
        }
        let upload = |name, bytes: &[u8], usage| -> Result<HostBuffer, Box<dyn Error>> {
            let mut buffer = HostBuffer::new(
                host,
                name,
                bytes.len() as u64,
                usage,
                MemoryLocation::CpuToGpu,
            )?;
            buffer.bytes()[..bytes.len()].copy_from_slice(bytes);
            Ok(buffer)
        };
        Ok(Self {
            vertices: upload(
                "host vertices",
                bytemuck::cast_slice(&vertices),
                vk::BufferUsageFlags::VERTEX_BUFFER,
            )?,
            indices: upload(
                "host indices",
                bytemuck::cast_slice(&indices),
                vk::BufferUsageFlags::INDEX_BUFFER,
            )?,
            draws,
            light: scene.lights_at(&world).into_iter().next(),
        })
    }

    /// Destroys the buffers.
    pub fn destroy(self, host: &HostDevice) {
        self.vertices.destroy(host);
        self.indices.destroy(host);
    }
}

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

/// Copies an RGBA16F `image`, last used as `from`, to the CPU as f32 texels (the host's own
/// submission, waited for).
pub fn read_rgba16f(
    host: &HostDevice,
    image: &HostImage,
    from: shine::graph::ExternalState,
) -> Result<Vec<[f32; 4]>, Box<dyn Error>> {
    let [w, h] = image.extent;
    let bytes = u64::from(w) * u64::from(h) * 8;
    let mut buffer = HostBuffer::new(
        host,
        "host readback",
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    let cb = host.begin()?;
    let barrier = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(vk::PipelineStageFlags2::COPY)
        .dst_access_mask(vk::AccessFlags2::TRANSFER_READ)
        .old_layout(from.layout)
        .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .image(image.image)
        .subresource_range(range(vk::ImageAspectFlags::COLOR))];
    // SAFETY: handles of the host's device; the submission is waited for below.
    unsafe {
        host.device.cmd_pipeline_barrier2(
            cb,
            &vk::DependencyInfo::default().image_memory_barriers(&barrier),
        );
        host.device.cmd_copy_image_to_buffer(
            cb,
            image.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer.buffer,
            &[vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: w,
                    height: h,
                    depth: 1,
                })],
        );
    }
    host.submit_and_wait(cb)?;
    let texels = buffer.bytes()[..bytes as usize]
        .chunks_exact(8)
        .map(|t| {
            let half = |i: usize| f16_to_f32(u16::from_le_bytes([t[2 * i], t[2 * i + 1]]));
            [half(0), half(1), half(2), half(3)]
        })
        .collect();
    buffer.destroy(host);
    Ok(texels)
}

/// IEEE half to single precision.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

/// The view and (unjittered, Vulkan y-down) projection of `scene`'s first camera for an
/// `extent` image, with the camera turned by `orbit` radians about the vertical axis through
/// the scene's centre: the host's own camera code.
pub fn camera(scene: &Scene, extent: [u32; 2], orbit: f32) -> (Mat4, Mat4) {
    let world = scene.rest_world_transforms();
    let camera_world = scene.camera_world(0, &world).unwrap_or(Mat4::IDENTITY);
    let bounds = world
        .iter()
        .zip(&scene.nodes)
        .filter_map(|(m, n)| Some((m, scene.meshes.get(n.mesh?)?)))
        .flat_map(|(m, mesh)| {
            mesh.primitives
                .iter()
                .flat_map(|p| p.positions.iter().map(|v| m.transform_point3(*v)))
        })
        .fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
    let centre = (bounds.0 + bounds.1) * 0.5;
    let turn = Mat4::from_translation(centre)
        * Mat4::from_rotation_y(orbit)
        * Mat4::from_translation(-centre);
    let view = (turn * camera_world).inverse();
    let aspect = extent[0] as f32 / extent[1].max(1) as f32;
    let (yfov, znear, zfar) = match scene.cameras.first().map(|c| c.projection) {
        Some(shine_scene::Projection::Perspective {
            yfov, znear, zfar, ..
        }) => (yfov, znear, zfar),
        _ => (0.8, 0.05, None),
    };
    let mut projection = match zfar {
        Some(far) => Mat4::perspective_rh(yfov, aspect, znear, far),
        None => Mat4::perspective_infinite_rh(yfov, aspect, znear),
    };
    projection.y_axis.y = -projection.y_axis.y;
    (view, projection)
}
