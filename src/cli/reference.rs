//! `shine reference`: the path-traced reference of a scene to an EXR (linear HDR; PNG for a
//! tonemapped preview), with a
//! progress bar and a samples-per-pixel or time budget.

use super::CliError;
use super::frame_args::{EnvironmentArgs, load_scene};
use glam::Vec3;
use shine::capture::image_io::{LdrImage, OutputFormat, write_exr, write_png};
use shine::capture::tonemap::{DEFAULT_TONEMAP, encode_ldr};
use shine::gpu::{Device, DeviceDesc};
use shine::reference::{PathTracer, ReferenceParams};
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Arguments of `shine reference`.
#[derive(clap::Args, Debug)]
pub struct ReferenceArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room, animated, marbles).
    scene: String,
    /// Output image: .exr (linear HDR radiance) or .png (a tonemapped preview).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    environment: EnvironmentArgs,
    /// Samples per pixel (the most, when --seconds stops earlier).
    #[arg(long, default_value_t = 256)]
    spp: u32,
    /// Time budget in seconds: stop after the submission that exceeds it.
    #[arg(long)]
    seconds: Option<f64>,
    /// Bounces after the first scattering (0: direct only; 1: one-bounce indirect).
    #[arg(long, default_value_t = 1)]
    bounces: u32,
    /// Image width in pixels.
    #[arg(long, default_value_t = 256)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 256)]
    height: u32,
    /// Write only light that scattered more than once (what GI techniques add).
    #[arg(long, conflicts_with = "direct_only")]
    indirect_only: bool,
    /// Write only light that scattered once (plus what the camera sees unscattered).
    #[arg(long)]
    direct_only: bool,
    /// Light the scene with the punctual lights and the environment only: emissive surfaces
    /// are seen but light nothing (the lights the raster GI techniques use).
    #[arg(long)]
    punctual_only: bool,
    /// Find the emissive surfaces' and the environment's light only by BRDF-sampled rays (no
    /// next-event estimation or MIS for them): the same mean with more noise, for comparisons
    #[arg(long)]
    no_light_sampling: bool,
    /// Trace through pixel centres (as the raster passes sample) instead of jittering.
    #[arg(long)]
    no_jitter: bool,
    /// Seed of the random numbers.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Scene time in seconds (animations).
    #[arg(long, default_value_t = 0.0)]
    time: f32,
}

/// Renders the reference and writes it atomically.
pub fn run(args: &ReferenceArgs) -> Result<(), CliError> {
    // Refuse a bad output path before any work.
    let format = OutputFormat::from_path(&args.output)?;
    if args.spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    let budget = match args.seconds {
        Some(s) if !(s.is_finite() && s > 0.0) => {
            return Err(format!("--seconds must be a positive number, got {s}").into());
        }
        Some(s) => Some(Duration::from_secs_f64(s)),
        None => None,
    };
    let params = ReferenceParams {
        width: args.width,
        height: args.height,
        bounces: args.bounces,
        jitter: !args.no_jitter,
        emissive_lighting: !args.punctual_only,
        lambert_only: false,
        light_sampling: !args.no_light_sampling,
        seed: args.seed,
    };
    let scene = load_scene(&args.scene, &args.environment)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let mut tracer = PathTracer::new(&device, &scene, args.time, &params)?;
    let bar = super::progress::bar(
        u64::from(args.spp),
        "{bar:40} {pos}/{len} spp, {elapsed} elapsed, {eta} left",
    );
    let start = Instant::now();
    let step = tracer.samples_per_dispatch();
    while tracer.samples() < args.spp {
        // The budget stops after the submission that exceeds it: at least one always runs.
        if tracer.samples() > 0 && budget.is_some_and(|b| start.elapsed() >= b) {
            break;
        }
        let now = step.min(args.spp - tracer.samples());
        tracer.accumulate(now)?;
        bar.inc(u64::from(now));
    }
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    let images = tracer.read()?;
    let image = if args.indirect_only {
        &images.indirect
    } else if args.direct_only {
        &images.direct
    } else {
        &images.full
    };
    match format {
        OutputFormat::Exr => write_exr(&args.output, image)?,
        // A preview: tonemapped with the default operator, sRGB-encoded.
        OutputFormat::Png => {
            let texels = image
                .texels
                .iter()
                .map(|t| encode_ldr(DEFAULT_TONEMAP, Vec3::new(t[0], t[1], t[2])))
                .collect();
            let ldr = LdrImage {
                width: image.width,
                height: image.height,
                texels,
            };
            write_png(&args.output, &ldr)?;
        }
    }
    let pixel_samples = f64::from(images.samples) * f64::from(args.width) * f64::from(args.height);
    println!(
        "wrote {} ({}×{}, {} spp, {} bounce(s), {:.1} s, {:.1} ns per sample per pixel)",
        args.output.display(),
        args.width,
        args.height,
        images.samples,
        args.bounces,
        elapsed,
        elapsed * 1e9 / pixel_samples.max(1.0)
    );
    Ok(())
}
