//! `shine study temporal`: GI modes judged in motion (issues 18 and 23). On an animated
//! sequence, for each mode (a label and settings), the cost per frame, the error of every
//! frame against a path-traced truth of that frame, and the flicker: the RMS of the second
//! temporal difference of the frames over their mean. The truth is a fixed-seed, unjittered
//! path-traced sequence (emissive surfaces lighting nothing, as the raster GI), whose own
//! flicker is reported as the yardstick. Each mode is rendered twice: as a sequence (one
//! renderer, its history kept from frame to frame) and cold (every frame a fresh scene at its
//! time, no history), so that what history buys and what it costs in accuracy show side by
//! side. Plots and per-pixel flicker maps are written by [`TemporalReport::write_pictures`].

use std::time::Instant;

use glam::Vec2;
use serde::Serialize;
use shine_scene::Scene;
use shine_scene::bvh::{Bvh, Ray};

use super::metrics;
use super::switch_off::SwitchOff;
use super::{Progress, StudyError};
use crate::capture::image_io::HdrImage;
use crate::frame::renderer::Renderer;
use crate::gpu::Device;
use crate::gpu_scene::FrameUpdate;
use crate::gpu_scene::frame_update::FrameState;
use crate::passes::composite::Component;
use crate::passes::gbuffer::unjittered_camera_view;
use crate::reference::{PathTracer, ReferenceParams};
use crate::settings::Settings;

/// One mode of the study: a label and the settings it renders with.
#[derive(Clone, Debug)]
pub struct TemporalMode {
    /// Shown in the table and the plot.
    pub label: String,
    /// The frame settings (size and GI technique included).
    pub settings: Settings,
}

/// The sequence the modes are judged on.
#[derive(Clone, Debug)]
pub struct TemporalConfig {
    /// Frames of the sequence (at least 3: flicker needs a second difference).
    pub frames: u32,
    /// Scene clock rate.
    pub fps: f32,
    /// Scene time of the first frame.
    pub time: f32,
    /// Samples per pixel of each truth frame.
    pub truth_spp: u32,
    /// Frames rendered before the measured ones (not measured: temporal state settles).
    pub warmup: u32,
    /// Judge the indirect light alone: every mode renders `output.component = indirect` and
    /// the truth is its indirect light (issue 43: what pops is the GI).
    pub indirect: bool,
    /// A light switched off halfway through the measured frames (truth, sequences and cold
    /// frames alike), and each mode's frames until its light is gone reported.
    pub switch_off: Option<SwitchOff>,
}

/// What the study measured for one mode.
#[derive(Clone, Debug, Serialize)]
pub struct ModeResult {
    /// The mode's label.
    pub label: String,
    /// Median wall time of a frame of the sequence (submission to readback), ms.
    pub ms_per_frame: f64,
    /// Mean over the sequence's frames of the relative RMSE against the truth frame.
    pub relative_rmse: f64,
    /// RMS of the second temporal difference over the mean of the sequence's frames.
    pub flicker: f64,
    /// Flicker where the truth holds still: over the pixels of [`TemporalReport::still`].
    pub still_flicker: f64,
    /// Flicker over the pixels no moving object covers ([`TemporalReport::uncovered`]).
    pub uncovered_flicker: f64,
    /// The cold frames' flicker over [`TemporalReport::uncovered`].
    pub cold_uncovered_flicker: f64,
    /// With [`TemporalConfig::switch_off`]: what the sequence keeps of the light at each frame
    /// from the switch on ([`SwitchOff::residual`]).
    pub switch_off_residual: Vec<f64>,
    /// With [`TemporalConfig::switch_off`]: frames until the light is gone from the sequence
    /// ([`SwitchOff::frames_until_gone`]; 1: in the first frame without it).
    pub switch_off_frames: Option<u32>,
    /// Relative RMSE of the sequence's last frame.
    pub last_rmse: f64,
    /// Flicker of the cold frames (each rendered from a fresh scene at its time).
    pub cold_flicker: f64,
    /// Flicker of the cold frames where the truth holds still.
    pub cold_still_flicker: f64,
    /// Relative RMSE of the last cold frame (what the sequence's last frame is judged by).
    pub cold_last_rmse: f64,
    /// Mean over the cold frames of the relative RMSE against the truth frame: the lag a
    /// history adds is `relative_rmse - cold_relative_rmse`.
    pub cold_relative_rmse: f64,
    /// The sequence's flicker at each inner frame k (1..frames-1): RMS over pixels of
    /// I(k+1) - 2 I(k) + I(k-1) over the mean of the frames.
    pub flicker_by_frame: Vec<f64>,
    /// Per-pixel flicker of the sequence (row-major): RMS over frames of the second
    /// difference, over the mean of the frames.
    #[serde(skip)]
    pub flicker_map: Vec<f32>,
}

