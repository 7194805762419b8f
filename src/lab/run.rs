//! A lab run: every (scene, configuration) point measured, journaled as it goes so that an
//! interrupted run resumes, then the report and its pictures written.
//!
//! The journal, `points.jsonl` in the output directory, starts with the run's conditions and
//! gets one line per measured point or failure, flushed before the next point starts. A run
//! over a journal of other conditions is refused; a torn last line (the run was killed while
//! writing it) is dropped and that point measured again.

use std::io::Write;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};
use shine_scene::Scene;

use super::configs::{base_settings, settings_of};
use super::measure::{display_exposure, measure, write_display};
use super::truth::truths;
use super::{
    LabConfig, LabError, LabPart, LabPoint, LabReport, LabSetup, SceneFailure, page, pareto,
};
use crate::capture::image_io::write_bytes_atomically;
use crate::farm::Shard;
use crate::farm::identity::scene_key;
use crate::gpu::Device;
use crate::study::Progress;
use crate::study::temporal_plot::file_label;

/// The journal's file name in the output directory.
pub const JOURNAL: &str = "points.jsonl";

/// What a lab run measures and where it writes.
#[derive(Debug, Clone)]
pub struct LabPlan {
    /// Scenes as given (`builtin:NAME` or a path).
    pub scenes: Vec<String>,
    /// Configurations, each measured on every scene.
    pub configs: Vec<LabConfig>,
    /// The conditions.
    pub setup: LabSetup,
    /// Output directory.
    pub out: PathBuf,
    /// Where truths are cached (`None`: traced every run).
    pub cache: Option<PathBuf>,
    /// The binary's git revision.
    pub revision: String,
    /// The part of the points this run measures (`Shard::WHOLE`: all).
    pub shard: Shard,
}

impl LabPlan {
    /// The part this plan measures, `None` for the whole run.
    pub fn part(&self) -> Option<LabPart> {
        (!self.shard.is_whole()).then(|| LabPart {
            shard: self.shard,
            scenes: self.scenes.clone(),
            configs: self.configs.iter().map(|c| c.label.clone()).collect(),
        })
    }

    /// Whether this plan measures configuration `config` of scene `scene` (indices).
    fn holds(&self, scene: usize, config: usize) -> bool {
        self.part().is_none_or(|part| part.holds(scene, config))
    }
}

/// One line of the journal.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Entry {
    /// The first line: the conditions every later line was measured under.
    Setup(LabSetup),
    /// A measured point.
    Point(Box<LabPoint>),
    /// A scene, or one configuration on a scene, that could not be measured.
    Failure {
        /// The configuration's label, `None` for the whole scene.
        label: Option<String>,
        /// The scene and why.
        failure: SceneFailure,
    },
}

/// An I/O error on `path`.
fn io(path: &Path) -> impl FnOnce(std::io::Error) -> LabError + '_ {
    move |source| LabError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The journal's entries, after checking its conditions are `setup`'s; a torn last line is
/// dropped (and cut from the file).
fn read_journal(path: &Path, setup: &LabSetup) -> Result<Vec<Entry>, LabError> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(io(path)(e)),
    };
    let mut entries = Vec::new();
    let mut good = 0;
    for line in text.split_inclusive('\n') {
        let Ok(entry) = serde_json::from_str::<Entry>(line.trim_end()) else {
            break;
        };
        good += line.len();
        entries.push(entry);
    }
    if good < text.len() {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .open(path)
            .map_err(io(path))?;
        file.set_len(good as u64).map_err(io(path))?;
    }
    match entries.first() {
        None => Ok(entries),
        Some(Entry::Setup(s)) if s == setup => Ok(entries),
        Some(_) => Err(LabError::Invalid(format!(
            "{} was measured under other conditions (size, samples or sequence): use another --out or delete it",
            path.display()
        ))),
    }
}

