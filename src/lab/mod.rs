//! The GI lab (issue 45): every technique's error, cost and flicker side by side, on the
//! user's scenes, and the frame-budget pick made from them.
//!
//! A lab run takes scenes and configurations ([`configs`]: every technique at the ends and
//! middle of its declared ranges, or a TOML file) and measures each pair ([`measure`]):
//!
//! - **error** of one still frame against the path-traced truth, direct and indirect light as
//!   the user sees them, emissive surfaces lighting nothing in either (relative RMSE, energy
//!   ratio, FLIP, per-region relative RMSE on a 4×4 grid);
//! - **cost**: the frame's median time and each pass's, by `shine profile`'s clock rules
//!   (GPU timestamps, or each pass alone on the host clock on CPU devices);
//! - **motion**: on a short sequence under a moving primary light, the flicker (RMS of the
//!   second temporal difference over the mean, every pixel, as `shine study temporal`) beside
//!   the truth's own (two fixed-seed, unjittered truths with their noise taken out), and the
//!   lag (the sequence's mean per-frame relative RMSE minus the same frames rendered cold).
//!
//! Truths are cached by scene, resolution, time and samples ([`truth`]); every measured point
//! is appended to a journal in the output directory so an interrupted run resumes
//! ([`run`]). The outputs are `lab.json`, `lab.csv`, a Pareto plot per scene ([`pareto`]) and
//! a self-contained `index.html` ([`page`]). [`budget`] picks, from a run's points, the
//! configuration with the least error whose measured cost fits a frame budget.

pub mod budget;
pub mod configs;
pub mod measure;
pub mod merge;
pub mod page;
pub mod pareto;
pub mod run;
pub mod truth;

use serde::{Deserialize, Serialize};

use crate::capture::image_io::ImageIoError;
use crate::frame::RenderError;

/// One configuration of the lab: a label and the settings it overrides over the lab's base
/// (`gi` and the technique's own keys).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabConfig {
    /// Unique within a run; names the point's images (`hvl`, `hvl.count=64`).
    pub label: String,
    /// `(key, value)` overrides as `--set` takes them (`("gi", "hvl")`, `("hvl.count", "64")`).
    pub set: Vec<(String, String)>,
}

impl LabConfig {
    /// The value this configuration sets for `key`, if it sets one.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.set
            .iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.as_str())
    }

    /// The GI technique list it renders with (`gi`; `hvl` when unset, the default).
    pub fn technique(&self) -> &str {
        self.get("gi").unwrap_or("hvl")
    }
}

/// A still frame against the truth.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StillError {
    /// RMSE over the truth's mean.
    pub relative_rmse: f64,
    /// Mean of the image over the truth's.
    pub energy_ratio: f64,
    /// Mean LDR-FLIP of the tonemapped images.
    pub flip: f64,
    /// Relative RMSE of each tile of a [`REGIONS`]×[`REGIONS`] grid, row-major.
    pub regions: Vec<f64>,
    /// Energy ratio of each tile, row-major.
    pub region_energy: Vec<f64>,
}

/// Side of the grid of [`StillError::regions`].
pub const REGIONS: u32 = 4;

/// What a frame costs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Cost {
    /// Median time of the measured frames, ms.
    pub frame_ms: f64,
    /// Median time of each pass, ms, in frame order.
    pub passes: Vec<(String, f64)>,
    /// `gpu` (timestamps) or `host` (each pass submitted alone).
    pub clock: String,
}

/// How the configuration holds still under a moving light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Motion {
    /// Flicker of the sequence (with its history), every pixel.
    pub flicker: f64,
    /// Flicker of the same frames rendered cold (no history), every pixel.
    pub cold_flicker: f64,
    /// Flicker of the fixed-seed, unjittered truth sequence (its noise changes little between
    /// frames where the light's paths do; a truth with caustics reads high).
    pub truth_flicker: f64,
    /// The truth's flicker with its noise taken out by a second seed (see [`truth`]; 0 where
    /// the noise outweighs it): the yardstick of issue 43.
    pub truth_flicker_noise_free: f64,
    /// `flicker / truth_flicker_noise_free`; 0 (no ratio) when that is below
    /// [`measure::STILL_TRUTH`].
    pub flicker_ratio: f64,
    /// Mean per-frame relative RMSE of the sequence against the truth of each frame.
    pub sequence_rmse: f64,
    /// The same for the cold frames.
    pub cold_rmse: f64,
    /// `sequence_rmse − cold_rmse`: what the history costs in accuracy.
    pub lag: f64,
}

