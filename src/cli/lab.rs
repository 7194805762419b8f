//! `shine lab SCENE…`: every technique's error, cost and flicker side by side (src/lab/).

use std::path::{Path, PathBuf};

use super::CliError;
use super::frame_args::{EnvironmentArgs, load_scene};
use shine::farm::identity::scene_key;
use shine::farm::{self, Shard};
use shine::gpu::{Device, DeviceDesc};
use shine::lab::budget;
use shine::lab::configs::{default_space, load};
use shine::lab::run::{LabPlan, run};
use shine::lab::{LabReport, LabSetup};
use shine::profile::roofline::cache_dir;
use shine::study::Progress;

/// Arguments of `shine lab`.
#[derive(clap::Args, Debug)]
pub struct LabArgs {
    /// Scenes: `builtin:NAME` or .gltf/.glb paths. A scene that cannot be read fails alone.
    #[arg(required = true)]
    scenes: Vec<String>,
    /// Configurations file (TOML, `[[config]]` entries with `label` and `set`); default: every
    /// technique at the ends and middle of its declared ranges, one setting at a time.
    #[arg(long)]
    configs: Option<PathBuf>,
    /// Output directory: lab.json, lab.csv, the Pareto plots, index.html, and the journal an
    /// interrupted run resumes from.
    #[arg(long, default_value = "out/lab")]
    out: PathBuf,
    /// Frame width.
    #[arg(long, default_value_t = 64)]
    width: u32,
    /// Frame height.
    #[arg(long, default_value_t = 64)]
    height: u32,
    /// Samples per pixel of the still truth.
    #[arg(long, default_value_t = LabSetup::default().truth_spp)]
    truth_spp: u32,
    /// Samples per pixel of each frame of the two truth sequences.
    #[arg(long, default_value_t = LabSetup::default().sequence_spp)]
    sequence_spp: u32,
    /// Frames of the moving-light sequence (at least 3).
    #[arg(long, default_value_t = LabSetup::default().sequence_frames)]
    sequence_frames: u32,
    /// Frames timed per configuration.
    #[arg(long, default_value_t = LabSetup::default().cost_frames)]
    cost_frames: u32,
    /// Print the configurations and exit.
    #[arg(long)]
    list: bool,
    /// Measure only part i (from 0) of n of the points (scene by scene, configuration by
    /// configuration, contiguous), into `--out`/part-i-of-n, for `shine merge`. Without it, a
    /// Slurm array task's SLURM_ARRAY_TASK_ID and SLURM_ARRAY_TASK_COUNT give it.
    #[arg(long)]
    shard: Option<Shard>,
    #[command(flatten)]
    environment: EnvironmentArgs,
}

/// One bar over the whole run, with an ETA; points a resumed run skips count as done.
struct Bar {
    bar: indicatif::ProgressBar,
    per_scene: u64,
    scenes_started: u64,
}

impl Progress for Bar {
    fn stage(&mut self, name: &str, total: u64) {
        self.bar
            .set_position(self.scenes_started * self.per_scene + self.per_scene - total);
        self.bar.reset_eta();
        self.scenes_started += 1;
        self.bar.set_prefix(name.to_owned());
    }

    fn advance(&mut self, steps: u64, message: &str) {
        self.bar.set_message(message.to_owned());
        self.bar.inc(steps);
    }

    fn finish(&mut self) {
        self.bar.finish_and_clear();
    }
}

