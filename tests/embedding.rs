//! Embedding: a host engine creates its own instance and device (as a host would, enabling
//! `Device::requirements()`), lends them to shine with `Device::from_raw`, runs shine work, and
//! still owns working handles after every shine object is gone.

#[path = "embedding/animated_host.rs"]
mod animated_host;
mod common;
#[path = "embedding/debug_view.rs"]
mod debug_view;
#[path = "embedding/gi_context.rs"]
mod gi_context;
#[path = "../examples/host_gbuffer/host/mod.rs"]
mod host;
#[path = "embedding/host_geometry.rs"]
mod host_geometry;
#[path = "embedding/internal_resolution.rs"]
mod internal_resolution;
#[path = "embedding/specular_out.rs"]
mod specular_out;
#[path = "embedding/truth.rs"]
mod truth;
#[path = "embedding/warm_up.rs"]
mod warm_up;

use host::HostDevice;
use shine::gpu::{Device, vk};
use std::sync::atomic::Ordering;

/// Zero problems reported to the host's own messenger (shine's calls on the host's device
/// included).
fn assert_host_clean() {
    assert_eq!(
        host::VALIDATION_MESSAGES.load(Ordering::Relaxed),
        0,
        "the host's validation layer reported problems"
    );
}

#[test]
fn shine_runs_on_a_host_device_and_leaves_it_alive() {
    let host = HostDevice::new(true).expect("host");
    {
        let device = Device::from_raw(host.lend(false)).expect("wrap the host device");
        let dirs: [[f32; 4]; 2] = [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0]];
        let y = common::sh_eval(&device, &shine::shaders::SH_EVAL_COMP_BANDS1, &dirs, 1);
        assert!(y.iter().all(|v| (v - 0.282_094_8).abs() < 1e-6), "{y:?}");
        device.wait_idle().expect("idle");
    }
    // shine is gone; the host's device and queue must still work.
    let cb = host.begin().expect("host device still usable");
    host.submit_and_wait(cb).expect("host queue still usable");
    assert_host_clean();
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
    let host = HostDevice::new(true).expect("host");
    let device = Device::from_raw(host.lend(false)).expect("wrap the host device");
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
    let cb = host.begin().expect("begin");
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
    host.submit_and_wait(cb).expect("submit");
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
    assert_host_clean();
}
