//! `shine profile`: per-pass time over N frames after a warm-up, as a table, JSON or CSV, and
//! optionally a Chrome trace (Perfetto opens it). Passes are timed by GPU timestamps, or on
//! CPU devices (lavapipe) by the host clock around each pass submitted alone.

use super::CliError;
use super::frame_args::SettingsArgs;
use super::render::DEFAULT_FPS;
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, DeviceDesc};
use shine::gpu_scene::FrameUpdate;
use shine::lab::budget::BudgetChoice;
use shine::profile::report::{PassClock, ProfileReport, ReportFormat, write_chrome_trace};
use shine::profile::roofline::{self, RooflineReport};
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
    /// Also set each pass that declares its work against the device's fp32 FMA peak and memory
    /// bandwidth (measured once per device by micro-kernels and cached; see
    /// docs/performance.md).
    #[arg(long)]
    roofline: bool,
    #[command(flatten)]
    settings: SettingsArgs,
}

/// Renders warm-up + measured frames and reports the measured ones.
pub fn run(args: &ProfileArgs) -> Result<(), CliError> {
    let format: ReportFormat = args.format.parse()?;
    if args.frames == 0 {
        return Err("--frames must be at least 1".into());
    }
    let mut settings = args.settings.resolve()?;
    let scene = args.settings.load_scene(&args.scene)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let budget = args
        .settings
        .apply_budget(&mut settings, &scene, &args.scene, &device)?;
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
    let total = args.warmup + args.frames;
    let bar = super::progress::bar(
        u64::from(total),
        "{bar:40} {pos}/{len} frames ({msg}), {elapsed} elapsed, {eta} left",
    );
    let timings = renderer.render_timed(&settings, total, clock, &|k| {
        bar.set_position(u64::from(k));
        bar.set_message(if k < args.warmup {
            "warm-up"
        } else {
            "measured"
        });
        FrameUpdate::at(time + k as f32 / DEFAULT_FPS)
    })?;
    bar.set_position(u64::from(total));
    bar.finish_and_clear();
    for warning in renderer.warnings() {
        eprintln!("warning: {warning}");
    }
    let first_frame = timings.iter().map(|t| t.frame).min().unwrap_or(0);
    let measured: Vec<_> = timings
        .into_iter()
        .filter(|t| t.frame >= first_frame + u64::from(args.warmup))
        .collect();
    let report = ProfileReport::from_timings(&measured, clock)?;
    let roofline = match args.roofline {
        true => Some(roofline_of(&report, &measured, &device)?),
        false => None,
    };
    if format == ReportFormat::Json {
        println!(
            "{}",
            with_run(
                &report,
                roofline.as_ref(),
                budget.as_ref(),
                args,
                &settings,
                &device
            )?
        );
    } else {
        println!("{}", report.format(format)?);
        if let Some(r) = &roofline {
            println!("{}", r.to_table());
        }
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

/// The roofline of the measured passes, with the device's peaks from the cache or measured now.
fn roofline_of(
    report: &ProfileReport,
    measured: &[shine::graph::PassTiming],
    device: &Device,
) -> Result<RooflineReport, CliError> {
    let dir = roofline::cache_dir();
    if dir.is_none() {
        eprintln!(
            "note: no cache directory (SHINE_CACHE_DIR, XDG_CACHE_HOME or HOME): the peaks are measured every run"
        );
    }
    let lookup = roofline::cached(device, dir.as_deref())?;
    let peaks = &lookup.peaks;
    if lookup.measured {
        eprintln!(
            "measured {}: {:.1} GFLOP/s fp32 FMA, {:.1} GB/s",
            peaks.device, peaks.gflops, peaks.gbps
        );
    }
    if let Some(e) = &lookup.not_cached {
        eprintln!("warning: {e}; the peaks will be measured again next time");
    }
    Ok(RooflineReport::new(report, measured, peaks))
}

/// The JSON report with what was measured beside it, so a saved report can be compared with
/// another: `run` holds the scene, resolution, device, driver, settings and git revision, and
/// `roofline` (with `--roofline`) the peaks and each declared pass against them.
fn with_run(
    report: &ProfileReport,
    roofline: Option<&RooflineReport>,
    budget: Option<&BudgetChoice>,
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
        "budget": budget,
    });
    if let Some(object) = value.as_object_mut() {
        object.insert("run".into(), run);
        if let Some(r) = roofline {
            object.insert("roofline".into(), serde_json::to_value(r).map_err(json)?);
        }
    }
    serde_json::to_string_pretty(&value).map_err(json)
}