/// Runs the lab and prints each scene's front.
pub fn run_lab(args: &LabArgs) -> Result<(), CliError> {
    let setup = LabSetup {
        extent: [args.width, args.height],
        truth_spp: args.truth_spp,
        sequence_spp: args.sequence_spp,
        sequence_frames: args.sequence_frames,
        cost_frames: args.cost_frames,
        ..LabSetup::default()
    };
    if args.width == 0 || args.height == 0 || args.sequence_frames < 3 || args.truth_spp == 0 {
        return Err(
            "a lab needs a non-empty frame, --sequence-frames ≥ 3 and --truth-spp ≥ 1".into(),
        );
    }
    let configs = match &args.configs {
        Some(path) => load(path, &setup)?,
        None => default_space(&setup),
    };
    if args.list {
        for c in &configs {
            let set: Vec<String> = c.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
            println!("{:<40} {}", c.label, set.join(" "));
        }
        println!("{} configurations", configs.len());
        return Ok(());
    }
    let (shard, from) = farm::resolve(args.shard)?;
    let out = if shard.is_whole() {
        args.out.clone()
    } else {
        args.out.join(part_folder(shard))
    };
    let device = Device::new(&DeviceDesc::from_env())?;
    let cache = cache_dir();
    let plan = LabPlan {
        scenes: args.scenes.clone(),
        configs,
        setup,
        out: out.clone(),
        cache: cache.clone(),
        revision: super::profile::REVISION.to_owned(),
        shard,
    };
    if !shard.is_whole() {
        let total = (plan.scenes.len() * plan.configs.len()) as u32;
        let points = shard.range(total);
        eprintln!(
            "part {shard} from {from}: points {}..{} of {total}",
            points.start, points.end
        );
    }
    let per_scene = 1 + plan.configs.len() as u64;
    let bar = super::progress::bar(
        per_scene * plan.scenes.len() as u64,
        "{prefix:>20} {bar:40} {pos}/{len} {msg}, {elapsed} elapsed, {eta} left",
    );
    let mut progress = Bar {
        bar,
        per_scene,
        scenes_started: 0,
    };
    let start = std::time::Instant::now();
    let environment = &args.environment;
    let report = run(
        &device,
        &plan,
        &|scene| load_scene(scene, environment).map_err(|e| e.to_string()),
        &mut progress,
    )?;
    // A part leaves the device's budget table to the merge: parts running at once would
    // overwrite each other's entries.
    if let (Some(cache), true) = (&cache, shard.is_whole()) {
        record_budget(cache, &report)?;
    }
    print_fronts(&report);
    for f in &report.failures {
        eprintln!("failed: {}: {}", f.scene, f.reason);
    }
    eprintln!(
        "{} points in {:.1} min; wrote {}",
        report.points.len(),
        start.elapsed().as_secs_f64() / 60.0,
        out.join("index.html").display()
    );
    Ok(())
}

/// The folder of part `shard` under a lab's `--out`.
pub fn part_folder(shard: Shard) -> String {
    format!("part-{}-of-{}", shard.index, shard.count)
}

/// Adds `report`'s points to its device's budget table in `cache`.
pub fn record_budget(cache: &Path, report: &LabReport) -> Result<(), CliError> {
    let key = |s: &str| scene_key(s).unwrap_or_else(|| s.to_owned());
    let entries = budget::entries_of(&report.points, &report.setup, &key);
    let table = budget::table_path(cache, &report.device, &report.driver);
    budget::record(&table, &entries)?;
    Ok(())
}

/// Each scene's Pareto front, fastest first.
fn print_fronts(report: &LabReport) {
    for scene in report.scenes() {
        let points: Vec<_> = report.points_of(scene).collect();
        println!("{scene}: front of {} points", points.len());
        println!(
            "  {:<36} {:>9} {:>8} {:>8} {:>8}",
            "configuration", "ms", "rel.RMSE", "FLIP", "flicker"
        );
        for i in shine::lab::pareto::front(&points) {
            let p = points[i];
            let ratio = match p.motion.flicker_ratio {
                r if r > 0.0 => format!("{r:.1}×"),
                _ => "n/a".to_owned(),
            };
            println!(
                "  {:<36} {:>9.2} {:>8.3} {:>8.3} {:>8}",
                p.config.label, p.cost.frame_ms, p.error.relative_rmse, p.error.flip, ratio
            );
        }
    }
}
