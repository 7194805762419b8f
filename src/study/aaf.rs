//! Paper 004's error-vs-spp study (its Fig. 10 and §6): how many samples AAF saves at equal
//! error.
//!
//! 1. **Truth**: uniform Monte Carlo of the same quantity AAF estimates (the AAF passes with
//!    `adaptive = false, filter = false`: `w` × the mean of cosine-weighted one-bounce
//!    samples, with a default frame's specular limit and hit regularisation), `truth_spp` per pixel as independent chunks of `truth_chunk` (one seed each),
//!    averaged. The chunks' spread gives the truth's own noise ([`metrics::TruthAccumulator`]).
//! 2. **Curves** (Fig. 10): the relative RMSE and energy ratio of uniform unfiltered Monte Carlo
//!    at each spp level, of uniform Monte Carlo through AAF's filter, and of AAF (adaptive and
//!    filtered) at each μ, over non-background pixels. Every render has its own seed.
//! 3. **Equal error** at the study's μ (paper: 0.9): the spp at which uniform unfiltered Monte
//!    Carlo reaches AAF's MSE ([`metrics::equal_error_spp`]), its ratio to AAF's average spp,
//!    and the ratio of times: uniform's sampling pass interpolated to that spp over AAF's five
//!    passes (each pass submitted alone and timed on the host after a warm-up frame).
//! 4. For information, AAF and the truth against the path tracer's indirect light (bounces 1,
//!    pixel centres, punctual lights), which also holds the specular indirect AAF lacks.

use std::path::{Path, PathBuf};

use shine_gpu::Device;
use shine_scene::Scene;

use super::metrics::{self, TruthAccumulator};
use super::plot::{self, Curve};
use super::report::{
    AafStudyReport, AgainstPathTracer, Bars, CurvePoint, Curves, EqualError, Maps, Setup, Truth,
};
use super::runner::{AAF_PASSES, AafFrame, AafRunner, Bench, Measured, Target};
use super::{Progress, StudyError};
use crate::passes::aaf::{self, AafParams};
use crate::reference::{self, ReferenceParams};

/// The bar on the sample speedup at equal error.
pub const SAMPLE_SPEEDUP_BAR: f64 = 5.0;
/// The bar on the filtering's share of AAF's frame.
pub const OVERHEAD_SHARE_BAR: f64 = 0.15;
/// aaf_error.png and filter_bias.png show signed errors relative to the truth's mean from
/// minus this (blue) to plus this (red).
pub const SIGNED_ERROR_RANGE: f32 = 1.0;
/// The equal-error numbers are reliable when the truth's own noise (its MSE τ²) is at most this
/// share of AAF's MSE (τ at most half AAF's RMSE).
pub const RELIABLE_NOISE_SHARE: f64 = 0.25;
/// Largest image side the study takes.
pub const MAX_EXTENT: u32 = reference::MAX_EXTENT;

/// What the study renders.
#[derive(Debug, Clone, PartialEq)]
pub struct AafStudyConfig {
    /// Image width and height.
    pub extent: [u32; 2],
    /// Scene time (animations).
    pub time: f32,
    /// The truth's samples per pixel (a multiple of `truth_chunk`).
    pub truth_spp: u32,
    /// Samples per pixel of one truth render.
    pub truth_chunk: u32,
    /// The uniform curves' spp levels.
    pub uniform_spp: Vec<u32>,
    /// AAF's μ values (the curve).
    pub mus: Vec<f32>,
    /// The μ of the equal-error comparison (added to `mus` if missing).
    pub mu: f32,
    /// Renders per curve point with different seeds (errors averaged, times the least).
    pub repeats: u32,
    /// The path tracer's spp for the comparison against it; 0: skip it.
    pub path_tracer_spp: u32,
    /// The first seed; every render takes the next.
    pub seed: u32,
    /// AAF's other parameters (a default `--gi aaf` frame's: [`frame_defaults`]); `mu`,
    /// `adaptive`, `filter`, `first_samples` and `seed` are set per render.
    pub params: AafParams,
}

impl Default for AafStudyConfig {
    fn default() -> Self {
        Self {
            extent: [128, 128],
            time: 0.0,
            truth_spp: 2048,
            truth_chunk: 128,
            uniform_spp: (0..=8).map(|k| 1 << k).collect(),
            mus: vec![0.25, 0.5, 0.9, 2.0, 4.0, 8.0],
            mu: shine_sh::aaf::DEFAULT_MU,
            repeats: 1,
            path_tracer_spp: 256,
            seed: 1,
            params: frame_defaults(),
        }
    }
}

