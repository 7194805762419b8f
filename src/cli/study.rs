//! `shine study`: quality studies. `shine study aaf SCENE` measures how many samples AAF
//! (paper 004) saves at equal error: the error-vs-spp curves of its Fig. 10 against a
//! high-sample truth, the equal-error speedup, the filter's share of the frame, and plots
//! (`shine::study::aaf`; the numbers measured so far are in docs/quality.md).

use super::CliError;
use super::frame_args::{EnvironmentArgs, load_scene};
use shine::gpu::{Device, DeviceDesc};
use shine::passes::aaf::AafParams;
use shine::study::aaf::AafStudyConfig;
use shine::study::report::StudyFormat;
use shine::study::switch_off::SwitchOff;
use shine::study::temporal::{self, TemporalConfig, TemporalMode};
use shine::study::{Progress, aaf};
use std::path::PathBuf;

/// Arguments of `shine study`.
#[derive(clap::Args, Debug)]
pub struct StudyArgs {
    #[command(subcommand)]
    study: Study,
}

#[derive(clap::Subcommand, Debug)]
enum Study {
    /// AAF (paper 004): error against spp of uniform Monte Carlo, filtered uniform Monte Carlo
    /// and AAF at several μ; the samples and time uniform sampling needs for AAF's error.
    Aaf(AafStudyArgs),
    /// GI modes in motion (paper 001): cost per frame, error against a path-traced truth of
    /// every frame, and flicker, on an animated sequence, as a sequence and cold; plots and
    /// per-pixel flicker maps beside the report.
    Temporal(TemporalStudyArgs),
}

/// Arguments of `shine study temporal`.
#[derive(clap::Args, Debug)]
pub struct TemporalStudyArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (animated, spheres, ...).
    scene: String,
    /// Frames of the sequence (at least 3).
    #[arg(long, default_value_t = 24)]
    frames: u32,
    /// Scene clock rate.
    #[arg(long, default_value_t = 24.0)]
    fps: f32,
    /// Scene time of the first frame.
    #[arg(long, default_value_t = 0.0)]
    time: f32,
    /// Image width in pixels.
    #[arg(long, default_value_t = 64)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 64)]
    height: u32,
    /// Samples per pixel of each truth frame.
    #[arg(long, default_value_t = 256)]
    truth_spp: u32,
    /// Frames rendered first and not measured (temporal state settles).
    #[arg(long, default_value_t = 4)]
    warmup: u32,
    /// Judge the indirect light alone: every mode renders `output.component=indirect`, the
    /// truth is its indirect light.
    #[arg(long)]
    indirect: bool,
    /// Switch light N (its index in the scene) off halfway through the measured frames, and
    /// report each mode's frames until its light is gone (below 5% of what it gave).
    #[arg(long, value_name = "N")]
    switch_off: Option<usize>,
    /// A mode, `LABEL=KEY=VALUE;KEY=VALUE…` (settings keys as `--set` takes them), repeated;
    /// default: `hvl=gi=hvl` and `hvl/4=gi=hvl;hvl.slices=4`.
    #[arg(long = "mode")]
    modes: Vec<String>,
    /// Output folder for plot.png, flicker-by-frame.png and flicker-LABEL.png (default:
    /// out/study-temporal-SCENE).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Report format on stdout: table or json.
    #[arg(long, default_value = "table")]
    format: String,
    #[command(flatten)]
    environment: EnvironmentArgs,
}

