//! One lab point: a configuration's still error, cost and motion on one scene.

use std::path::Path;

use shine_scene::Scene;

use super::truth::Truths;
use super::{Cost, LabConfig, LabError, LabPoint, LabSetup, Motion, REGIONS, StillError};
use crate::capture::image_compare::{self, CompareError};
use crate::capture::image_io::{HdrImage, write_png};
use crate::capture::regions::region_grid;
use crate::frame::renderer::Renderer;
use crate::gpu::Device;
use crate::gpu_scene::FrameUpdate;
use crate::profile::report::{PassClock, ProfileReport};
use crate::settings::Settings;
use crate::study::temporal::flicker;
use crate::study::temporal_plot::file_label;

/// Middle grey the display images map the truth's mean to: the FLIP maps and the PNGs show
/// the frame exposed as a person would look at it (FLIP of dim linear values says
/// little), every configuration of a scene at the truth's one exposure.
pub const DISPLAY_GREY: f32 = 0.18;

/// The exposure that maps `truth`'s mean rgb to [`DISPLAY_GREY`] (1 for a black truth).
pub fn display_exposure(truth: &HdrImage) -> f32 {
    let n = (3 * truth.texels.len()).max(1) as f64;
    let mean = truth
        .texels
        .iter()
        .map(|t| f64::from(t[0] + t[1] + t[2]))
        .sum::<f64>()
        / n;
    if mean > 0.0 {
        (f64::from(DISPLAY_GREY) / mean) as f32
    } else {
        1.0
    }
}

/// Noise-free truth flicker below which no flicker ratio is reported (0): the light holds
/// still, or the truth's noise outweighs its flicker (more `--sequence-spp` would tell).
pub const STILL_TRUTH: f64 = 1e-6;

/// `image` times `k` (alpha kept).
pub fn scaled(image: &HdrImage, k: f32) -> HdrImage {
    HdrImage {
        width: image.width,
        height: image.height,
        texels: image
            .texels
            .iter()
            .map(|t| [t[0] * k, t[1] * k, t[2] * k, t[3]])
            .collect(),
    }
}

/// A comparison error as the lab reports it.
fn compared(e: CompareError) -> LabError {
    LabError::Invalid(format!("comparison failed: {e}"))
}

/// Where a point's files go, relative to the output directory.
pub fn point_files(scene: &str, label: &str) -> (String, String) {
    let (s, l) = (file_label(scene), file_label(label));
    (format!("images/{s}/{l}.png"), format!("flip/{s}/{l}.png"))
}

/// Creates the folder `path` goes in.
pub fn create_parent(path: &Path) -> Result<(), LabError> {
    match path.parent() {
        Some(parent) => std::fs::create_dir_all(parent).map_err(|source| LabError::Io {
            path: parent.to_owned(),
            source,
        }),
        None => Ok(()),
    }
}

/// Writes `image` exposed by `k`, tonemapped, to `out/relative`.
pub fn write_display(out: &Path, relative: &str, image: &HdrImage, k: f32) -> Result<(), LabError> {
    let path = out.join(relative);
    create_parent(&path)?;
    let texels: Vec<[f32; 3]> = image.texels.iter().map(|t| [t[0], t[1], t[2]]).collect();
    crate::study::plot::write_tonemapped(&path, [image.width, image.height], &texels, k)
        .map_err(|e| LabError::Plot(e.to_string()))
}

/// Measures `config` (rendering with `settings`) on `scene` against `truths`, writing its
/// image and FLIP map under `out`.
#[allow(clippy::too_many_arguments)]
pub fn measure(
    device: &Device,
    scene: &Scene,
    scene_name: &str,
    setup: &LabSetup,
    config: &LabConfig,
    settings: &Settings,
    truths: &Truths,
    out: &Path,
) -> Result<LabPoint, LabError> {
    let mut renderer = Renderer::new(device)?;
    renderer.set_scene(scene, setup.time)?;
    renderer.update(&FrameUpdate::at(setup.time))?;
    let still = renderer.render(settings)?.hdr;
    let k = display_exposure(&truths.still);
    let (shown, truth_shown) = (scaled(&still, k), scaled(&truths.still, k));
    let error = still_error(&still, &truths.still, &shown, &truth_shown)?;
    let (image, flip_map) = point_files(scene_name, &config.label);
    write_display(out, &image, &still, k)?;
    let map = image_compare::flip_map(&shown, &truth_shown).map_err(compared)?;
    let map_path = out.join(&flip_map);
    create_parent(&map_path)?;
    write_png(&map_path, &map)?;
    let cost = cost(device, &mut renderer, settings, setup)?;
    let motion = motion(&mut renderer, scene, settings, setup, truths)?;
    Ok(LabPoint {
        scene: scene_name.to_owned(),
        config: config.clone(),
        error,
        cost,
        motion,
        image,
        flip_map,
    })
}