/// The AAF parameters of a default `--gi aaf` frame: [`AafParams::default`] with the traced
/// specular pass's roughness limit, so the study judges the share of the light AAF computes in
/// the frame (the pass traces the lobes sharper than the limit: the room's chrome and gold).
pub fn frame_defaults() -> AafParams {
    AafParams {
        specular_limit: crate::passes::specular::SpecularParams::default().traced_limit(),
        ..AafParams::default()
    }
}

impl AafStudyConfig {
    /// Checks the sizes, sample counts and μ against what the passes take.
    pub fn validate(&self) -> Result<(), StudyError> {
        let bad = |m: String| Err(StudyError::Invalid(m));
        let [w, h] = self.extent;
        if !(1..=MAX_EXTENT).contains(&w) || !(1..=MAX_EXTENT).contains(&h) {
            return bad(format!(
                "image size {w}×{h} is out of range (1..={MAX_EXTENT} per side)"
            ));
        }
        let spp = aaf::FIRST_SAMPLES;
        if !spp.contains(&self.truth_chunk) {
            return bad(format!(
                "--truth-chunk {} is out of range ({spp:?})",
                self.truth_chunk
            ));
        }
        if self.truth_spp < 2 * self.truth_chunk || !self.truth_spp.is_multiple_of(self.truth_chunk)
        {
            return bad(format!(
                "--truth-spp {} must be a multiple of --truth-chunk {} and at least two chunks \
                 (the truth's noise is measured from their spread)",
                self.truth_spp, self.truth_chunk
            ));
        }
        if self.uniform_spp.is_empty() {
            return bad("--spp needs at least one level".into());
        }
        if let Some(n) = self.uniform_spp.iter().find(|n| !spp.contains(n)) {
            return bad(format!("--spp level {n} is out of range ({spp:?})"));
        }
        if self.uniform_spp.windows(2).any(|p| p[0] >= p[1]) {
            return bad("--spp levels must increase".into());
        }
        let mus = aaf::MU_RANGE;
        if let Some(mu) = self.mus.iter().chain([&self.mu]).find(|m| !mus.contains(m)) {
            return bad(format!("μ = {mu} is out of range ({mus:?})"));
        }
        if self.repeats == 0 {
            return bad("--repeats must be at least 1".into());
        }
        if self.path_tracer_spp > 1 << 16 {
            return bad("--path-tracer-spp is at most 65536".into());
        }
        self.params
            .validate()
            .or_else(|e| bad(format!("the AAF parameters: {e}")))
    }

    /// The AAF curve's μ values, sorted, with the study's μ among them.
    fn all_mus(&self) -> Vec<f32> {
        let mut mus = self.mus.clone();
        if !mus.contains(&self.mu) {
            mus.push(self.mu);
        }
        mus.sort_by(f32::total_cmp);
        mus.dedup();
        mus
    }
}

/// A finished study: the report and what its pictures are made of.
#[derive(Debug, Clone)]
pub struct AafStudy {
    /// The numbers.
    pub report: AafStudyReport,
    truth: Vec<[f32; 3]>,
    aaf: AafFrame,
    uniform: Vec<[f32; 3]>,
    mask: Vec<bool>,
    beta_px: Vec<f32>,
    /// Uniform filtered at the most spp: the filter's bias with little noise left.
    filtered_most: Vec<[f32; 3]>,
}