/// Appends `entry` to the journal and flushes it to the disk.
fn append(path: &Path, entry: &Entry) -> Result<(), LabError> {
    let mut line = serde_json::to_string(entry)
        .map_err(|e| LabError::Invalid(format!("journal entry: {e}")))?;
    line.push('\n');
    let mut file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .map_err(io(path))?;
    file.write_all(line.as_bytes()).map_err(io(path))?;
    file.sync_data().map_err(io(path))
}

/// Measures every point of `plan` not already in its journal, then writes `lab.json`,
/// `lab.csv`, the truths' pictures, a Pareto plot per scene and `index.html`. A scene that
/// cannot be loaded or traced fails alone; so does a configuration a scene cannot render.
pub fn run(
    device: &Device,
    plan: &LabPlan,
    load: &dyn Fn(&str) -> Result<Scene, String>,
    progress: &mut dyn Progress,
) -> Result<LabReport, LabError> {
    if plan.configs.is_empty() || plan.scenes.is_empty() {
        return Err(LabError::Invalid(
            "a lab needs a scene and a configuration".into(),
        ));
    }
    std::fs::create_dir_all(&plan.out).map_err(io(&plan.out))?;
    let journal = plan.out.join(JOURNAL);
    let mut entries = read_journal(&journal, &plan.setup)?;
    if entries.is_empty() {
        let header = Entry::Setup(plan.setup.clone());
        append(&journal, &header)?;
        entries.push(header);
    }
    let done = |entries: &[Entry], scene: &str, label: Option<&str>| {
        entries.iter().any(|e| match e {
            Entry::Point(p) => label == Some(p.config.label.as_str()) && p.scene == scene,
            Entry::Failure { label: l, failure } => {
                failure.scene == scene && (l.is_none() || l.as_deref() == label)
            }
            Entry::Setup(_) => false,
        })
    };
    let base = base_settings(&plan.setup);
    let mut truth_images = Vec::new();
    for (scene_index, scene_name) in plan.scenes.iter().enumerate() {
        if !(0..plan.configs.len()).any(|c| plan.holds(scene_index, c)) {
            continue;
        }
        let todo: Vec<&LabConfig> = plan
            .configs
            .iter()
            .enumerate()
            .filter(|(c, config)| {
                plan.holds(scene_index, *c) && !done(&entries, scene_name, Some(&config.label))
            })
            .map(|(_, config)| config)
            .collect();
        progress.stage(scene_name, 1 + todo.len() as u64);
        let fail = |reason: String| Entry::Failure {
            label: None,
            failure: SceneFailure {
                scene: scene_name.clone(),
                reason,
            },
        };
        let scene = match load(scene_name) {
            Ok(scene) => scene,
            Err(reason) => {
                let entry = fail(reason);
                append(&journal, &entry)?;
                entries.push(entry);
                continue;
            }
        };
        let key = scene_key(scene_name).unwrap_or_else(|| file_label(scene_name));
        let truth = truths(
            device,
            &scene,
            &key,
            &plan.setup,
            plan.cache.as_deref(),
            &mut |m| progress.advance(0, &format!("truth: {m}")),
        );
        let truth = match truth {
            Ok(t) => t,
            Err(e) => {
                let entry = fail(format!("truth: {e}"));
                append(&journal, &entry)?;
                entries.push(entry);
                continue;
            }
        };
        progress.advance(1, "truth");
        let truth_png = format!("truth/{}.png", file_label(scene_name));
        write_display(
            &plan.out,
            &truth_png,
            &truth.still,
            display_exposure(&truth.still),
        )?;
        truth_images.push((scene_name.clone(), truth_png));
        for config in todo {
            progress.advance(0, &config.label);
            let measured = settings_of(&base, config)
                .map_err(|e| LabError::Invalid(e.to_string()))
                .and_then(|settings| {
                    measure(
                        device,
                        &scene,
                        scene_name,
                        &plan.setup,
                        config,
                        &settings,
                        &truth,
                        &plan.out,
                    )
                });
            let entry = match measured {
                Ok(point) => Entry::Point(Box::new(point)),
                Err(e) => Entry::Failure {
                    label: Some(config.label.clone()),
                    failure: SceneFailure {
                        scene: scene_name.clone(),
                        reason: format!("`{}`: {e}", config.label),
                    },
                },
            };
            append(&journal, &entry)?;
            entries.push(entry);
            progress.advance(1, &config.label);
        }
    }
    progress.finish();
    let report = assemble(device, plan, &entries, truth_images);
    write_outputs(&plan.out, &report)?;
    Ok(report)
}

