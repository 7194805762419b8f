//! A minimal host engine, written as an engine would be and sharing nothing with shine but the
//! Vulkan device: its own instance (validation on), device, queue, command pool and
//! gpu-allocator; its own GLSL compiled at run time; its own images; its own G-buffer raster
//! pipeline (dynamic rendering) with its own direct light. `examples/host_gbuffer/main.rs` and
//! `tests/embedding.rs` drive it.

// Two examples (host_gbuffer, embed) and tests/embedding.rs each use a part of this host.
#![allow(dead_code, unused_imports)]

mod raster;
mod resources;
mod scene;

pub use raster::{Raster, Targets, color_written, copy_source, depth_written, sampled_after};
pub use resources::{HostImage, read_rgba16f};
pub use scene::{HostScene, camera};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};
use shine::gpu::ash;
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
    /// The host's pipeline cache, lent to shine (a real engine saves it between runs).
    pub pipeline_cache: vk::PipelineCache,
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
            let pipeline_cache =
                device.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None)?;
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
                pipeline_cache,
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
            // The host's instance enables VK_EXT_debug_utils: shine names and labels its work.
            debug_utils: true,
            enabled: shine::gpu::EnabledFeatures::required(),
            allocator: share_allocator.then(|| self.allocator()),
            pipeline_cache: self.pipeline_cache,
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
            self.device
                .destroy_pipeline_cache(self.pipeline_cache, None);
            drop(self.allocator.take());
            self.device.destroy_device(None);
            if let Some((debug, messenger)) = self.messenger.take() {
                debug.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}
