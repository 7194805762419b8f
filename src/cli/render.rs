//! `shine render`: headless capture of a scene, or of a sequence of its frames, to PNG
//! (tonemapped) or EXR (linear HDR).
//!
//! A sequence uploads the scene once and then sends one [`FrameUpdate`] per frame (scene
//! clock, orbiting camera): the update path a host engine drives, not a cold start per frame.

use super::CliError;
use super::frame_args::SettingsArgs;
use shine::capture::image_io::{OutputFormat, remove_stale_temporaries, write_frame};
use shine::capture::sequence::{FramePattern, orbit};
use shine::farm::frames::{FrameRange, SequenceSlice, longest_history};
use shine::farm::identity::scene_key;
use shine::farm::manifest::SequenceManifest;
use shine::farm::{self, Shard};
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, DeviceDesc};
use shine::gpu_scene::{CameraPose, FrameUpdate};
use shine::settings::Settings;
use std::path::PathBuf;

/// Frames per second of the scene clock in sequences, unless `--fps` says otherwise.
pub const DEFAULT_FPS: f32 = 60.0;

/// Arguments of `shine render`.
#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room, animated, marbles, metals, motion-sweep, motion-orbit, motion-sun, motion-crossing, motion-dolly).
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
    /// Write only frames A..B (end exclusive; A..=B includes B) of the --frames N sequence,
    /// with the same pixels as a one-process run: the frames before A are rendered unwritten
    /// to warm the histories up (--warm-up).
    #[arg(long, conflicts_with = "shard")]
    frame_range: Option<FrameRange>,
    /// Write only part i (from 0) of n of the sequence's frames, contiguous (a --frame-range).
    /// Without it and --frame-range, a Slurm array task's SLURM_ARRAY_TASK_ID and
    /// SLURM_ARRAY_TASK_COUNT give it for a sequence; --shard 0/1 renders the whole sequence
    /// there.
    #[arg(long)]
    shard: Option<Shard>,
    /// Frames rendered unwritten before the first written frame of a --frame-range or
    /// --shard (default: 8 times the longest history, docs/many-machines.md).
    #[arg(long)]
    warm_up: Option<u32>,
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
    let (slice, part) = slice_of(args, &settings)?;
    let mut renderer = Renderer::new(&device)?;
    renderer.set_scene(&scene, settings.time)?;
    // The orbit turns the scene's own camera (as posed at the first frame) about the centre of
    // the scene's bounds then.
    let first_world = scene.world_transforms_at(settings.time);
    let center = scene.bounds(&first_world).center();
    let first_camera = scene.camera_world(0, &first_world);
    let projection = scene.cameras.first().map(|c| c.projection);
    let progress = (frames > 1).then(|| {
        super::progress::bar(
            u64::from(slice.rendered.len() as u32),
            "{bar:40} {pos}/{len} frames, {eta} left",
        )
    });
    // A part of the sequence lists what it wrote in a manifest for `shine merge`.
    let mut manifest = part.as_ref().map(|_| {
        let written = [slice.written.start, slice.written.end];
        let warm_up = slice.written.start - slice.rendered.start;
        let manifest = SequenceManifest::new(run_of(args, &settings), frames, written, warm_up);
        (manifest, SequenceManifest::path_for(&pattern, written))
    });
    if let Some((_, path)) = &manifest {
        // A re-queued task finds the temporary files its killed run left: none is a frame.
        for k in slice.written.clone() {
            remove_stale_temporaries(&pattern.path(k))?;
        }
        remove_stale_temporaries(path)?;
    }
    renderer.skip_to_frame(u64::from(slice.rendered.start))?;
    let mut last_wall = std::time::Duration::ZERO;
    for k in slice.rendered.clone() {
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
        if slice.written.contains(&k) {
            let path = pattern.path(k);
            write_frame(&path, &frame.ldr, &frame.hdr)?;
            if let Some((manifest, at)) = &mut manifest {
                manifest.add(k, &path, at)?;
            }
        }
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
    if let Some((manifest, path)) = &manifest {
        manifest.write(path)?;
    }
    let written = if let Some(part) = &part {
        format!(
            "frames {}..{} of {frames} ({part}, after {} warm-up frames) to {}",
            slice.written.start,
            slice.written.end,
            slice.written.start - slice.rendered.start,
            args.output.display()
        )
    } else if frames > 1 {
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

/// The frames this process renders and writes, and, for a part of the sequence, what made it
/// one (`--frame-range`, `--shard` or the Slurm array task).
fn slice_of(
    args: &RenderArgs,
    settings: &Settings,
) -> Result<(SequenceSlice, Option<String>), CliError> {
    let frames = settings.frames;
    let (range, part) = match (args.frame_range, args.shard) {
        (Some(range), _) => (range, format!("--frame-range {range}")),
        (None, given) => {
            // A single frame is not split: an array task rendering a frame of its own keeps it.
            let (shard, from) = match given {
                None if frames == 1 => (Shard::WHOLE, "one process"),
                _ => farm::resolve(given)?,
            };
            if shard.is_whole() {
                if args.warm_up.is_some() {
                    return Err("--warm-up needs --frame-range or --shard".into());
                }
                return Ok((SequenceSlice::whole(frames), None));
            }
            let r = shard.range(frames);
            if r.is_empty() {
                return Err(format!(
                    "shard {shard} ({from}) holds no frame of a {frames}-frame sequence: use \
                     at most {frames} shards"
                )
                .into());
            }
            if given.is_none() {
                eprintln!(
                    "rendering part {shard} of the sequence, from the Slurm array task \
                     (--shard 0/1 renders it whole)"
                );
            }
            let range = FrameRange {
                start: r.start,
                end: r.end,
            };
            (range, format!("shard {shard} from {from}"))
        }
    };
    let ldr = OutputFormat::from_path(&args.output)? == OutputFormat::Png;
    let warm_up = args
        .warm_up
        .unwrap_or_else(|| SequenceSlice::warm_up(longest_history(settings, ldr)));
    Ok((SequenceSlice::new(range, frames, warm_up)?, Some(part)))
}

/// What makes two processes' frames parts of one sequence: the scene, every setting, the
/// clock, the camera path and the output files.
fn run_of(args: &RenderArgs, settings: &Settings) -> serde_json::Value {
    serde_json::json!({
        "scene": scene_key(&args.scene).unwrap_or_else(|| args.scene.clone()),
        "settings": settings,
        "fps": args.fps,
        "camera_orbit": args.camera_orbit,
        "environment": format!("{:?}", args.settings.environment()),
        "output": args.output,
    })
}
