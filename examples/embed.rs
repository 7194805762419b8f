//! Embedding shine's full renderer in a host Vulkan engine: the host (examples/host_gbuffer/
//! host, its instance, device, queue and command buffers) lends its device to shine, records a
//! whole shine frame into its own command buffer targeting an image, submits it, and saves the
//! image. For shine as a GI pass fed by the host's own G-buffer, see `host_gbuffer`.
//!
//! `cargo run --example embed -- out.png`

#[path = "host_gbuffer/host/mod.rs"]
mod host;

use shine::frame::renderer::{HostTarget, Renderer};
use shine::gpu::{Device, Image, ImageDesc, vk};
use shine::graph::ExternalState;
use shine::settings::Settings;
use std::error::Error;

fn main() -> Result<(), Box<dyn Error>> {
    let output = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "embed.png".into());
    let (width, height) = (256, 256);
    let host = host::HostDevice::new(true)?;
    {
        // --- shine on the host's device.
        let shine_device = Device::from_raw(host.lend(false))?;
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
        let cb = host.begin()?;
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
                after: host::copy_source(),
            },
            &Settings {
                width,
                height,
                ..Settings::default()
            },
        )?;
        host.submit_and_wait(cb)?;
        for t in renderer.timings()? {
            println!("{:>10} {:8.3} ms", t.name, (t.end_ns - t.begin_ns) / 1e6);
        }
        let pixels = shine_device.read_image(&target, vk::ImageLayout::TRANSFER_SRC_OPTIMAL)?;
        image::RgbaImage::from_raw(width, height, pixels)
            .ok_or("readback size mismatch")?
            .save(&output)?;
        println!("wrote {output}");
    }
    // The host's objects go after shine's (HostDevice's drop).
    Ok(())
}
