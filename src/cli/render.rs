//! `shine render`: headless capture of a scene, or of a sequence of its frames, to PNG
//! (tonemapped) or EXR (linear HDR).
//!
//! A sequence uploads the scene once and then sends one [`FrameUpdate`] per frame (scene
//! clock, orbiting camera): the update path a host engine drives, not a cold start per frame.

use super::CliError;
use super::frame_args::SettingsArgs;
use shine::capture::image_io::{OutputFormat, write_frame};
use shine::capture::sequence::{FramePattern, orbit};
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, DeviceDesc};
use shine::gpu_scene::{CameraPose, FrameUpdate};
use std::path::PathBuf;

/// Frames per second of the scene clock in sequences, unless `--fps` says otherwise.
pub const DEFAULT_FPS: f32 = 60.0;

/// Arguments of `shine render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room, animated, marbles).
    scene: String,
    /// Output image: .png (tonemapped, sRGB) or .exr (linear HDR). With --frames N > 1 the
    /// name needs a frame field, %d or %04d (out/frame_%04d.png), and every frame is written.
    #[arg(short, long)]
    output: PathBuf,
    #[arg(long, help = super::frame_args::with_default(
        "Frames to render; frame k shows the scene at --time + k / --fps",
        "frames",
    ))]
    frames: Option<u32>,
    /// Frames per second of the scene clock.
    #[arg(long, default_value_t = DEFAULT_FPS)]
    fps: f32,
    /// Turn the camera by this many degrees about the vertical axis through the scene's
    /// centre over the sequence (frame k at k / N of it: 360 loops seamlessly). Meant for
    /// scenes seen from outside: a camera inside a room leaves it.
    #[arg(long)]
    camera_orbit: Option<f32>,
    #[command(flatten)]
    settings: SettingsArgs,
}

/// Renders and writes every frame atomically.
pub fn run(args: &RenderArgs) -> Result<(), CliError> {
    // Refuse a bad output path, frame rate or orbit before any work.
    OutputFormat::from_path(&args.output)?;
    let mut settings = args.settings.resolve_capture()?;
    if let Some(frames) = args.frames {
        settings.set("frames", &frames.to_string())?;
        settings.validate()?;
    }
    let frames = settings.frames;
    let pattern = FramePattern::parse(&args.output, frames)?;
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err(format!("--fps {} must be a positive number", args.fps).into());
    }
    if args.camera_orbit.is_some_and(|d| !d.is_finite()) {
        return Err("--camera-orbit must be a finite number of degrees".into());
    }
    let scene = args.settings.load_scene(&args.scene)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    args.settings
        .apply_budget(&mut settings, &scene, &args.scene, &device)?;
    let mut renderer = Renderer::new(&device)?;
    renderer.set_scene(&scene, settings.time)?;
    // The orbit turns the scene's own camera (as posed at the first frame) about the centre of
    // the scene's bounds then.
    let first_world = scene.world_transforms_at(settings.time);
    let center = scene.bounds(&first_world).center();
    let first_camera = scene.camera_world(0, &first_world);
    let projection = scene.cameras.first().map(|c| c.projection);
    let progress = (frames > 1).then(|| {
        super::progress::bar(u64::from(frames), "{bar:40} {pos}/{len} frames, {eta} left")
    });
    let mut last_wall = std::time::Duration::ZERO;
    for k in 0..frames {
        let camera = match (args.camera_orbit, first_camera, projection) {
            (Some(degrees), Some(world), Some(projection)) => Some(CameraPose {
                world: orbit(world, center, degrees * k as f32 / frames as f32),
                projection,
            }),
            _ => None,
        };
        renderer.update(&FrameUpdate {
            camera,
            ..FrameUpdate::at(settings.time + k as f32 / args.fps)
        })?;
        let start = std::time::Instant::now();
        let frame = renderer.render(&settings)?;
        last_wall = start.elapsed();
        write_frame(&pattern.path(k), &frame.ldr, &frame.hdr)?;
        if let Some(bar) = &progress {
            bar.inc(1);
        }
    }
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    for warning in renderer.warnings() {
        eprintln!("warning: {warning}");
    }
    // Wall time of the last frame's render call (submission to readback): GPU timestamps
    // miss compute work on lavapipe, and `shine profile` gives the per-pass split.
    let written = if frames > 1 {
        format!("{frames} frames to {}", args.output.display())
    } else {
        pattern.path(0).display().to_string()
    };
    println!(
        "wrote {written} ({}×{}, supersampled {}×, last frame {:.2} ms from submission to \
         readback)",
        settings.width,
        settings.height,
        settings.output.ssaa_for(settings.width, settings.height),
        last_wall.as_secs_f64() * 1e3
    );
    Ok(())
}
