//! The frame-budget mode: from the lab's results for this device, the configuration with the
//! least error whose measured frame cost fits a budget (`shine render --budget-ms`,
//! `GiContextDesc::budget_ms`).
//!
//! Results live in one table per device and driver under the cache directory
//! (`lab-results/DEVICE-DRIVER.json`): every lab run adds its points, keyed by scene (the
//! built-in's name or the file's hash) and frame size, since cost and error depend on both.
//! Where the table has nothing for a scene and size, a quick lab fills it: each of
//! [`candidates`] rendered on the first frame, timed over a few frames and compared with a
//! path-traced truth of that frame ([`quick_lab`]).
//!
//! The pick is on the measured front: no other point is both as fast and more accurate, since
//! it would fit the budget too. With no point within budget the cheapest is taken, and said.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use shine_scene::Scene;

use super::configs::{base_settings, settings_of};
use super::measure::{cost, create_parent};
use super::{LabConfig, LabError, LabPoint, LabSetup};
use crate::capture::image_compare;
use crate::capture::image_io::write_bytes_atomically;
use crate::frame::renderer::Renderer;
use crate::gpu::Device;
use crate::gpu_scene::FrameUpdate;
use crate::reference::{PathTracer, ReferenceParams};

/// One configuration's measured cost and error on one scene at one size.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BudgetEntry {
    /// The scene's key ([`crate::farm::identity::scene_key`]).
    pub scene: String,
    /// Frame width and height it was measured at.
    pub extent: [u32; 2],
    /// The configuration.
    pub config: LabConfig,
    /// Median frame time, ms.
    pub frame_ms: f64,
    /// Relative RMSE of the frame against the truth.
    pub relative_rmse: f64,
}

/// The results of one device and driver.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct BudgetTable {
    /// Every measured configuration.
    pub entries: Vec<BudgetEntry>,
}

/// What the budget mode chose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BudgetChoice {
    /// The budget asked for, ms.
    pub budget_ms: f64,
    /// The chosen configuration.
    pub config: LabConfig,
    /// Its measured frame time, ms.
    pub frame_ms: f64,
    /// Its measured relative RMSE.
    pub relative_rmse: f64,
    /// Whether it fits the budget (false: nothing did, this is the cheapest).
    pub fits: bool,
    /// How many configurations it was chosen from.
    pub candidates: usize,
}

impl BudgetChoice {
    /// One line for the user: what was chosen and why.
    pub fn describe(&self) -> String {
        let why = if self.fits {
            format!(
                "the least error of {} configurations within {:.2} ms",
                self.candidates, self.budget_ms
            )
        } else {
            format!(
                "no configuration of {} fits {:.2} ms: the cheapest",
                self.candidates, self.budget_ms
            )
        };
        format!(
            "budget: `{}` ({:.2} ms, relative RMSE {:.3}), {why}",
            self.config.label, self.frame_ms, self.relative_rmse
        )
    }
}

/// The entry with the least error among those within `budget_ms`, or the cheapest when none
/// fits (`fits` false); `None` for no entries. Entries without a finite cost and error are
/// never chosen. Ties go to the cheaper, then the first.
pub fn pick(entries: &[&BudgetEntry], budget_ms: f64) -> Option<BudgetChoice> {
    let by = |key: fn(&BudgetEntry) -> (f64, f64)| {
        move |a: &&&BudgetEntry, b: &&&BudgetEntry| {
            key(a)
                .partial_cmp(&key(b))
                .unwrap_or(std::cmp::Ordering::Equal)
        }
    };
    let measured: Vec<&&BudgetEntry> = entries
        .iter()
        .filter(|e| e.relative_rmse.is_finite() && e.frame_ms.is_finite())
        .collect();
    let within = measured
        .iter()
        .copied()
        .filter(|e| e.frame_ms <= budget_ms)
        .min_by(by(|e| (e.relative_rmse, e.frame_ms)));
    let (chosen, fits) = match within {
        Some(e) => (e, true),
        None => (
            measured
                .iter()
                .copied()
                .min_by(by(|e| (e.frame_ms, e.relative_rmse)))?,
            false,
        ),
    };
    Some(BudgetChoice {
        budget_ms,
        config: chosen.config.clone(),
        frame_ms: chosen.frame_ms,
        relative_rmse: chosen.relative_rmse,
        fits,
        candidates: measured.len(),
    })
}

