//! `shine reference`: the path-traced reference of a scene to an EXR (linear HDR; PNG for a
//! tonemapped preview), with a
//! progress bar and a samples-per-pixel or time budget.

use super::CliError;
use super::frame_args::{EnvironmentArgs, load_scene};
use glam::Vec3;
use shine::capture::image_io::{
    LdrImage, OutputFormat, remove_stale_temporaries, write_exr, write_png,
};
use shine::capture::tonemap::{DEFAULT_TONEMAP, encode_ldr};
use shine::farm::identity::scene_key;
use shine::farm::partial::{PartialHeader, PartialSums};
use shine::farm::{self, Shard};
use shine::gpu::{Device, DeviceDesc};
use shine::reference::{PathTracer, ReferenceImages, ReferenceParams};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Arguments of `shine reference`.
#[derive(clap::Args, Debug)]
pub struct ReferenceArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room, animated, marbles, metals, motion-sweep, motion-orbit, motion-sun, motion-crossing, motion-dolly).
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
    /// Trace only part i (from 0) of n of the --spp samples (global sample indices
    /// i·spp/n..(i+1)·spp/n) and write their sums to -o (a partial-sum file, `.part` by
    /// convention) for `shine merge`. Without it, a Slurm array task's SLURM_ARRAY_TASK_ID
    /// and SLURM_ARRAY_TASK_COUNT give it; --shard 0/1 traces the whole reference there.
    #[arg(long, conflicts_with = "seconds")]
    shard: Option<Shard>,
}

/// Which image of a reference is written.
fn component(args: &ReferenceArgs) -> &'static str {
    if args.indirect_only {
        "indirect"
    } else if args.direct_only {
        "direct"
    } else {
        "full"
    }
}

/// What makes two processes' samples parts of one reference.
fn run_of(args: &ReferenceArgs, params: &ReferenceParams) -> serde_json::Value {
    serde_json::json!({
        "scene": scene_key(&args.scene).unwrap_or_else(|| args.scene.clone()),
        "environment": format!("{:?}", args.environment),
        "spp": args.spp,
        "bounces": params.bounces,
        "jitter": params.jitter,
        "emissive_lighting": params.emissive_lighting,
        "light_sampling": params.light_sampling,
        "seed": params.seed,
        "time": args.time,
        "component": component(args),
    })
}

/// Writes `images`' `component` (`full`, `direct` or `indirect`) to `path`: linear EXR, or a
/// PNG preview (tonemapped with the default operator, sRGB-encoded).
pub(super) fn write_reference(
    path: &Path,
    images: &ReferenceImages,
    component: &str,
) -> Result<(), CliError> {
    let image = match component {
        "indirect" => &images.indirect,
        "direct" => &images.direct,
        "full" => &images.full,
        other => return Err(format!("unknown reference component `{other}`").into()),
    };
    match OutputFormat::from_path(path)? {
        OutputFormat::Exr => write_exr(path, image)?,
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
            write_png(path, &ldr)?;
        }
    }
    Ok(())
}

/// Renders the reference and writes it atomically.
pub fn run(args: &ReferenceArgs) -> Result<(), CliError> {
    let (shard, from) = farm::resolve(args.shard)?;
    // Refuse a bad output path before any work: a whole reference is an image, a part is not
    // (an array task over several scenes that meant whole references says --shard 0/1).
    if shard.is_whole() {
        OutputFormat::from_path(&args.output)?;
    } else if OutputFormat::from_path(&args.output).is_ok() {
        return Err(format!(
            "part {shard} ({from}) writes partial sums, not an image: name -o something.part \
             and join the parts with `shine merge`, or give --shard 0/1 for the whole reference"
        )
        .into());
    }
    if args.spp == 0 {
        return Err("--spp must be at least 1".into());
    }
    if !shard.is_whole() && args.seconds.is_some() {
        return Err(format!(
            "part {shard} ({from}) must trace its samples whole: --seconds would stop it early"
        )
        .into());
    }
    let samples = shard.range(args.spp);
    if samples.is_empty() {
        return Err(format!(
            "shard {shard} ({from}) holds no sample of --spp {}: use at most {} shards",
            args.spp, args.spp
        )
        .into());
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
        primary_specular: None,
    };
    if !shard.is_whole() {
        // A re-queued task finds the temporary file its killed run left: it is no part.
        remove_stale_temporaries(&args.output)?;
    }
    let scene = load_scene(&args.scene, &args.environment)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let mut tracer = PathTracer::new(&device, &scene, args.time, &params)?;
    tracer.start_at_sample(samples.start);
    let spp = samples.end - samples.start;
    let bar = super::progress::bar(
        u64::from(spp),
        "{bar:40} {pos}/{len} spp, {elapsed} elapsed, {eta} left",
    );
    let start = Instant::now();
    let step = tracer.samples_per_dispatch();
    while tracer.samples() < spp {
        // The budget stops after the submission that exceeds it: at least one always runs.
        if tracer.samples() > 0 && budget.is_some_and(|b| start.elapsed() >= b) {
            break;
        }
        let now = step.min(spp - tracer.samples());
        tracer.accumulate(now)?;
        bar.inc(u64::from(now));
    }
    bar.finish_and_clear();
    let elapsed = start.elapsed().as_secs_f64();
    let written = if shard.is_whole() {
        write_reference(&args.output, &tracer.read()?, component(args))?;
        String::new()
    } else {
        let part = PartialSums {
            header: PartialHeader {
                run: run_of(args, &params),
                shard,
                samples: [samples.start, samples.end],
                width: args.width,
                height: args.height,
            },
            sums: tracer.read_sums()?,
        };
        part.write(&args.output)?;
        format!(
            ", part {shard} from {from}: samples {}..{}",
            samples.start, samples.end
        )
    };
    let pixel_samples =
        f64::from(tracer.samples()) * f64::from(args.width) * f64::from(args.height);
    println!(
        "wrote {} ({}×{}, {} spp{written}, {} bounce(s), {:.1} s, {:.1} ns per sample per pixel)",
        args.output.display(),
        args.width,
        args.height,
        tracer.samples(),
        args.bounces,
        elapsed,
        elapsed * 1e9 / pixel_samples.max(1.0)
    );
    Ok(())
}