/// One measured (scene, configuration) pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabPoint {
    /// The scene as given on the command line (`builtin:cornell-box`, a path).
    pub scene: String,
    /// The configuration.
    pub config: LabConfig,
    /// Still-frame error.
    pub error: StillError,
    /// Cost.
    pub cost: Cost,
    /// Motion.
    pub motion: Motion,
    /// The still frame, tonemapped (PNG), relative to the output directory.
    pub image: String,
    /// Its FLIP map against the truth (PNG, magma), relative to the output directory.
    pub flip_map: String,
}

/// A scene that could not be measured, and why (the lab goes on with the others).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneFailure {
    /// The scene as given.
    pub scene: String,
    /// What went wrong.
    pub reason: String,
}

/// The conditions of a run: what every point was measured under.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabSetup {
    /// Frame width and height.
    pub extent: [u32; 2],
    /// Samples per pixel of the still truth.
    pub truth_spp: u32,
    /// Samples per pixel of each frame of the two truth sequences.
    pub sequence_spp: u32,
    /// Frames of the moving-light sequence.
    pub sequence_frames: u32,
    /// Degrees the primary light turns per frame of the sequence.
    pub degrees_per_frame: f32,
    /// Frames timed for the cost (after [`LabSetup::warmup`]).
    pub cost_frames: u32,
    /// Frames rendered before the timed ones.
    pub warmup: u32,
    /// Scene time of the still frame and of the sequence's first.
    pub time: f32,
}

impl Default for LabSetup {
    /// 64² frames, a 1024-spp still truth and 256-spp sequence truths, 8 frames turning by
    /// 1.5° each, 5 timed frames after 2.
    fn default() -> Self {
        Self {
            extent: [64, 64],
            truth_spp: 1024,
            sequence_spp: 256,
            sequence_frames: 8,
            degrees_per_frame: 1.5,
            cost_frames: 5,
            warmup: 2,
            time: 0.0,
        }
    }
}

/// A lab run's results: `lab.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabReport {
    /// The device's name.
    pub device: String,
    /// Its driver.
    pub driver: String,
    /// The git revision of the binary.
    pub revision: String,
    /// What the points were measured under.
    pub setup: LabSetup,
    /// Every measured point, by scene then configuration.
    pub points: Vec<LabPoint>,
    /// The scenes that failed.
    pub failures: Vec<SceneFailure>,
    /// Each scene's truth (tonemapped PNG), relative to the output directory.
    pub truths: Vec<(String, String)>,
    /// Which part of a sharded run this report holds (`shine lab --shard`; `None`: the whole).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part: Option<LabPart>,
}

/// The part of a sharded lab a report holds: its shard of the run's points, numbered scene
/// by scene, configuration by configuration ([`LabPart::index`]), and the run's whole plan, so
/// that `shine merge` can tell a missing part or a part of another run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LabPart {
    /// Which part.
    pub shard: crate::farm::Shard,
    /// Every scene of the run, as given.
    pub scenes: Vec<String>,
    /// Every configuration's label, in order.
    pub configs: Vec<String>,
}

impl LabPart {
    /// The number of the point of scene `scene` and configuration `config` (indices into the
    /// run's lists).
    pub fn index(&self, scene: usize, config: usize) -> u32 {
        (scene * self.configs.len() + config) as u32
    }

    /// Whether this part measures that point.
    pub fn holds(&self, scene: usize, config: usize) -> bool {
        let total = (self.scenes.len() * self.configs.len()) as u32;
        self.shard.range(total).contains(&self.index(scene, config))
    }
}

impl LabReport {
    /// The scenes that have points, in order of first appearance.
    pub fn scenes(&self) -> Vec<&str> {
        let mut scenes: Vec<&str> = Vec::new();
        for p in &self.points {
            if !scenes.contains(&p.scene.as_str()) {
                scenes.push(&p.scene);
            }
        }
        scenes
    }

    /// The points of `scene`.
    pub fn points_of<'a>(&'a self, scene: &'a str) -> impl Iterator<Item = &'a LabPoint> + 'a {
        self.points.iter().filter(move |p| p.scene == scene)
    }
}

/// Why a lab could not run, or a point could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum LabError {
    /// A configuration file or a lab parameter is wrong (the message names the file and line).
    #[error("{0}")]
    Invalid(String),
    /// Rendering or path tracing failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// An image could not be read or written.
    #[error(transparent)]
    Image(#[from] ImageIoError),
    /// A file of the run could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A plot could not be drawn.
    #[error("cannot draw the plot {0}")]
    Plot(String),
}