/// The study's report.
#[derive(Clone, Debug, Serialize)]
pub struct TemporalReport {
    /// The scene.
    pub scene: String,
    /// Frames measured.
    pub frames: u32,
    /// Frames rendered before them, not measured.
    pub warmup: u32,
    /// Width and height of the frames.
    pub extent: [u32; 2],
    /// Flicker of the path-traced truth (the yardstick), its noise taken out: two fixed-seed
    /// truths A and B, `sqrt(mean(d2(A)·d2(B)))` over the mean ([`flicker_noise_free`]).
    pub truth_flicker: f64,
    /// Flicker of truth A alone, noise included (what one fixed-seed truth reads).
    pub truth_flicker_one_seed: f64,
    /// Where the truth holds still: the pixels whose per-pixel truth flicker is at most its
    /// median (moving objects and their shadows are out; surfaces only a moving light
    /// changes are in). Row-major.
    #[serde(skip)]
    pub still: Vec<bool>,
    /// The truth's flicker over [`TemporalReport::still`].
    pub truth_still_flicker: f64,
    /// The pixels no moving object covers in any frame (every pixel where nothing but lights
    /// and the camera moves), from primary rays through the scene's BVH at each frame's time:
    /// a silhouette crossing a pixel is a true jump that would hide popping on the walls.
    /// Row-major.
    #[serde(skip)]
    pub uncovered: Vec<bool>,
    /// Share of the pixels in [`TemporalReport::uncovered`].
    pub uncovered_share: f64,
    /// The truth's flicker over [`TemporalReport::uncovered`], its noise taken out.
    pub truth_uncovered_flicker: f64,
    /// The truth's flicker at each inner frame.
    pub truth_flicker_by_frame: Vec<f64>,
    /// Per-pixel flicker of the truth.
    #[serde(skip)]
    pub truth_flicker_map: Vec<f32>,
    /// The light switched off, if one was.
    pub switch_off: Option<SwitchOff>,
    /// One result per mode.
    pub modes: Vec<ModeResult>,
}

/// `√MSE / mean(b)` of `a` against `b` over every pixel ([`metrics::image_error`]); 0 when `b`
/// is black.
fn relative_rmse(a: &HdrImage, b: &HdrImage) -> f64 {
    let rgb =
        |i: &HdrImage| -> Vec<[f32; 3]> { i.texels.iter().map(|t| [t[0], t[1], t[2]]).collect() };
    let mask = vec![true; b.texels.len()];
    metrics::image_error(&rgb(a), &rgb(b), &mask).map_or(0.0, |e| e.relative_rmse)
}

/// Mean of the frames' rgb channels (at least 1e-12).
pub(crate) fn frames_mean(frames: &[HdrImage]) -> f64 {
    let (mut sum, mut m) = (0.0f64, 0usize);
    for f in frames {
        for t in &f.texels {
            sum += f64::from(t[0] + t[1] + t[2]);
            m += 3;
        }
    }
    (sum / m.max(1) as f64).max(1e-12)
}

/// Squared second temporal difference `I[k+1] - 2 I[k] + I[k-1]` of every pixel (summed over
/// rgb) at each inner frame k.
fn second_differences(frames: &[HdrImage]) -> Vec<Vec<f64>> {
    frames
        .windows(3)
        .map(|w| {
            w[0].texels
                .iter()
                .zip(&w[1].texels)
                .zip(&w[2].texels)
                .map(|((a, b), c)| {
                    (0..3)
                        .map(|k| f64::from(c[k] - 2.0 * b[k] + a[k]).powi(2))
                        .sum()
                })
                .collect()
        })
        .collect()
}