/// The pick for `scene` at `extent`: from that scene's entries, or, for `None`, from every
/// scene's at that size, each configuration judged by its mean error and its slowest cost.
pub fn choose(
    table: &BudgetTable,
    scene: Option<&str>,
    extent: [u32; 2],
    budget_ms: f64,
) -> Option<BudgetChoice> {
    let sized = table.entries.iter().filter(|e| e.extent == extent);
    if let Some(scene) = scene {
        let entries: Vec<&BudgetEntry> = sized.filter(|e| e.scene == scene).collect();
        return pick(&entries, budget_ms);
    }
    let mut merged: Vec<(BudgetEntry, usize)> = Vec::new();
    for e in sized {
        match merged
            .iter_mut()
            .find(|(m, _)| m.config.label == e.config.label)
        {
            Some((m, n)) => {
                m.frame_ms = m.frame_ms.max(e.frame_ms);
                m.relative_rmse += e.relative_rmse;
                *n += 1;
            }
            None => merged.push((e.clone(), 1)),
        }
    }
    let merged: Vec<BudgetEntry> = merged
        .into_iter()
        .map(|(mut m, n)| {
            m.relative_rmse /= n as f64;
            m
        })
        .collect();
    pick(&merged.iter().collect::<Vec<_>>(), budget_ms)
}

/// The table's file for the device named `device` with driver `driver` under `cache`.
pub fn table_path(cache: &Path, device: &str, driver: &str) -> PathBuf {
    let name = crate::study::temporal_plot::file_label(&format!("{device}-{driver}"));
    cache.join("lab-results").join(format!("{name}.json"))
}

/// The table at `path` (empty when there is none yet).
pub fn load_table(path: &Path) -> Result<BudgetTable, LabError> {
    match std::fs::read_to_string(path) {
        Ok(text) => serde_json::from_str(&text).map_err(|e| {
            LabError::Invalid(format!(
                "{}: {e} (delete it to measure again)",
                path.display()
            ))
        }),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(BudgetTable::default()),
        Err(source) => Err(LabError::Io {
            path: path.to_owned(),
            source,
        }),
    }
}

/// Adds `entries` to the table at `path`, replacing those of the same scene, size and label.
pub fn record(path: &Path, entries: &[BudgetEntry]) -> Result<(), LabError> {
    let mut table = load_table(path)?;
    table.entries.retain(|old| {
        !entries.iter().any(|e| {
            e.scene == old.scene && e.extent == old.extent && e.config.label == old.config.label
        })
    });
    table.entries.extend_from_slice(entries);
    create_parent(path)?;
    let json = serde_json::to_string_pretty(&table)
        .map_err(|e| LabError::Invalid(format!("budget table: {e}")))?;
    write_bytes_atomically(path, json.as_bytes())?;
    Ok(())
}

/// The entries of lab points measured under `setup` (`key` maps a point's scene to its key).
pub fn entries_of(
    points: &[LabPoint],
    setup: &LabSetup,
    key: &dyn Fn(&str) -> String,
) -> Vec<BudgetEntry> {
    points
        .iter()
        .map(|p| BudgetEntry {
            scene: key(&p.scene),
            extent: setup.extent,
            config: p.config.clone(),
            frame_ms: p.cost.frame_ms,
            relative_rmse: p.error.relative_rmse,
        })
        .collect()
}

/// The quick lab's candidates: each technique at its defaults, amortised over 2×2 cells
/// (paper 001) and, for the two that trace most, cheaper: fewer HVLs, fewer AAF samples.
pub fn candidates() -> Vec<LabConfig> {
    let config = |label: &str, set: &[(&str, &str)]| LabConfig {
        label: label.to_owned(),
        set: set
            .iter()
            .map(|(k, v)| ((*k).to_owned(), (*v).to_owned()))
            .collect(),
    };
    vec![
        config("hvl", &[("gi", "hvl")]),
        config("hvl slices=4", &[("gi", "hvl"), ("hvl.slices", "4")]),
        config("hvl count=100", &[("gi", "hvl"), ("hvl.count", "100")]),
        config("igi", &[("gi", "igi")]),
        config("igi slices=4", &[("gi", "igi"), ("igi.slices", "4")]),
        config("aaf", &[("gi", "aaf")]),
        config("aaf spp_max=16", &[("gi", "aaf"), ("aaf.spp_max", "16")]),
        config("aaf slices=4", &[("gi", "aaf"), ("aaf.slices", "4")]),
    ]
}

/// Samples per pixel of the quick lab's truth.
pub const QUICK_TRUTH_SPP: u32 = 256;
/// Frames the quick lab times each candidate over, after one warm-up frame.
pub const QUICK_FRAMES: u32 = 3;