/// The report of the journal's entries, points ordered by scene then configuration.
fn assemble(
    device: &Device,
    plan: &LabPlan,
    entries: &[Entry],
    truths: Vec<(String, String)>,
) -> LabReport {
    let mut points = Vec::new();
    for (scene_index, scene) in plan.scenes.iter().enumerate() {
        for (config_index, config) in plan.configs.iter().enumerate() {
            if !plan.holds(scene_index, config_index) {
                continue;
            }
            let found = entries.iter().find_map(|e| match e {
                Entry::Point(p) if &p.scene == scene && p.config.label == config.label => {
                    Some(p.as_ref().clone())
                }
                _ => None,
            });
            points.extend(found);
        }
    }
    let failures = entries
        .iter()
        .filter_map(|e| match e {
            Entry::Failure { failure, .. } => Some(failure.clone()),
            _ => None,
        })
        .collect();
    LabReport {
        device: device.info().name.clone(),
        driver: device.info().driver.clone(),
        revision: plan.revision.clone(),
        setup: plan.setup.clone(),
        points,
        failures,
        truths,
        part: plan.part(),
    }
}

/// `lab.csv`: one line per point with its configuration, device, driver and revision.
pub fn csv(report: &LabReport) -> String {
    let mut out = String::from(
        "scene,label,set,frame_ms,relative_rmse,energy_ratio,flip,flicker,cold_flicker,\
         truth_flicker,truth_flicker_noise_free,flicker_ratio,sequence_rmse,cold_rmse,lag,clock,device,driver,revision\n",
    );
    let quote = |s: &str| format!("\"{}\"", s.replace('"', "\"\""));
    for p in &report.points {
        let set: Vec<String> = p
            .config
            .set
            .iter()
            .map(|(k, v)| format!("{k}={v}"))
            .collect();
        let (e, m) = (&p.error, &p.motion);
        out.push_str(&format!(
            "{},{},{},{:.4},{:.5},{:.5},{:.5},{:.6},{:.6},{:.6},{:.6},{:.3},{:.5},{:.5},{:.5},{},{},{},{}\n",
            quote(&p.scene),
            quote(&p.config.label),
            quote(&set.join(" ")),
            p.cost.frame_ms,
            e.relative_rmse,
            e.energy_ratio,
            e.flip,
            m.flicker,
            m.cold_flicker,
            m.truth_flicker,
            m.truth_flicker_noise_free,
            m.flicker_ratio,
            m.sequence_rmse,
            m.cold_rmse,
            m.lag,
            p.cost.clock,
            quote(&report.device),
            quote(&report.driver),
            quote(&report.revision),
        ));
    }
    out
}

/// Writes `lab.json`, `lab.csv`, each scene's Pareto plot and `index.html` into `out`.
pub fn write_outputs(out: &Path, report: &LabReport) -> Result<(), LabError> {
    let json = serde_json::to_string_pretty(report)
        .map_err(|e| LabError::Invalid(format!("lab.json: {e}")))?;
    write_bytes_atomically(&out.join("lab.json"), json.as_bytes())?;
    write_bytes_atomically(&out.join("lab.csv"), csv(report).as_bytes())?;
    let mut fronts = Vec::new();
    let mut plots = Vec::new();
    for scene in report.scenes() {
        let points: Vec<&LabPoint> = report.points_of(scene).collect();
        let front = pareto::front(&points);
        let plot = format!("pareto-{}.png", file_label(scene));
        pareto::write_plot(&out.join(&plot), scene, &points, &front)?;
        fronts.push((scene.to_owned(), front));
        plots.push((scene.to_owned(), plot));
    }
    page::write_page(out, report, &fronts, &plots)?;
    Ok(())
}
