//! Embedding: a host engine creates its own instance and device (as a host would, enabling
//! `Device::requirements()`), lends them to shine with `Device::from_raw`, runs shine work, and
//! still owns working handles after every shine object is gone.

mod common;
#[path = "embedding/gi_context.rs"]
mod gi_context;
#[path = "../examples/host_gbuffer/host/mod.rs"]
mod host;

use shine::gpu::ash;
use shine::gpu::{Device, RawDevice, vk};
use std::ffi::{CStr, c_void};
use std::sync::atomic::{AtomicU32, Ordering};

/// Problems reported to the host's own messenger.
static HOST_PROBLEMS: AtomicU32 = AtomicU32::new(0);

unsafe extern "system" fn host_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    _user: *mut c_void,
) -> vk::Bool32 {
    if severity.intersects(
        vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
            | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
    ) {
        HOST_PROBLEMS.fetch_add(1, Ordering::Relaxed);
        // SAFETY: the loader passes valid callback data for this call.
        let message = unsafe { data.as_ref() }
            .filter(|d| !d.p_message.is_null())
            // SAFETY: p_message is NUL-terminated.
            .map(|d| {
                unsafe { CStr::from_ptr(d.p_message) }
                    .to_string_lossy()
                    .into_owned()
            })
            .unwrap_or_default();
        eprintln!("[host validation] {message}");
    }
    vk::FALSE
}

struct Host {
    entry: ash::Entry,
    instance: ash::Instance,
    debug: (ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT),
    physical: vk::PhysicalDevice,
    device: ash::Device,
    family: u32,
    queue: vk::Queue,
}

impl Host {
    fn new() -> Self {
        // SAFETY: test code: the system loader, valid create infos, objects destroyed in Drop.
        unsafe {
            let entry = ash::Entry::load().expect("Vulkan loader");
            let layer = c"VK_LAYER_KHRONOS_validation";
            let have_layer = entry
                .enumerate_instance_layer_properties()
                .expect("layers")
                .iter()
                .any(|l| l.layer_name_as_c_str() == Ok(layer));
            assert!(
                have_layer || std::env::var_os("CI").is_none(),
                "CI needs the validation layer"
            );
            let layers = if have_layer {
                vec![layer.as_ptr()]
            } else {
                vec![]
            };
            let extensions = [ash::ext::debug_utils::NAME.as_ptr()];
            let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
            let instance = entry
                .create_instance(
                    &vk::InstanceCreateInfo::default()
                        .application_info(&app)
                        .enabled_layer_names(&layers)
                        .enabled_extension_names(&extensions),
                    None,
                )
                .expect("host instance");
            let debug_loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let messenger = debug_loader
                .create_debug_utils_messenger(
                    &vk::DebugUtilsMessengerCreateInfoEXT::default()
                        .message_severity(
                            vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING,
                        )
                        .message_type(
                            vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                                | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION,
                        )
                        .pfn_user_callback(Some(host_callback)),
                    None,
                )
                .expect("host messenger");
            let physical = instance.enumerate_physical_devices().expect("devices")[0];
            let family = instance
                .get_physical_device_queue_family_properties(physical)
                .iter()
                .position(|f| {
                    f.queue_flags
                        .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                })
                .expect("graphics+compute queue") as u32;
            let priorities = [1.0];
            let queues = [vk::DeviceQueueCreateInfo::default()
                .queue_family_index(family)
                .queue_priorities(&priorities)];
            let mut f13 = Device::requirements()
                .enable_vulkan13(vk::PhysicalDeviceVulkan13Features::default());
            let device = instance
                .create_device(
                    physical,
                    &vk::DeviceCreateInfo::default()
                        .queue_create_infos(&queues)
                        .push_next(&mut f13),
                    None,
                )
                .expect("host device");
            let queue = device.get_device_queue(family, 0);
            Self {
                entry,
                instance,
                debug: (debug_loader, messenger),
                physical,
                device,
                family,
                queue,
            }
        }
    }
}

impl Host {
    /// shine's view of the host's objects.
    fn lend(&self) -> Device {
        Device::from_raw(RawDevice {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical_device: self.physical,
            device: self.device.clone(),
            queue_family_index: self.family,
            queue: self.queue,
            debug_utils: true,
            enabled: shine::gpu::EnabledFeatures::required(),
            allocator: None,
        })
        .expect("wrap the host device")
    }
}