/// Measures `configs` on the first frame of `scene` at `extent` (time 0): the still error
/// against a [`QUICK_TRUTH_SPP`]-spp truth and the median of [`QUICK_FRAMES`] frames. Returns
/// the entries (keyed `key`) and the seconds it took. A candidate that fails is left out.
pub fn quick_lab(
    device: &Device,
    scene: &Scene,
    key: &str,
    extent: [u32; 2],
    configs: &[LabConfig],
) -> Result<(Vec<BudgetEntry>, f64), LabError> {
    let start = Instant::now();
    let setup = LabSetup {
        extent,
        warmup: 1,
        cost_frames: QUICK_FRAMES,
        ..LabSetup::default()
    };
    let params = ReferenceParams {
        width: extent[0],
        height: extent[1],
        jitter: false,
        emissive_lighting: false,
        ..ReferenceParams::default()
    };
    let mut tracer = PathTracer::new(device, scene, 0.0, &params)?;
    tracer.update(&FrameUpdate::at(0.0))?;
    tracer.accumulate(QUICK_TRUTH_SPP)?;
    let truth = tracer.read()?.full;
    let base = base_settings(&setup);
    let mut entries = Vec::new();
    for config in configs {
        let Ok(settings) = settings_of(&base, config) else {
            continue;
        };
        let mut renderer = Renderer::new(device)?;
        renderer.set_scene(scene, 0.0)?;
        let Ok(frame) = renderer.render(&settings) else {
            continue;
        };
        let (relative_rmse, _) = image_compare::relative_error(&frame.hdr, &truth)
            .map_err(|e| LabError::Invalid(format!("comparison failed: {e}")))?;
        let cost = cost(device, &mut renderer, &settings, &setup)?;
        entries.push(BudgetEntry {
            scene: key.to_owned(),
            extent,
            config: config.clone(),
            frame_ms: cost.frame_ms,
            relative_rmse,
        });
    }
    Ok((entries, start.elapsed().as_secs_f64()))
}

/// [`quick_lab`] of the [`candidates`], recorded in the table at `table` when there is one:
/// what the budget mode does where the table has nothing for a scene and size.
pub fn fill(
    device: &Device,
    scene: &Scene,
    key: &str,
    extent: [u32; 2],
    table: Option<&Path>,
) -> Result<(Vec<BudgetEntry>, f64), LabError> {
    let (entries, seconds) = quick_lab(device, scene, key, extent, &candidates())?;
    if let Some(path) = table {
        record(path, &entries)?;
    }
    Ok((entries, seconds))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn entry(label: &str, ms: f64, error: f64) -> BudgetEntry {
        BudgetEntry {
            scene: "s".into(),
            extent: [64, 64],
            config: LabConfig {
                label: label.into(),
                set: vec![("gi".into(), "hvl".into())],
            },
            frame_ms: ms,
            relative_rmse: error,
        }
    }

    /// A fake cost table: the pick is the least error within budget, on the front, and the
    /// cheapest (said so) when nothing fits.
    #[test]
    fn the_pick_fits_the_budget_and_lies_on_the_front() {
        let table = [
            entry("fast", 2.0, 0.40),
            entry("dominated", 5.0, 0.45),
            entry("mid", 6.0, 0.25),
            entry("slow", 12.0, 0.10),
            entry("nan", 1.0, f64::NAN),
        ];
        let refs: Vec<&BudgetEntry> = table.iter().collect();
        for (budget, want, fits) in [
            (8.0, "mid", true),
            (5.5, "fast", true),
            (100.0, "slow", true),
            (1.5, "fast", false),
            (0.5, "fast", false),
        ] {
            let choice = pick(&refs, budget).unwrap();
            assert_eq!(
                (choice.config.label.as_str(), choice.fits),
                (want, fits),
                "{budget}"
            );
            assert!(!choice.fits || choice.frame_ms <= budget);
            // On the front: no entry is at least as fast and strictly more accurate.
            if choice.fits {
                assert!(!table.iter().any(
                    |e| e.frame_ms <= choice.frame_ms && e.relative_rmse < choice.relative_rmse
                ));
            }
        }
        assert!(pick(&[], 8.0).is_none());
        assert!(
            pick(&refs, 0.5)
                .unwrap()
                .describe()
                .contains("no configuration")
        );
    }

    #[test]
    fn scenes_merge_by_mean_error_and_slowest_cost() {
        let mut a = entry("x", 2.0, 0.2);
        let mut b = entry("x", 4.0, 0.4);
        b.scene = "t".into();
        let c = entry("y", 3.0, 0.1);
        a.scene = "s".into();
        let table = BudgetTable {
            entries: vec![a, b, c],
        };
        let any = choose(&table, None, [64, 64], 3.5).unwrap();
        assert_eq!(any.config.label, "y");
        let x = choose(&table, None, [64, 64], 100.0).unwrap();
        assert_eq!(x.config.label, "y");
        let only_s = choose(&table, Some("t"), [64, 64], 10.0).unwrap();
        assert_eq!(only_s.config.label, "x");
        assert!((only_s.frame_ms - 4.0).abs() < 1e-12);
        assert!(choose(&table, None, [32, 32], 10.0).is_none());
    }

    #[test]
    fn tables_round_trip_and_replace_entries() {
        let path = std::env::temp_dir().join(format!("shine-budget-{}.json", std::process::id()));
        record(&path, &[entry("a", 1.0, 0.5), entry("b", 2.0, 0.4)]).unwrap();
        record(&path, &[entry("a", 3.0, 0.3)]).unwrap();
        let table = load_table(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert_eq!(table.entries.len(), 2);
        let a = table
            .entries
            .iter()
            .find(|e| e.config.label == "a")
            .unwrap();
        assert_eq!(a.frame_ms, 3.0);
        assert!(load_table(&path).unwrap().entries.is_empty());
    }
}