/// Arguments of `shine study aaf`.
#[derive(clap::Args, Debug)]
pub struct AafStudyArgs {
    /// Scene: a .gltf/.glb file or `builtin:NAME` (cornell-box, spheres, room, animated, marbles, metals, motion-sweep, motion-orbit, motion-sun, motion-crossing, motion-dolly).
    scene: String,
    /// Image width in pixels.
    #[arg(long, default_value_t = 128)]
    width: u32,
    /// Image height in pixels.
    #[arg(long, default_value_t = 128)]
    height: u32,
    /// Output folder for error.png, spp.png, beta.png, truth.png, aaf.png and uniform.png
    /// (default: out/study-aaf-SCENE).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Report format on stdout: table or json.
    #[arg(long, default_value = "table")]
    format: String,
    /// Samples per pixel of the truth (uniform Monte Carlo of the same quantity).
    #[arg(long, default_value_t = 2048)]
    truth_spp: u32,
    /// Samples per pixel of one truth render (one seed); --truth-spp is a multiple of it.
    #[arg(long, default_value_t = 128)]
    truth_chunk: u32,
    /// The uniform curves' spp levels, increasing, comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [1, 2, 4, 8, 16, 32, 64, 128, 256])]
    spp: Vec<u32>,
    /// AAF's μ values (the AAF curve), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [0.25, 0.5, 0.9, 2.0, 4.0, 8.0])]
    mu: Vec<f32>,
    /// The μ of the equal-error comparison (paper: 0.9).
    #[arg(long, default_value_t = shine_sh::aaf::DEFAULT_MU)]
    equal_error_mu: f32,
    /// Renders per curve point, each with its own seed (errors averaged, times the least).
    #[arg(long, default_value_t = 1)]
    repeats: u32,
    /// Samples per pixel of the path-traced indirect light AAF is also compared with; 0 skips
    /// it.
    #[arg(long, default_value_t = 256)]
    path_tracer_spp: u32,
    /// The first seed (every render takes the next).
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Scene time in seconds (animations).
    #[arg(long, default_value_t = 0.0)]
    time: f32,
    /// Degree of the filter's local polynomial fit (0: paper 004's gaussian).
    #[arg(long, default_value_t = shine_sh::aaf::FILTER_DEGREE)]
    filter_degree: u32,
    /// Filter the diffuse part as an irradiance vector (`aaf.irradiance_vector`; false: the
    /// paper's scalar mean).
    #[arg(long, default_value_t = aaf::frame_defaults().irradiance_vector, action = clap::ArgAction::Set)]
    irradiance_vector: bool,
    /// Roughness limit of the traced specular pass whose lobes AAF leaves out (0: AAF takes
    /// every lobe; default: a default frame's).
    #[arg(long, default_value_t = aaf::frame_defaults().specular_limit)]
    specular_limit: f32,
    #[command(flatten)]
    environment: EnvironmentArgs,
}

/// Runs the chosen study.
pub fn run(args: &StudyArgs) -> Result<(), CliError> {
    match &args.study {
        Study::Aaf(args) => run_aaf(args),
        Study::Temporal(args) => run_temporal(args),
    }
}

/// The modes of `shine study temporal`, parsed (bad ones refused before any work).
fn temporal_modes(args: &TemporalStudyArgs) -> Result<Vec<TemporalMode>, CliError> {
    let specs = if args.modes.is_empty() {
        vec![
            "hvl=gi=hvl".to_owned(),
            "hvl/4=gi=hvl;hvl.slices=4".to_owned(),
        ]
    } else {
        args.modes.clone()
    };
    specs
        .iter()
        .map(|spec| {
            let (label, rest) = spec
                .split_once('=')
                .ok_or_else(|| format!("--mode `{spec}`: expected LABEL=KEY=VALUE;…"))?;
            let mut settings = shine::Settings {
                width: args.width,
                height: args.height,
                ..shine::Settings::default()
            };
            for pair in rest.split(';').filter(|p| !p.is_empty()) {
                let (key, value) = pair
                    .split_once('=')
                    .ok_or_else(|| format!("--mode `{spec}`: `{pair}` is not KEY=VALUE"))?;
                settings.set(key.trim(), value.trim())?;
            }
            settings.validate()?;
            Ok(TemporalMode {
                label: label.to_owned(),
                settings,
            })
        })
        .collect()
}