/// RMS of the second temporal difference `I[k+1] - 2 I[k] + I[k-1]` over the mean of the
/// frames (rgb); 0 for fewer than 3 frames.
pub fn flicker(frames: &[HdrImage]) -> f64 {
    let d = second_differences(frames);
    let n: usize = d.iter().map(|f| 3 * f.len()).sum();
    if n == 0 {
        return 0.0;
    }
    let se: f64 = d.iter().flatten().sum();
    (se / n as f64).sqrt() / frames_mean(frames)
}

/// The flicker of a sequence whose two renders `a` and `b` differ only by their noise (two
/// seeds): the issue's `mean(d2(A)²) − mean((d2(A) − d2(B))²)/2`, symmetrised in A and B,
/// which is `mean(d2(A)·d2(B))`: independent noise averages out of the product and the
/// signal's second difference stays. Its square root over the mean of both; 0 where the noise
/// leaves a negative estimate.
pub fn flicker_noise_free(a: &[HdrImage], b: &[HdrImage]) -> f64 {
    let pixels = a.first().map_or(0, |f| f.texels.len());
    flicker_noise_free_masked(a, b, &vec![true; pixels])
}

/// [`flicker_noise_free`] over the pixels where `mask` holds (the product and the mean both
/// over them).
pub fn flicker_noise_free_masked(a: &[HdrImage], b: &[HdrImage], mask: &[bool]) -> f64 {
    let (mut product, mut n) = (0.0f64, 0usize);
    for (wa, wb) in a.windows(3).zip(b.windows(3)) {
        let pixels = wa[0].texels.len();
        for i in (0..pixels).filter(|&i| mask.get(i).copied().unwrap_or(false)) {
            for k in 0..3 {
                let d = |w: &[HdrImage]| {
                    f64::from(w[2].texels[i][k] - 2.0 * w[1].texels[i][k] + w[0].texels[i][k])
                };
                product += d(wa) * d(wb);
                n += 1;
            }
        }
    }
    if n == 0 {
        return 0.0;
    }
    let mean_of = |frames: &[HdrImage]| masked_mean(frames, mask).unwrap_or(0.0).max(1e-12);
    let mean = 0.5 * (mean_of(a) + mean_of(b));
    (product / n as f64).max(0.0).sqrt() / mean
}

/// The pixels of a `width`×`height` view of `scene` that no moving object covers at any of
/// `times`: each pixel centre's primary ray (unjittered camera of that time) through the
/// scene's BVH posed at that time hits an instance whose world matrix is the same at every
/// time, or nothing. Skinned or morphing meshes count as still (the motion scenes have none).
pub fn uncovered_pixels(scene: &Scene, times: &[f32], width: u32, height: u32) -> Vec<bool> {
    let states: Vec<FrameState> = times
        .iter()
        .map(|&t| FrameState::evaluate(scene, &FrameUpdate::at(t)))
        .collect();
    let instances: Vec<Vec<[[f32; 4]; 4]>> = states
        .iter()
        .map(|s| {
            scene
                .instances(&s.pose.world)
                .iter()
                .map(|i| i.world)
                .collect()
        })
        .collect();
    let moving: Vec<bool> = (0..instances.first().map_or(0, Vec::len))
        .map(|i| instances.iter().any(|w| w.get(i) != instances[0].get(i)))
        .collect();
    let mut uncovered = vec![true; (width * height) as usize];
    for state in &states {
        let bvh = Bvh::from_scene(scene, &state.pose.world);
        let view = unjittered_camera_view(state, width, height);
        let to_world = view.view_proj().inverse();
        for (p, keep) in uncovered.iter_mut().enumerate() {
            let (x, y) = ((p as u32 % width) as f32, (p as u32 / width) as f32);
            let ndc = Vec2::new(
                2.0 * (x + 0.5) / width as f32 - 1.0,
                2.0 * (y + 0.5) / height as f32 - 1.0,
            );
            let near = to_world.project_point3(ndc.extend(0.0));
            let far = to_world.project_point3(ndc.extend(0.5));
            let ray = Ray {
                origin: near,
                dir: far - near,
                t_min: 0.0,
                t_max: f32::INFINITY,
            };
            if let Some(hit) = bvh.intersect(&ray) {
                let instance = bvh.triangles[hit.triangle].instance as usize;
                *keep &= !moving.get(instance).copied().unwrap_or(false);
            }
        }
    }
    uncovered
}

