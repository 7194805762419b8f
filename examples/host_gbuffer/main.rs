//! A host engine using shine as a GI pass (docs/embedding.md): the host rasterises its own
//! G-buffer and direct light with its own pipeline into its own images, hands them to a
//! `GiContext` recorded into its own command buffer, composites direct + GI itself, and
//! writes a PNG after 6 frames of a moving camera. It prints how long the context took to make
//! and warm up, and each frame's wall time (recording, submission and wait): with the warm-up
//! the first frame costs what the others do; `--cold` skips it to show the hitch. `--gi T`
//! picks the technique (default `hvl`), `--internal P` the internal resolution in per cent
//! (100, 75, 50 or 25); the last frame's GPU time of shine's passes is printed.
//!
//! `cargo run --release --example host_gbuffer -- out.png [--cold] [--gi igi] [--internal 50]`

mod host;

use host::{HostDevice, HostScene, Raster, Targets};
use shine::embed::{DispatchShape, GiCamera, GiContext, GiContextDesc, InternalResolution};
use std::error::Error;
use std::sync::atomic::Ordering;
use std::time::Instant;

/// Frames rendered; the camera turns a little each frame.
const FRAMES: u32 = 6;
/// Radians the camera turns per frame about the scene's vertical axis.
const ORBIT_PER_FRAME: f32 = 0.05;

fn main() -> Result<(), Box<dyn Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let cold = args.iter().any(|a| a == "--cold");
    let option = |name: &str| {
        args.iter()
            .position(|a| a == name)
            .map(|i| {
                args.get(i + 1)
                    .cloned()
                    .ok_or(format!("{name} needs a value"))
            })
            .transpose()
    };
    let technique = option("--gi")?.unwrap_or_else(|| "hvl".into());
    let internal = match option("--internal")? {
        Some(p) => InternalResolution::from_percent(p.parse()?)?,
        None => InternalResolution::Full,
    };
    // The output path: the first argument that is neither an option nor an option's value.
    let output = args
        .iter()
        .enumerate()
        .find(|(i, a)| {
            !a.starts_with("--")
                && (*i == 0 || !["--gi", "--internal"].contains(&args[i - 1].as_str()))
        })
        .map(|(_, a)| a.clone())
        .unwrap_or_else(|| "host_gbuffer.png".into());
    let extent = [256, 256];
    let scene = shine_scene::Scene::builtin("cornell-box")?;

    let host = HostDevice::new(true)?;
    let targets = Targets::new(&host, extent)?;
    let host_scene = HostScene::new(&host, &scene)?;
    let raster = Raster::new(&host)?;
    let (direct, gi) = {
        // shine on the host's device, allocating from the host's allocator.
        let device = shine::gpu::Device::from_raw(host.lend(true))?;
        let ms = |start: Instant| start.elapsed().as_secs_f64() * 1e3;
        let start = Instant::now();
        let mut desc = GiContextDesc::new(extent, &technique)?;
        desc.internal_resolution = internal;
        let mut gi = GiContext::new(&device, &desc)?;
        println!("GiContext::new {:.1} ms", ms(start));
        let start = Instant::now();
        gi.set_scene(&scene, 0.0)?;
        println!("set_scene {:.1} ms", ms(start));
        if !cold {
            let start = Instant::now();
            gi.warm_up(DispatchShape::default())?;
            println!("warm_up {:.1} ms", ms(start));
        }
        let mut previous = None;
        for frame in 0..FRAMES {
            let (view, projection) = host::camera(&scene, extent, frame as f32 * ORBIT_PER_FRAME);
            let (previous_view, previous_projection) = previous.unwrap_or((view, projection));
            previous = Some((view, projection));
            let start = Instant::now();
            let cb = host.begin()?;
            raster.record(&host, cb, &targets, &host_scene, projection * view);
            let camera = GiCamera {
                view,
                projection,
                jitter: [0.0; 2],
                previous_view,
                previous_projection,
            };
            // Every image in the state the raster left it (host/raster.rs `Targets::dispatch`).
            gi.dispatch(cb, &targets.dispatch(u64::from(frame), camera))?;
            host.submit_and_wait(cb)?;
            println!("frame {}/{FRAMES} {:.1} ms", frame + 1, ms(start));
        }
        let timings = gi.timings()?;
        let last = timings.iter().map(|t| t.frame).max();
        let gpu_ns: f64 = timings
            .iter()
            .filter(|t| Some(t.frame) == last)
            .map(|t| t.end_ns - t.begin_ns)
            .sum();
        println!(
            "{technique} at {} % ({}×{}): shine's passes {:.2} ms GPU in the last frame",
            internal.percent(),
            gi.internal_extent()[0],
            gi.internal_extent()[1],
            gpu_ns * 1e-6
        );
        let direct = host::read_rgba16f(&host, &targets.direct, host::color_written())?;
        let gi_texels = host::read_rgba16f(&host, &targets.gi, host::copy_source())?;
        // Teardown order: shine's objects (context, then device), then the host's.
        drop(gi);
        drop(device);
        (direct, gi_texels)
    };
    raster.destroy(&host);
    host_scene.destroy(&host);
    targets.destroy(&host);

    let mean =
        |t: &[[f32; 4]]| t.iter().map(|p| (p[0] + p[1] + p[2]) / 3.0).sum::<f32>() / t.len() as f32;
    println!(
        "mean radiance: direct {:.4}, indirect {:.4}",
        mean(&direct),
        mean(&gi)
    );
    // The host's composite: direct + indirect, Reinhard, sRGB.
    let encode = |x: f32| {
        let x = x / (1.0 + x);
        let s = if x <= 0.003_130_8 {
            12.92 * x
        } else {
            1.055 * x.powf(1.0 / 2.4) - 0.055
        };
        (s.clamp(0.0, 1.0) * 255.0).round() as u8
    };
    let pixels: Vec<u8> = direct
        .iter()
        .zip(&gi)
        .flat_map(|(d, g)| {
            [
                encode(d[0] + g[0]),
                encode(d[1] + g[1]),
                encode(d[2] + g[2]),
                255,
            ]
        })
        .collect();
    let problems = host::VALIDATION_MESSAGES.load(Ordering::Relaxed);
    if problems > 0 {
        return Err(format!("{problems} validation messages").into());
    }
    if mean(&gi) <= 0.0 || mean(&direct) <= 0.0 {
        return Err("the frame is black".into());
    }
    // Written beside the target and renamed: no half-written file.
    let path = std::path::Path::new(&output);
    let partial = path.with_extension("partial.png");
    image::save_buffer(
        &partial,
        &pixels,
        extent[0],
        extent[1],
        image::ColorType::Rgba8,
    )?;
    std::fs::rename(&partial, path)?;
    println!("wrote {output}");
    Ok(())
}