fn run_temporal(args: &TemporalStudyArgs) -> Result<(), CliError> {
    let format: StudyFormat = args.format.parse()?;
    let modes = temporal_modes(args)?;
    let config = TemporalConfig {
        frames: args.frames,
        fps: args.fps,
        time: args.time,
        truth_spp: args.truth_spp,
        warmup: args.warmup,
        indirect: args.indirect,
        switch_off: None,
    };
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_out("temporal", &args.scene));
    let scene = load_scene(&args.scene, &args.environment)?;
    let config = TemporalConfig {
        switch_off: args
            .switch_off
            .map(|light| SwitchOff::new(&scene, light, config.frames as usize))
            .transpose()?,
        ..config
    };
    let device = Device::new(&DeviceDesc::from_env())?;
    let mut bars = Bars::default();
    let report = temporal::run(&device, &scene, &args.scene, &config, &modes, &mut bars)?;
    std::fs::create_dir_all(&out)?;
    let written = report.write_pictures(&out)?;
    match format {
        StudyFormat::Json => println!("{}", serde_json::to_string_pretty(&report)?),
        StudyFormat::Table => print!("{}", report.table()),
    }
    for path in written {
        eprintln!("wrote {}", path.display());
    }
    Ok(())
}

/// The default output folder of a study of a scene argument: `out/study-STUDY-NAME`, NAME the
/// built-in's name or the file's stem.
fn default_out(study: &str, scene: &str) -> PathBuf {
    let name = match scene.strip_prefix("builtin:") {
        Some(name) => name.to_owned(),
        None => PathBuf::from(scene)
            .file_stem()
            .map_or_else(|| "scene".to_owned(), |s| s.to_string_lossy().into_owned()),
    };
    PathBuf::from("out").join(format!("study-{study}-{name}"))
}

fn run_aaf(args: &AafStudyArgs) -> Result<(), CliError> {
    let format: StudyFormat = args.format.parse()?;
    let config = AafStudyConfig {
        extent: [args.width, args.height],
        time: args.time,
        truth_spp: args.truth_spp,
        truth_chunk: args.truth_chunk,
        uniform_spp: args.spp.clone(),
        mus: args.mu.clone(),
        mu: args.equal_error_mu,
        repeats: args.repeats,
        path_tracer_spp: args.path_tracer_spp,
        seed: args.seed,
        params: AafParams {
            filter_degree: args.filter_degree,
            irradiance_vector: args.irradiance_vector,
            specular_limit: args.specular_limit,
            ..aaf::frame_defaults()
        },
    };
    // Refuse bad numbers before loading anything.
    config.validate()?;
    let out = args
        .out
        .clone()
        .unwrap_or_else(|| default_out("aaf", &args.scene));
    let scene = load_scene(&args.scene, &args.environment)?;
    let device = Device::new(&DeviceDesc::from_env())?;
    let mut bars = Bars::default();
    let mut study = aaf::run(&device, &scene, &args.scene, &config, &mut bars)?;
    study.write_outputs(&out)?;
    println!("{}", study.report.format(format)?);
    Ok(())
}

/// Progress bars on stderr, one per stage (hidden when stderr is not a terminal).
#[derive(Default)]
struct Bars {
    bar: Option<indicatif::ProgressBar>,
}

impl Progress for Bars {
    fn stage(&mut self, name: &str, total: u64) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
        let bar = super::progress::bar(
            total,
            "{prefix:>12} {bar:40} {pos}/{len} {msg}, {elapsed} elapsed, {eta} left",
        );
        bar.set_prefix(name.to_owned());
        self.bar = Some(bar);
    }

    fn advance(&mut self, steps: u64, message: &str) {
        if let Some(bar) = &self.bar {
            bar.set_message(message.to_owned());
            bar.inc(steps);
        }
    }

    fn finish(&mut self) {
        if let Some(bar) = self.bar.take() {
            bar.finish_and_clear();
        }
    }
}