/// [`flicker`] over the pixels where `mask` holds (RMS and mean both over them).
pub fn flicker_masked(frames: &[HdrImage], mask: &[bool]) -> f64 {
    let d = second_differences(frames);
    let (mut se, mut n) = (0.0f64, 0usize);
    for f in &d {
        for (v, _) in f.iter().zip(mask).filter(|(_, m)| **m) {
            se += v;
            n += 3;
        }
    }
    match masked_mean(frames, mask) {
        Some(mean) if n > 0 => (se / n as f64).sqrt() / mean.max(1e-12),
        _ => 0.0,
    }
}

/// Mean of the frames' rgb channels over the pixels where `mask` holds; `None` where it holds
/// nowhere.
fn masked_mean(frames: &[HdrImage], mask: &[bool]) -> Option<f64> {
    let (mut sum, mut m) = (0.0f64, 0usize);
    for f in frames {
        for (t, _) in f.texels.iter().zip(mask).filter(|(_, m)| **m) {
            sum += f64::from(t[0] + t[1] + t[2]);
            m += 3;
        }
    }
    (m > 0).then(|| sum / m as f64)
}

/// The pixels whose value in `map` is at most its (lower) median: the calmer half.
pub fn calm_half(map: &[f32]) -> Vec<bool> {
    let mut sorted = map.to_vec();
    sorted.sort_by(f32::total_cmp);
    let median = sorted
        .get(sorted.len().saturating_sub(1) / 2)
        .copied()
        .unwrap_or(0.0);
    map.iter().map(|v| *v <= median).collect()
}

/// [`flicker`] at each inner frame, and per pixel (row-major), both over the mean of all the
/// frames.
pub fn flicker_parts(frames: &[HdrImage]) -> (Vec<f64>, Vec<f32>) {
    let d = second_differences(frames);
    let mean = frames_mean(frames);
    let by_frame = d
        .iter()
        .map(|f| (f.iter().sum::<f64>() / (3 * f.len().max(1)) as f64).sqrt() / mean)
        .collect();
    let pixels = d.first().map_or(0, Vec::len);
    let map = (0..pixels)
        .map(|i| {
            let se: f64 = d.iter().map(|f| f[i]).sum();
            ((se / (3 * d.len()) as f64).sqrt() / mean) as f32
        })
        .collect();
    (by_frame, map)
}