/// Relative RMSE, energy ratio and the per-region figures of `image` against `truth`, and
/// FLIP of the two as shown (`shown`, `truth_shown`: at the display exposure).
fn still_error(
    image: &HdrImage,
    truth: &HdrImage,
    shown: &HdrImage,
    truth_shown: &HdrImage,
) -> Result<StillError, LabError> {
    let (relative_rmse, energy_ratio) =
        image_compare::relative_error(image, truth).map_err(compared)?;
    let grid = REGIONS.min(image.width).min(image.height);
    let regions = region_grid(image, truth, grid).map_err(compared)?;
    Ok(StillError {
        relative_rmse,
        energy_ratio,
        flip: image_compare::flip(shown, truth_shown).map_err(compared)?,
        regions: regions.iter().map(|r| r.relative_rmse).collect(),
        region_energy: regions.iter().map(|r| r.energy_ratio).collect(),
    })
}

/// The frame's median time and each pass's over `cost_frames` after `warmup`, by the
/// device's clock rule (`shine profile --clock auto`).
pub fn cost(
    device: &Device,
    renderer: &mut Renderer,
    settings: &Settings,
    setup: &LabSetup,
) -> Result<Cost, LabError> {
    let clock = PassClock::for_device(device.info().device_type);
    let time = setup.time;
    let timings =
        renderer.render_timed(settings, setup.warmup + setup.cost_frames, clock, &|_| {
            FrameUpdate::at(time)
        })?;
    let first = timings.iter().map(|t| t.frame).min().unwrap_or(0);
    let measured: Vec<_> = timings
        .into_iter()
        .filter(|t| t.frame >= first + u64::from(setup.warmup))
        .collect();
    let report = ProfileReport::from_timings(&measured, clock)
        .map_err(|e| LabError::Invalid(format!("timing failed: {e}")))?;
    Ok(Cost {
        frame_ms: report.frame.median_ms,
        passes: report
            .passes
            .iter()
            .map(|p| (p.name.clone(), p.time.median_ms))
            .collect(),
        clock: match clock {
            PassClock::Gpu => "gpu",
            PassClock::Host => "host",
        }
        .to_owned(),
    })
}

/// Mean relative RMSE of `frames` against `truth`'s, frame by frame.
fn mean_error(frames: &[HdrImage], truth: &[HdrImage]) -> Result<f64, LabError> {
    let mut sum = 0.0;
    for (a, b) in frames.iter().zip(truth) {
        sum += image_compare::relative_error(a, b).map_err(compared)?.0;
    }
    Ok(sum / frames.len().max(1) as f64)
}

/// The sequence under the moving light with its history, and the same frames cold (a fresh
/// scene each, no history): flicker, error and lag.
fn motion(
    renderer: &mut Renderer,
    scene: &Scene,
    settings: &Settings,
    setup: &LabSetup,
    truths: &Truths,
) -> Result<Motion, LabError> {
    renderer.set_scene(scene, setup.time)?;
    let mut sequence = Vec::new();
    for update in &truths.updates {
        renderer.update(update)?;
        sequence.push(renderer.render(settings)?.hdr);
    }
    let mut cold = Vec::new();
    for update in &truths.updates {
        renderer.set_scene(scene, setup.time)?;
        renderer.update(update)?;
        cold.push(renderer.render(settings)?.hdr);
    }
    let truth = truths.sequence_mean();
    let (sequence_rmse, cold_rmse) = (mean_error(&sequence, &truth)?, mean_error(&cold, &truth)?);
    let yardstick = truths.noise_free_flicker();
    let own = flicker(&sequence);
    Ok(Motion {
        flicker: own,
        cold_flicker: flicker(&cold),
        truth_flicker: truths.flicker(),
        truth_flicker_noise_free: yardstick,
        flicker_ratio: if yardstick > STILL_TRUTH {
            own / yardstick
        } else {
            0.0
        },
        sequence_rmse,
        cold_rmse,
        lag: sequence_rmse - cold_rmse,
    })
}
