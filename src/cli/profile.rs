//! `shine profile`: per-pass time over N frames after a warm-up, as a table, JSON or CSV, and
//! optionally a Chrome trace (Perfetto opens it). Passes are timed by GPU timestamps, or on
//! CPU devices (lavapipe) by the host clock around each pass submitted alone.

use super::CliError;
use super::frame_args::SettingsArgs;
use super::render::DEFAULT_FPS;
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, DeviceDesc};
use shine::gpu_scene::FrameUpdate;
use shine::profile::report::{PassClock, ProfileReport, ReportFormat, write_chrome_trace};
use shine::settings::Settings;
use std::path::PathBuf;

/// Fewest measured frames whose 95th percentile is not their slowest (the nearest-rank p95 of
/// n frames is the ⌈0.95 n⌉-th, which is the n-th for every n below 20).
pub const P95_MIN_FRAMES: u32 = 20;

/// The git revision the binary was built from (`build.rs`; "unknown" outside a checkout).
pub const REVISION: &str = env!("SHINE_GIT_REV");

/// Arguments of `shine profile`.
#[derive(clap::Args, Debug)]
pub struct ProfileArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME`.
    scene: String,
    /// Frames measured.
    #[arg(long, default_value_t = 60)]
    frames: u32,
    /// Frames rendered first and not measured (pipeline creation, first-dispatch costs).
    #[arg(long, default_value_t = 5)]
    warmup: u32,
    /// Report format: table, json or csv.
    #[arg(long, default_value = "table")]
    format: String,
    /// Also write a Chrome trace (JSON) of the measured frames.
    #[arg(long)]
    trace: Option<PathBuf>,
    /// Pass clock: `gpu` (timestamps), `host` (each pass submitted alone, timed on the host)
    /// or `auto` (host on CPU devices such as lavapipe, whose timestamps miss compute work).
    #[arg(long, default_value = "auto")]
    clock: String,
    #[command(flatten)]
    settings: SettingsArgs,
}

/// Renders warm-up + measured frames and reports the measured ones.
pub fn run(args: &ProfileArgs) -> Result<(), CliError> {
    let format: ReportFormat = args.format.parse()?;
    if args.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    let settings = args.settings.resolve()?;
    let scene = args.settings.load_scene(&args.scene)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let clock = match args.clock.as_str() {
        "auto" => PassClock::for_device(device.info().device_type),
        "gpu" => PassClock::Gpu,
        "host" => PassClock::Host,
        other => {
            return Err(format!("unknown --clock `{other}`: expected auto, gpu or host").into());
        }
    };
    if clock == PassClock::Gpu
        && PassClock::for_device(device.info().device_type) == PassClock::Host
    {
        eprintln!(
            "warning: {} is a CPU device whose timestamps miss compute work: passes read near 0 ms \
             with --clock gpu; --clock host (or auto) times each pass alone",
            device.info().name
        );
    }
    if args.frames < P95_MIN_FRAMES {
        eprintln!(
            "note: the p95 of {} frames is their slowest; measure at least {P95_MIN_FRAMES} frames \
             for a p95 below the maximum",
            args.frames
        );
    }
    let mut renderer = Renderer::new(&device)?;
    // A cold start (what every frame of an animated scene cost before the update path), timed
    // once for comparison with the measured frames' `update …` passes.
    let cold = std::time::Instant::now();
    renderer.set_scene(&scene, settings.time)?;
    device.wait_idle()?;
    let cold_ms = cold.elapsed().as_secs_f64() * 1e3;
    // Frames advance the scene clock as a sequence does (`shine render --frames`).
    let time = settings.time;
    let timings = renderer.render_timed(&settings, args.warmup + args.frames, clock, &|k| {
        FrameUpdate::at(time + k as f32 / DEFAULT_FPS)
    })?;
    for warning in renderer.warnings() {
        eprintln!("warning: {warning}");
    }
    let first_frame = timings.iter().map(|t| t.frame).min().unwrap_or(0);
    let measured: Vec<_> = timings
        .into_iter()
        .filter(|t| t.frame >= first_frame + u64::from(args.warmup))
        .collect();
    let report = ProfileReport::from_timings(&measured, clock)?;
    if format == ReportFormat::Json {
        println!("{}", with_run(&report, args, &settings, &device)?);
    } else {
        println!("{}", report.format(format)?);
    }
    // Medians per pass; the frame's median is of whole frames.
    let update_ms: f64 = report
        .passes
        .iter()
        .filter(|p| p.name.starts_with("update"))
        .map(|p| p.time.median_ms)
        .sum();
    let frame_ms = report.frame.median_ms;
    eprintln!(
        "update passes: {update_ms:.3} ms of a {frame_ms:.3} ms frame ({:.2}%); a cold set_scene took {cold_ms:.1} ms",
        100.0 * update_ms / frame_ms.max(1e-9),
    );
    if let Some(path) = &args.trace {
        write_chrome_trace(path, &measured)?;
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// The JSON report with what was measured beside it, so a saved report can be compared with
/// another: `run` holds the scene, resolution, device, driver, settings and git revision.
fn with_run(
    report: &ProfileReport,
    args: &ProfileArgs,
    settings: &Settings,
    device: &Device,
) -> Result<String, CliError> {
    let json = |e: serde_json::Error| CliError::from(format!("profile JSON: {e}"));
    let mut value = serde_json::to_value(report).map_err(json)?;
    let info = device.info();
    let run = serde_json::json!({
        "scene": args.scene,
        "width": settings.width,
        "height": settings.height,
        "device": info.name,
        "driver": info.driver,
        "revision": REVISION,
        "settings": settings,
    });
    if let Some(object) = value.as_object_mut() {
        object.insert("run".into(), run);
    }
    serde_json::to_string_pretty(&value).map_err(json)
}