/// Runs the study: the truth sequence, then every mode's.
pub fn run(
    device: &Device,
    scene: &Scene,
    name: &str,
    config: &TemporalConfig,
    modes: &[TemporalMode],
    progress: &mut dyn Progress,
) -> Result<TemporalReport, StudyError> {
    let fps_ok = config.fps.is_finite() && config.fps > 0.0;
    if config.frames < 3 || !fps_ok || config.truth_spp == 0 {
        return Err(StudyError::Invalid(
            "a temporal study needs at least 3 frames, a positive --fps and --truth-spp".into(),
        ));
    }
    let first = modes
        .first()
        .ok_or_else(|| StudyError::Invalid("no mode to study".into()))?;
    // Frame k of the sequence (warm-up included) shows time + k / fps.
    let at = |k: u32| config.time + k as f32 / config.fps;
    let times: Vec<f32> = (config.warmup..config.warmup + config.frames)
        .map(at)
        .collect();
    // The measured frames' updates: the scene as animated, the switched-off light off.
    let updates: Vec<FrameUpdate> = times
        .iter()
        .enumerate()
        .map(|(k, &t)| match &config.switch_off {
            Some(off) => off.update(scene, k, t),
            None => FrameUpdate::at(t),
        })
        .collect();
    progress.stage("truth", 2 * u64::from(config.frames));
    let params = ReferenceParams {
        width: first.settings.width,
        height: first.settings.height,
        jitter: false,
        emissive_lighting: false,
        ..ReferenceParams::default()
    };
    let truth = truth_sequence(device, scene, &updates, config, &params, progress)?;
    let truth_b = truth_sequence(
        device,
        scene,
        &updates,
        config,
        &ReferenceParams {
            seed: params.seed.wrapping_add(1),
            ..params
        },
        progress,
    )?;
    let (truth_flicker_by_frame, truth_flicker_map) = flicker_parts(&truth);
    let still = calm_half(&truth_flicker_map);
    let uncovered = uncovered_pixels(scene, &times, first.settings.width, first.settings.height);
    let mut results = Vec::new();
    for mode in modes {
        progress.stage(&mode.label, 2 * u64::from(config.frames));
        let mut settings = mode.settings.clone();
        if config.indirect {
            settings.output.component = Component::Indirect;
        }
        let mut renderer = Renderer::new(device)?;
        renderer.set_scene(scene, config.time)?;
        for k in 0..config.warmup {
            renderer.update(&FrameUpdate::at(at(k)))?;
            renderer.render(&settings)?;
        }
        let (mut images, mut ms) = (Vec::new(), Vec::new());
        for update in &updates {
            renderer.update(update)?;
            let start = Instant::now();
            let frame = renderer.render(&settings)?;
            ms.push(start.elapsed().as_secs_f64() * 1e3);
            images.push(frame.hdr);
            progress.advance(1, &mode.label);
        }
        // Cold: every frame from a fresh scene at its time, so nothing carries over.
        let mut cold = Vec::new();
        for update in &updates {
            renderer.set_scene(scene, update.time)?;
            renderer.update(update)?;
            cold.push(renderer.render(&settings)?.hdr);
            progress.advance(1, &format!("{} (cold)", mode.label));
        }
        ms.sort_by(f64::total_cmp);
        let error = |frames: &[HdrImage]| {
            frames
                .iter()
                .zip(&truth)
                .map(|(a, b)| relative_rmse(a, b))
                .sum::<f64>()
                / frames.len() as f64
        };
        let last = |frames: &[HdrImage]| match (frames.last(), truth.last()) {
            (Some(a), Some(b)) => relative_rmse(a, b),
            _ => 0.0,
        };
        let (flicker_by_frame, flicker_map) = flicker_parts(&images);
        let switch_off_residual = config
            .switch_off
            .map(|off| off.residual(&images, &cold))
            .unwrap_or_default();
        results.push(ModeResult {
            switch_off_frames: config
                .switch_off
                .and_then(|_| SwitchOff::frames_until_gone(&switch_off_residual)),
            switch_off_residual,
            label: mode.label.clone(),
            ms_per_frame: ms[ms.len() / 2],
            relative_rmse: error(&images),
            flicker: flicker(&images),
            still_flicker: flicker_masked(&images, &still),
            uncovered_flicker: flicker_masked(&images, &uncovered),
            cold_uncovered_flicker: flicker_masked(&cold, &uncovered),
            last_rmse: last(&images),
            cold_flicker: flicker(&cold),
            cold_still_flicker: flicker_masked(&cold, &still),
            cold_last_rmse: last(&cold),
            cold_relative_rmse: error(&cold),
            flicker_by_frame,
            flicker_map,
        });
    }
    progress.finish();
    Ok(TemporalReport {
        scene: name.to_owned(),
        frames: config.frames,
        warmup: config.warmup,
        extent: [first.settings.width, first.settings.height],
        truth_flicker: flicker_noise_free(&truth, &truth_b),
        truth_flicker_one_seed: flicker(&truth),
        truth_still_flicker: flicker_masked(&truth, &still),
        still,
        uncovered_share: uncovered.iter().filter(|u| **u).count() as f64
            / uncovered.len().max(1) as f64,
        truth_uncovered_flicker: flicker_noise_free_masked(&truth, &truth_b, &uncovered),
        uncovered,
        truth_flicker_by_frame,
        truth_flicker_map,
        switch_off: config.switch_off,
        modes: results,
    })
}

