//! `shine render`: headless capture of a scene to PNG (tonemapped) or EXR (linear HDR).

use super::CliError;
use super::frame_args::SettingsArgs;
use shine::capture::image_io::{OutputFormat, write_frame};
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, DeviceDesc};
use std::path::PathBuf;

/// Frames per second of the scene clock in multi-frame renders.
const FRAME_RATE: f32 = 60.0;

/// Arguments of `shine render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room).
    scene: String,
    /// Output image: .png (tonemapped, sRGB) or .exr (linear HDR).
    #[arg(short, long)]
    output: PathBuf,
    /// Frames to render (the scene clock advances at 60 Hz from --time); the last is written.
    #[arg(long)]
    frames: Option<u32>,
    #[command(flatten)]
    settings: SettingsArgs,
}

/// Renders and writes the image atomically.
pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    // Refuse a bad output path before any work.
    OutputFormat::from_path(&args.output)?;
    let mut settings = args.settings.resolve()?;
    if let Some(frames) = args.frames {
        settings.set("frames", &frames.to_string())?;
        settings.validate()?;
    }
    let scene = args.settings.load_scene(&args.scene)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let mut renderer = Renderer::new(&device)?;
    let animated = !scene.animations.is_empty();
    let progress = (settings.frames > 1).then(|| {
        let bar = indicatif::ProgressBar::new(u64::from(settings.frames));
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {eta} left")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    let mut last = None;
    let mut last_wall = std::time::Duration::ZERO;
    for i in 0..settings.frames {
        if i == 0 || animated {
            renderer.set_scene(&scene, settings.time + i as f32 / FRAME_RATE)?;
        }
        let start = std::time::Instant::now();
        last = Some(renderer.render(&settings)?);
        last_wall = start.elapsed();
        if let Some(bar) = &progress {
            bar.inc(1);
        }
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    let frame = last.ok_or("no frame was rendered")?;
    for warning in renderer.warnings() {
        eprintln!("warning: {warning}");
    }
    write_frame(&args.output, &frame.ldr, &frame.hdr)?;
    // Wall time of the last frame's render call (submission to readback): GPU timestamps
    // miss compute work on lavapipe, and `shine profile` gives the per-pass split.
    println!(
        "wrote {} ({}×{}, last frame {:.2} ms from submission to readback)",
        args.output.display(),
        settings.width,
        settings.height,
        last_wall.as_secs_f64() * 1e3
    );
    Ok(())
}