impl Drop for Host {
    fn drop(&mut self) {
        // SAFETY: the host destroys what it created, after shine's objects are gone.
        unsafe {
            self.device.destroy_device(None);
            self.debug
                .0
                .destroy_debug_utils_messenger(self.debug.1, None);
            self.instance.destroy_instance(None);
        }
    }
}

#[test]
fn shine_runs_on_a_host_device_and_leaves_it_alive() {
    let host = Host::new();
    {
        let device = host.lend();
        let dirs: [[f32; 4]; 2] = [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]];
        let y = common::sh_eval(&device, &shine::shaders::SH_EVAL_COMP_BANDS1, &dirs, 1);
        assert!(y.iter().all(|v| (v - 0.282_094_8).abs() < 1e-6), "{y:?}");
        device.wait_idle().expect("idle");
    }
    // shine is gone; the host's device and queue must still work.
    // SAFETY: host objects are alive; the fence is created and destroyed here.
    unsafe {
        let fence = host
            .device
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .expect("host device still usable");
        host.device
            .queue_submit(host.queue, &[], fence)
            .expect("host queue still usable");
        host.device
            .wait_for_fences(&[fence], true, u64::MAX)
            .expect("wait");
        host.device.destroy_fence(fence, None);
    }
    assert_eq!(
        HOST_PROBLEMS.load(Ordering::Relaxed),
        0,
        "the host's validation layer reported problems"
    );
}

#[test]
fn requirements_name_what_a_host_must_enable() {
    let r = Device::requirements();
    assert_eq!(r.api_version, vk::API_VERSION_1_3);
    assert!(r.vulkan13_features.contains(&"synchronization2"));
    assert!(r.vulkan13_features.contains(&"dynamicRendering"));
    let f = r.enable_vulkan13(vk::PhysicalDeviceVulkan13Features::default());
    assert_eq!(
        (f.synchronization2, f.dynamic_rendering),
        (vk::TRUE, vk::TRUE)
    );
}

#[test]
fn a_frame_recorded_into_a_host_command_buffer_lands_in_the_host_image() {
    let host = Host::new();
    let device = host.lend();
    let scene = shine_scene::Scene::builtin("cornell-box").expect("scene");
    let mut settings = shine::settings::Settings {
        width: 32,
        height: 32,
        gi: shine::settings::GiTechniques::none(),
        ..Default::default()
    };
    settings.shadow.size = 256;
    let mut renderer = shine::frame::renderer::Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let reference = renderer.render(&settings).expect("reference frame");

    let target = shine::gpu::Image::new(
        &device,
        &shine::gpu::ImageDesc::new_2d(
            "host target",
            [32, 32],
            vk::Format::R8G8B8A8_UNORM,
            vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC,
        ),
    )
    .expect("target");
    let after = shine::graph::ExternalState::new(
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    );
    // SAFETY: host-side command pool, buffer and fence, destroyed below after the wait.
    unsafe {
        let pool = host
            .device
            .create_command_pool(
                &vk::CommandPoolCreateInfo::default().queue_family_index(host.family),
                None,
            )
            .expect("pool");
        let cb = host
            .device
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )
            .expect("cb")[0];
        host.device
            .begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())
            .expect("begin");
        renderer
            .record(
                cb,
                0,
                &shine::frame::renderer::HostTarget {
                    image: target.raw(),
                    view: target.view(),
                    format: target.format(),
                    extent: [32, 32],
                    usage: target.usage(),
                    before: shine::graph::ExternalState::UNDEFINED,
                    after,
                },
                &settings,
            )
            .expect("record");
        host.device.end_command_buffer(cb).expect("end");
        let fence = host
            .device
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .expect("fence");
        let cbs = [cb];
        host.device
            .queue_submit(
                host.queue,
                &[vk::SubmitInfo::default().command_buffers(&cbs)],
                fence,
            )
            .expect("submit");
        host.device
            .wait_for_fences(&[fence], true, u64::MAX)
            .expect("wait");
        host.device.destroy_fence(fence, None);
        host.device.destroy_command_pool(pool, None);
    }
    let pixels = device
        .read_image(&target, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .expect("read target");
    let expected: Vec<u8> = reference.ldr.texels.iter().flatten().copied().collect();
    assert_eq!(
        pixels, expected,
        "the host image differs from the rendered LDR frame"
    );
    assert!(pixels.iter().any(|&p| p > 0), "the host image stayed black");
    drop((renderer, target));
    device.wait_idle().expect("idle");
    drop(device);
    assert_eq!(
        HOST_PROBLEMS.load(Ordering::Relaxed),
        0,
        "the host's validation layer reported problems"
    );
}