/// One fixed-seed truth sequence of `updates`: the full frame, or its indirect light when
/// `config.indirect`.
fn truth_sequence(
    device: &Device,
    scene: &Scene,
    updates: &[FrameUpdate],
    config: &TemporalConfig,
    params: &ReferenceParams,
    progress: &mut dyn Progress,
) -> Result<Vec<HdrImage>, StudyError> {
    let first = updates.first().map_or(config.time, |u| u.time);
    let mut tracer = PathTracer::new(device, scene, first, params)?;
    let mut frames = Vec::with_capacity(updates.len());
    for update in updates {
        tracer.update(update)?;
        tracer.accumulate(config.truth_spp)?;
        let images = tracer.read()?;
        frames.push(if config.indirect {
            images.indirect
        } else {
            images.full
        });
        progress.advance(1, &format!("path tracing (seed {})", params.seed));
    }
    Ok(frames)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2×1 image of one grey level per pixel.
    fn frame(a: f32, b: f32) -> HdrImage {
        HdrImage {
            width: 2,
            height: 1,
            texels: vec![[a, a, a, 1.0], [b, b, b, 1.0]],
        }
    }

    #[test]
    fn a_steady_change_does_not_flicker_and_a_pop_does() {
        let ramp: Vec<HdrImage> = (0..5).map(|k| frame(1.0 + k as f32, 2.0)).collect();
        assert_eq!(flicker(&ramp), 0.0);
        // Pixel 0 pops to 3 at frame 2 of five frames at 1: second differences 2, -4, 2 there.
        let pop: Vec<HdrImage> = [1.0, 1.0, 3.0, 1.0, 1.0]
            .iter()
            .map(|&a| frame(a, 1.0))
            .collect();
        let mean = (7.0 + 5.0) / 10.0;
        let expected = ((4.0 + 16.0 + 4.0) / 6.0f64).sqrt() / mean;
        assert!((flicker(&pop) - expected).abs() < 1e-9, "{}", flicker(&pop));
        let (by_frame, map) = flicker_parts(&pop);
        assert_eq!(by_frame.len(), 3);
        assert!((by_frame[1] - (16.0f64 / 2.0).sqrt() / mean).abs() < 1e-9);
        assert_eq!(map[1], 0.0);
        // Over the still pixel alone, nothing flickers; over both, as everywhere.
        let still = calm_half(&map);
        assert_eq!(still, vec![false, true]);
        assert_eq!(flicker_masked(&pop, &still), 0.0);
        assert!((flicker_masked(&pop, &[true, true]) - flicker(&pop)).abs() < 1e-12);
    }

    #[test]
    fn two_seeds_take_the_noise_out_of_the_truths_flicker() {
        // A steady ramp under independent noise: one seed flickers by its noise alone, the
        // pair reads nearly nothing; a pop common to both seeds is kept.
        let noise = |seed: u32, k: u32| {
            let mut h = u64::from(seed) << 32 | u64::from(k);
            h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            0.05 * (((h ^ (h >> 31)) >> 40) as f32 / (1u64 << 24) as f32 - 0.5)
        };
        let seq = |seed: u32, pop: f32| -> Vec<HdrImage> {
            (0..32u32)
                .map(|k| HdrImage {
                    width: 256,
                    height: 1,
                    texels: (0..256u32)
                        .map(|i| {
                            let jump = if k == 15 { pop } else { 0.0 };
                            let a = 1.0 + 0.01 * k as f32 + jump + noise(seed, 256 * k + i);
                            [a, a, a, 1.0]
                        })
                        .collect(),
                })
                .collect()
        };
        let (a, b) = (seq(1, 0.0), seq(2, 0.0));
        assert!(flicker(&a) > 0.02, "{}", flicker(&a));
        assert!(flicker_noise_free(&a, &b) < 0.3 * flicker(&a));
        let (a, b) = (seq(1, 0.5), seq(2, 0.5));
        let estimate = flicker_noise_free(&a, &b);
        assert!(
            estimate > 0.5 * flicker(&a),
            "{estimate} against {}",
            flicker(&a)
        );
    }
}