/// Renders the study's images of `scene` on `device` and measures them.
pub fn run(
    device: &Device,
    scene: &Scene,
    scene_name: &str,
    config: &AafStudyConfig,
    progress: &mut dyn Progress,
) -> Result<AafStudy, StudyError> {
    config.validate()?;
    let runner = AafRunner::new(device, scene, config.time, config.extent)?;
    let mut bench = Bench {
        runner,
        seed: config.seed,
        repeats: config.repeats,
    };
    let base = |first_samples: u32, adaptive: bool, filter: bool, mu: f32| AafParams {
        first_samples,
        adaptive,
        filter,
        mu,
        ..config.params
    };
    // Warm-up: pipelines and transient memory of both graph shapes, not measured.
    progress.stage("warm-up", 2);
    for adaptive in [false, true] {
        bench.render(base(config.params.first_samples, adaptive, true, config.mu))?;
        progress.advance(1, "warm-up");
    }

    // The truth.
    let chunks = config.truth_spp / config.truth_chunk;
    progress.stage("truth", u64::from(config.truth_spp));
    let [w, h] = config.extent;
    let mut truth_acc = TruthAccumulator::new(w as usize * h as usize);
    let mut mask = Vec::new();
    for _ in 0..chunks {
        let frame = bench.render(base(config.truth_chunk, false, false, config.mu))?;
        if mask.is_empty() {
            mask = frame.samples.iter().map(|s| *s > 0.0).collect();
        }
        truth_acc.add(&frame.indirect);
        progress.advance(u64::from(config.truth_chunk), "truth");
    }
    let truth = truth_acc.mean();
    let noise_mse = truth_acc.noise_mse(&mask);
    let pixels = mask.iter().filter(|m| **m).count();
    let truth_mean = metrics::mean_over(&truth, &mask);
    if pixels == 0 || truth_mean <= 0.0 {
        return Err(StudyError::NothingToMeasure(format!(
            "{scene_name} has no indirect light to measure at {w}×{h} (no lit, non-background \
             pixel)"
        )));
    }
    let target = Target {
        truth: &truth,
        mask: &mask,
        mean: truth_mean,
    };

    // The curves.
    let mus = config.all_mus();
    let renders = (2 * config.uniform_spp.len() + mus.len()) as u64 * u64::from(config.repeats);
    progress.stage("curves", renders);
    let sampling = |f: &AafFrame| f.time_ms(&["aaf_sample_first"]);
    let whole = |f: &AafFrame| f.aaf_ms();
    let mut uniform = Vec::new();
    let mut uniform_images = Vec::new();
    for &n in &config.uniform_spp {
        let what = format!("uniform {n} spp");
        let m = bench.measure(
            base(n, false, false, config.mu),
            &target,
            &sampling,
            &what,
            progress,
        )?;
        uniform.push(point(&m, None));
        uniform_images.push((n, m.last.indirect));
    }
    let mut filtered = Vec::new();
    let mut filtered_most = Vec::new();
    for &n in &config.uniform_spp {
        let what = format!("uniform filtered {n} spp");
        let m = bench.measure(
            base(n, false, true, config.mu),
            &target,
            &whole,
            &what,
            progress,
        )?;
        filtered.push(point(&m, None));
        filtered_most = m.last.indirect;
    }
    let mut aaf_points = Vec::new();
    let mut at_mu = None;
    for &mu in &mus {
        let what = format!("AAF μ = {mu}");
        let p = base(config.params.first_samples, true, true, mu);
        let m = bench.measure(p, &target, &whole, &what, progress)?;
        aaf_points.push(point(&m, Some(mu)));
        if mu == config.mu {
            at_mu = Some(m);
        }
    }
    let at_mu =
        at_mu.ok_or_else(|| StudyError::Invalid("the study's μ was not rendered".into()))?;

    // Equal error.
    let uniform_mse: Vec<(f64, f64)> = uniform.iter().map(|p| (p.spp, p.mse)).collect();
    let crossing =
        metrics::equal_error_spp(&uniform_mse, at_mu.error.mse, noise_mse.unwrap_or(0.0));
    let uniform_time: Vec<(f64, f64)> = uniform.iter().map(|p| (p.spp, p.time_ms)).collect();
    let uniform_time_ms = crossing.and_then(|c| metrics::interpolate_linear(&uniform_time, c.spp));
    let frame = &at_mu.last;
    let aaf_time_ms = frame.aaf_ms();
    let share = |names: &[&str]| frame.time_ms(names) / aaf_time_ms.max(f64::MIN_POSITIVE);
    let filter_share = share(&["aaf_filter_x", "aaf_filter_y"]);
    let overhead_share = share(&["aaf_beta", "aaf_filter_x", "aaf_filter_y"]);
    let sample_speedup = crossing.map(|c| c.spp / at_mu.spp);
    let equal_error = EqualError {
        reliable: noise_mse.is_some_and(|t| t <= RELIABLE_NOISE_SHARE * at_mu.error.mse),
        mu: config.mu,
        aaf_spp: at_mu.spp,
        aaf_relative_rmse: at_mu.error.relative_rmse,
        uniform_spp: crossing.map(|c| c.spp),
        extrapolated: crossing.is_some_and(|c| c.extrapolated),
        sample_speedup,
        aaf_time_ms,
        uniform_time_ms,
        time_speedup: uniform_time_ms.map(|t| t / aaf_time_ms.max(f64::MIN_POSITIVE)),
        passes_ms: frame
            .passes
            .iter()
            .filter(|(n, _)| AAF_PASSES.contains(&n.as_str()))
            .cloned()
            .collect(),
        gbuffer_ms: frame.time_ms(&["gbuffer"]),
        filter_share,
        overhead_share,
    };
    let bars = Bars {
        sample_speedup_min: SAMPLE_SPEEDUP_BAR,
        sample_speedup_met: sample_speedup.is_some_and(|s| s >= SAMPLE_SPEEDUP_BAR),
        overhead_share_max: OVERHEAD_SHARE_BAR,
        overhead_share_met: overhead_share <= OVERHEAD_SHARE_BAR,
    };

    // Against the path tracer.
    let path_tracer = if config.path_tracer_spp > 0 {
        progress.stage("path tracer", 1);
        progress.advance(0, "path tracer");
        let images = reference::render_reference(
            device,
            scene,
            config.time,
            &ReferenceParams {
                width: config.extent[0],
                height: config.extent[1],
                bounces: 1,
                jitter: false,
                emissive_lighting: false,
                lambert_only: false,
                light_sampling: true,
                seed: config.seed,
                primary_specular: None,
            },
            config.path_tracer_spp,
        )?;
        progress.advance(1, "path tracer");
        let pt: Vec<[f32; 3]> = images
            .indirect
            .texels
            .iter()
            .map(|t| [t[0], t[1], t[2]])
            .collect();
        let against = |image: &[[f32; 3]]| metrics::image_error(image, &pt, &mask);
        match (against(&frame.indirect), against(&truth)) {
            (Some(a), Some(t)) => Some(AgainstPathTracer {
                spp: config.path_tracer_spp,
                aaf_relative_rmse: a.relative_rmse,
                aaf_energy_ratio: a.energy_ratio,
                truth_relative_rmse: t.relative_rmse,
                truth_energy_ratio: t.energy_ratio,
            }),
            _ => None,
        }
    } else {
        None
    };
    progress.finish();

    // The maps' ranges and the images.
    let footprint = bench.runner.footprint();
    let depth = bench.runner.depth().unwrap_or_default();
    let beta_px: Vec<f32> = frame
        .beta
        .iter()
        .zip(depth)
        .map(|(b, z)| {
            let d = z * footprint[0] + footprint[1];
            if d > 0.0 { b / d } else { 0.0 }
        })
        .collect();
    let masked = |v: &[f32]| -> Vec<f32> {
        v.iter()
            .zip(&mask)
            .filter(|(_, m)| **m)
            .map(|(v, _)| *v)
            .collect()
    };
    let spp_values = masked(&frame.samples);
    let beta_values = masked(&beta_px);
    let max = |v: &[f32]| v.iter().copied().fold(0.0f32, f32::max);
    let min = |v: &[f32]| v.iter().copied().fold(f32::INFINITY, f32::min);
    let beta_max = max(&beta_values);
    let (uniform_image_spp, uniform_image) = uniform_images
        .into_iter()
        .min_by(|a, b| {
            let d = |n: u32| (f64::from(n).ln() - at_mu.spp.ln()).abs();
            d(a.0).total_cmp(&d(b.0))
        })
        .unwrap_or_default();
    let maps = Maps {
        spp_ramp_max: AafParams {
            mu: config.mu,
            ..config.params
        }
        .spp_upper(),
        spp_range: [min(&spp_values), max(&spp_values)],
        beta_ramp_max_px: beta_max.min(aaf::MAX_RADIUS as f32 / 2.0).max(1.0),
        beta_px_mean_max: [
            beta_values.iter().sum::<f32>() / beta_values.len().max(1) as f32,
            beta_max,
        ],
        signed_error_range: SIGNED_ERROR_RANGE,
        exposure: (0.3 / truth_mean) as f32,
        uniform_image_spp,
    };
    let report = AafStudyReport {
        scene: scene_name.to_owned(),
        extent: config.extent,
        device: device.info().name.clone(),
        repeats: config.repeats,
        setup: Setup {
            filter_degree: config.params.filter_degree,
            irradiance_vector: config.params.irradiance_vector,
            specular_limit: config.params.specular_limit,
            hit_roughness_min: config.params.hit_roughness_min,
        },
        truth: Truth {
            spp: config.truth_spp,
            chunk: config.truth_chunk,
            mean: truth_mean,
            noise_relative_rmse: noise_mse.map(|t| t.sqrt() / truth_mean),
            pixels,
        },
        curves: Curves {
            uniform,
            uniform_filtered: filtered,
            aaf: aaf_points,
        },
        equal_error,
        bars,
        path_tracer,
        maps,
        error_plot: None,
        files: Vec::new(),
    };
    Ok(AafStudy {
        report,
        truth,
        aaf: at_mu.last,
        uniform: uniform_image,
        mask,
        beta_px,
        filtered_most,
    })
}

