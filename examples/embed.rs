//! Embedding shine in a host Vulkan engine: the host creates its instance, device, queue and
//! command buffer itself (enabling what `Device::requirements()` lists), lends them to shine,
//! records a shine frame into its own command buffer targeting its own image, submits it, and
//! saves the image.
//!
//! `cargo run --example embed -- out.png`

use shine::frame::renderer::{HostTarget, Renderer};
use shine::gpu::{Device, Image, ImageDesc, RawDevice, ash, vk};
use shine::graph::ExternalState;
use shine::settings::Settings;
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let output = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "embed.png".into());
    let (width, height) = (256, 256);

    // --- The host engine's own Vulkan objects.
    // SAFETY: plain Vulkan object creation by the host; destroyed at the end of main.
    let entry = unsafe { ash::Entry::load()? };
    let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
    // SAFETY: as above.
    let instance = unsafe {
        entry.create_instance(
            &vk::InstanceCreateInfo::default().application_info(&app),
            None,
        )?
    };
    // SAFETY: as above.
    let physical = *unsafe { instance.enumerate_physical_devices()? }
        .first()
        .ok_or("no Vulkan device")?;
    // SAFETY: as above.
    let family = unsafe { instance.get_physical_device_queue_family_properties(physical) }
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
    let mut features =
        Device::requirements().enable_vulkan13(vk::PhysicalDeviceVulkan13Features::default());
    // SAFETY: as above; the features enabled are those shine requires.
    let device = unsafe {
        instance.create_device(
            physical,
            &vk::DeviceCreateInfo::default()
                .queue_create_infos(&queues)
                .push_next(&mut features),
            None,
        )?
    };
    // SAFETY: queue 0 of `family` was requested.
    let queue = unsafe { device.get_device_queue(family, 0) };
    // SAFETY: as above.
    let pool = unsafe {
        device.create_command_pool(
            &vk::CommandPoolCreateInfo::default().queue_family_index(family),
            None,
        )?
    };

    {
        // --- shine on the host's device.
        let shine_device = Device::from_raw(RawDevice {
            entry: entry.clone(),
            instance: instance.clone(),
            physical_device: physical,
            device: device.clone(),
            queue_family_index: family,
            queue,
            debug_utils: false,
            enabled: shine::gpu::EnabledFeatures::required(),
            allocator: None,
        })?;
        let mut renderer = Renderer::new(&shine_device)?;
        renderer.set_scene(&shine_scene::Scene::builtin("cornell-box")?, 0.0)?;
        let target = Image::new(
            &shine_device,
            &ImageDesc::new_2d(
                "host target",
                [width, height],
                vk::Format::R8G8B8A8_UNORM,
                vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::TRANSFER_SRC,
            ),
        )?;

        // --- The host records shine's frame into its own command buffer and submits it.
        // SAFETY: host-side recording and submission; everything is waited for below.
        unsafe {
            let cb = device.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .level(vk::CommandBufferLevel::PRIMARY)
                    .command_buffer_count(1),
            )?[0];
            device.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())?;
            renderer.record(
                cb,
                0,
                &HostTarget {
                    image: target.raw(),
                    view: target.view(),
                    format: target.format(),
                    extent: [width, height],
                    usage: target.usage(),
                    before: ExternalState::UNDEFINED,
                    after: ExternalState::new(
                        vk::PipelineStageFlags2::COPY,
                        vk::AccessFlags2::TRANSFER_READ,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    ),
                },
                &Settings {
                    width,
                    height,
                    ..Settings::default()
                },
            )?;
            device.end_command_buffer(cb)?;
            let fence = device.create_fence(&vk::FenceCreateInfo::default(), None)?;
            let cbs = [cb];
            device.queue_submit(
                queue,
                &[vk::SubmitInfo::default().command_buffers(&cbs)],
                fence,
            )?;
            device.wait_for_fences(&[fence], true, u64::MAX)?;
            device.destroy_fence(fence, None);
        }
        for t in renderer.timings()? {
            println!("{:>10} {:8.3} ms", t.name, (t.end_ns - t.begin_ns) / 1e6);
        }
        let pixels = shine_device.read_image(&target, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)?;
        image::RgbaImage::from_raw(width, height, pixels)
            .ok_or("readback size mismatch")?
            .save(&output)?;
        println!("wrote {output}");
    }

    // --- The host tears down its own objects after shine's are gone.
    // SAFETY: every shine object was dropped with the block above.
    unsafe {
        device.destroy_command_pool(pool, None);
        device.destroy_device(None);
        instance.destroy_instance(None);
    }
    Ok(())
}