impl AafStudy {
    /// Writes error.png, spp.png, beta.png, aaf_error.png, filter_bias.png, truth.png, aaf.png
    /// and uniform.png into `dir`
    /// (created if missing), each atomically; records them and the plot's axes in the report.
    pub fn write_outputs(&mut self, dir: &Path) -> Result<(), StudyError> {
        std::fs::create_dir_all(dir)
            .map_err(|e| StudyError::Invalid(format!("cannot create {}: {e}", dir.display())))?;
        let r = &self.report;
        let extent = r.extent;
        let curve = |label: &str, points: &[CurvePoint], colour| Curve {
            label: label.to_owned(),
            points: points.iter().map(|p| (p.spp, p.relative_rmse)).collect(),
            colour,
        };
        let mus: Vec<String> = r
            .curves
            .aaf
            .iter()
            .filter_map(|p| p.mu)
            .map(|m| m.to_string())
            .collect();
        let aaf_label = format!("AAF, μ = {}", mus.join(", "));
        let curves = [
            curve("uniform MC, unfiltered", &r.curves.uniform, [220, 40, 40]),
            curve(
                "uniform MC, filtered",
                &r.curves.uniform_filtered,
                [30, 150, 60],
            ),
            curve(&aaf_label, &r.curves.aaf, [40, 70, 220]),
        ];
        let e = &r.equal_error;
        let crossing = e.uniform_spp.map(|n| (n, e.aaf_relative_rmse));
        let mut files: Vec<PathBuf> = Vec::new();
        let path = dir.join("error.png");
        let title = format!(
            "{}: error vs samples ({}×{})",
            r.scene, extent[0], extent[1]
        );
        let marks = plot::Marks {
            crossing,
            floor: r.truth.noise_relative_rmse,
        };
        let plot = plot::error_plot(&path, &title, &curves, marks, [800, 560])?;
        files.push(path);
        let path = dir.join("spp.png");
        plot::write_map(
            &path,
            extent,
            &self.aaf.samples,
            &self.mask,
            [0.0, r.maps.spp_ramp_max],
        )?;
        files.push(path);
        let path = dir.join("beta.png");
        plot::write_map(
            &path,
            extent,
            &self.beta_px,
            &self.mask,
            [0.0, r.maps.beta_ramp_max_px],
        )?;
        files.push(path);
        // Signed errors per pixel, relative to the truth's mean.
        let signed = |image: &[[f32; 3]]| -> Vec<f32> {
            let mean = r.truth.mean as f32;
            image
                .iter()
                .zip(&self.truth)
                .map(|(x, t)| (0..3).map(|c| x[c] - t[c]).sum::<f32>() / (3.0 * mean))
                .collect()
        };
        let range = r.maps.signed_error_range;
        for (name, image) in [
            ("aaf_error.png", &self.aaf.indirect),
            ("filter_bias.png", &self.filtered_most),
        ] {
            let path = dir.join(name);
            plot::write_signed_map(&path, extent, &signed(image), &self.mask, range)?;
            files.push(path);
        }
        for (name, image) in [
            ("truth.png", &self.truth),
            ("aaf.png", &self.aaf.indirect),
            ("uniform.png", &self.uniform),
        ] {
            let path = dir.join(name);
            plot::write_tonemapped(&path, extent, image, r.maps.exposure)?;
            files.push(path);
        }
        self.report.error_plot = Some(plot);
        self.report.files = files.iter().map(|p| p.display().to_string()).collect();
        Ok(())
    }
}

/// A curve point of the report from a measurement.
fn point(m: &Measured, mu: Option<f32>) -> CurvePoint {
    CurvePoint {
        spp: m.spp,
        mu,
        relative_rmse: m.error.relative_rmse,
        mse: m.error.mse,
        energy_ratio: m.error.energy_ratio,
        time_ms: m.time_ms,
    }
}
