//! The AAF study's report (`shine study aaf --format table|json`): every number the study
//! measured, with the definitions in the field docs. JSON field names are the Rust ones.

use std::fmt::Write as _;

use serde::Serialize;

use super::plot::ErrorPlot;

/// The output formats of a study report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StudyFormat {
    /// Aligned columns for a terminal.
    Table,
    /// One JSON object ([`AafStudyReport`]'s fields).
    Json,
}

impl std::str::FromStr for StudyFormat {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "table" => Ok(Self::Table),
            "json" => Ok(Self::Json),
            _ => Err(format!("unknown --format `{s}`: expected table or json")),
        }
    }
}

/// One measured point of a curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Average samples per non-background pixel.
    pub spp: f64,
    /// The filter scale μ (AAF only).
    pub mu: Option<f32>,
    /// RMSE over non-background pixels and channels / the truth's mean there.
    pub relative_rmse: f64,
    /// Mean squared error (linear radiance², for the equal-error interpolation).
    pub mse: f64,
    /// Σ image / Σ truth over non-background pixels.
    pub energy_ratio: f64,
    /// Host time of the frame's passes that count for the method, in ms (uniform unfiltered:
    /// the sampling pass only; the others: every AAF pass), the least over the repeats.
    pub time_ms: f64,
}

/// The three curves of paper 004's Fig. 10.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curves {
    /// Uniform (stratified) Monte Carlo, unfiltered.
    pub uniform: Vec<CurvePoint>,
    /// Uniform Monte Carlo through AAF's filter (β from the same samples).
    pub uniform_filtered: Vec<CurvePoint>,
    /// AAF: adaptive sampling and filter, one point per μ.
    pub aaf: Vec<CurvePoint>,
}

/// The truth: uniform Monte Carlo of the same quantity at high spp.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Truth {
    /// Samples per pixel.
    pub spp: u32,
    /// Samples per pixel of each independent chunk (seed).
    pub chunk: u32,
    /// Mean over non-background pixels and channels (linear radiance).
    pub mean: f64,
    /// The truth's own noise as a relative RMSE (√τ² / mean, from the chunks' spread): the floor
    /// every measured error sits on.
    pub noise_relative_rmse: Option<f64>,
    /// Non-background pixels measured.
    pub pixels: usize,
}

/// AAF and the truth against the path tracer's indirect light (information: the path tracer
/// also has the specular indirect light AAF does not compute, and its own noise).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AgainstPathTracer {
    /// The path tracer's samples per pixel (bounces 1, no jitter, punctual lights only).
    pub spp: u32,
    /// AAF at the study's μ: relative RMSE against the path tracer.
    pub aaf_relative_rmse: f64,
    /// AAF at the study's μ: energy ratio to the path tracer.
    pub aaf_energy_ratio: f64,
    /// The truth: relative RMSE against the path tracer.
    pub truth_relative_rmse: f64,
    /// The truth: energy ratio to the path tracer.
    pub truth_energy_ratio: f64,
}

/// The equal-error comparison at the study's μ.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EqualError {
    /// Whether the truth's own noise is small against AAF's error (its MSE at most a quarter of
    /// AAF's): if not, every error is mostly the truth's noise and these numbers mean little.
    pub reliable: bool,
    /// AAF's μ.
    pub mu: f32,
    /// AAF's average spp.
    pub aaf_spp: f64,
    /// AAF's relative RMSE.
    pub aaf_relative_rmse: f64,
    /// The spp at which uniform unfiltered Monte Carlo has AAF's error (log-log interpolation);
    /// `None` when AAF's error is below the truth's noise.
    pub uniform_spp: Option<f64>,
    /// Whether `uniform_spp` lies beyond the measured uniform points (extrapolated at the
    /// Monte-Carlo rate, variance ∝ 1/spp, after taking the truth's noise out).
    pub extrapolated: bool,
    /// `uniform_spp / aaf_spp`.
    pub sample_speedup: Option<f64>,
    /// Host time of AAF's five passes, ms.
    pub aaf_time_ms: f64,
    /// Host time of uniform sampling at `uniform_spp` (the sampling pass's times at the
    /// measured spp, interpolated linearly), ms.
    pub uniform_time_ms: Option<f64>,
    /// `uniform_time_ms / aaf_time_ms`.
    pub time_speedup: Option<f64>,
    /// Host time of each AAF pass, ms, in frame order.
    pub passes_ms: Vec<(String, f64)>,
    /// Host time of the G-buffer pass, ms (not counted in AAF's time).
    pub gbuffer_ms: f64,
    /// (aaf_filter_x + aaf_filter_y) / AAF's time.
    pub filter_share: f64,
    /// (aaf_beta + aaf_filter_x + aaf_filter_y) / AAF's time: everything AAF adds to sampling
    /// (paper 004 Table 1's "total overhead").
    pub overhead_share: f64,
}

/// The bars and whether they are met.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bars {
    /// Required sample speedup at equal error.
    pub sample_speedup_min: f64,
    /// Whether it is met.
    pub sample_speedup_met: bool,
    /// Largest share of AAF's frame the filtering may take (checked against `overhead_share`,
    /// β's pass included).
    pub overhead_share_max: f64,
    /// Whether it is met.
    pub overhead_share_met: bool,
}

/// The per-pixel maps' ranges.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Maps {
    /// spp.png: AAF's samples per pixel on the ramp from 0 to this (spp_max·μ).
    pub spp_ramp_max: f32,
    /// Least and most samples per non-background pixel.
    pub spp_range: [f32; 2],
    /// beta.png: β in pixels on the ramp from 0 to this.
    pub beta_ramp_max_px: f32,
    /// Mean and largest β over non-background pixels, in pixels.
    pub beta_px_mean_max: [f32; 2],
    /// aaf_error.png (AAF at the study's μ) and filter_bias.png (uniform filtered at the most
    /// spp): per pixel, the mean over channels of (image − truth) / the truth's mean, on a
    /// blue–white–red ramp from −this to +this.
    pub signed_error_range: f32,
    /// The factor the tonemapped images' radiance was scaled by.
    pub exposure: f32,
    /// The uniform spp shown in uniform.png (the measured level nearest AAF's average spp).
    pub uniform_image_spp: u32,
}

/// The AAF parameters the study's renders share.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Setup {
    /// Degree of the filter's local polynomial fit (0: the paper's gaussian).
    pub filter_degree: u32,
    /// Whether the diffuse part is filtered as an irradiance vector.
    pub irradiance_vector: bool,
    /// Roughness limit of the traced specular pass whose lobes AAF leaves out (0: none).
    pub specular_limit: f32,
    /// Least roughness of the BRDF at the samples' hits.
    pub hit_roughness_min: f32,
}

/// Everything `shine study aaf` measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AafStudyReport {
    /// The scene argument.
    pub scene: String,
    /// Image width and height.
    pub extent: [u32; 2],
    /// The Vulkan device.
    pub device: String,
    /// Renders per curve point (errors averaged, times the least).
    pub repeats: u32,
    /// The AAF parameters every render shares (the filter's fit, the specular limit, the
    /// hits' least roughness): they change every number.
    pub setup: Setup,
    /// The truth.
    pub truth: Truth,
    /// The error curves.
    pub curves: Curves,
    /// Equal error at the study's μ.
    pub equal_error: EqualError,
    /// The bars.
    pub bars: Bars,
    /// Against the path tracer, if it was run.
    pub path_tracer: Option<AgainstPathTracer>,
    /// The maps' ranges and the images' exposure.
    pub maps: Maps,
    /// What error.png shows.
    pub error_plot: Option<ErrorPlot>,
    /// The files written.
    pub files: Vec<String>,
}

fn opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "—".to_owned(), |v| format!("{v:.digits$}"))
}

impl AafStudyReport {
    /// The report as JSON or as a table.
    pub fn format(&self, format: StudyFormat) -> Result<String, serde_json::Error> {
        match format {
            StudyFormat::Json => serde_json::to_string_pretty(self),
            StudyFormat::Table => Ok(self.table()),
        }
    }

    /// Aligned columns for a terminal.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let [w, h] = self.extent;
        let t = &self.truth;
        let _ = writeln!(
            s,
            "AAF study: {} at {w}×{h} on {} ({} render(s) per point); filter degree {}, \
             irradiance vector {}, specular limit {}, hit roughness ≥ {}",
            self.scene,
            self.device,
            self.repeats,
            self.setup.filter_degree,
            self.setup.irradiance_vector,
            self.setup.specular_limit,
            self.setup.hit_roughness_min
        );
        let _ = writeln!(
            s,
            "truth: {} spp in chunks of {}, {} pixels, mean {:.4e}, own noise {} relative RMSE",
            t.spp,
            t.chunk,
            t.pixels,
            t.mean,
            opt(t.noise_relative_rmse, 4)
        );
        let _ = writeln!(
            s,
            "\n{:<18} {:>5} {:>8} {:>10} {:>7} {:>10}",
            "method", "μ", "spp", "rel. RMSE", "energy", "time ms"
        );
        let curves = [
            ("uniform", &self.curves.uniform),
            ("uniform filtered", &self.curves.uniform_filtered),
            ("AAF", &self.curves.aaf),
        ];
        for (name, points) in curves {
            for p in points.iter() {
                let mu = p.mu.map_or_else(String::new, |m| format!("{m}"));
                let _ = writeln!(
                    s,
                    "{name:<18} {mu:>5} {:>8.1} {:>10.4} {:>7.3} {:>10.1}",
                    p.spp, p.relative_rmse, p.energy_ratio, p.time_ms
                );
            }
        }
        let e = &self.equal_error;
        let _ = writeln!(
            s,
            "\nequal error at μ = {}: AAF {:.1} spp, rel. RMSE {:.4}; uniform reaches it at {} spp{}",
            e.mu,
            e.aaf_spp,
            e.aaf_relative_rmse,
            opt(e.uniform_spp, 1),
            if e.extrapolated {
                " (extrapolated)"
            } else {
                ""
            }
        );
        if !e.reliable {
            let _ = writeln!(
                s,
                "WARNING: the truth's own noise ({} relative RMSE) is not small against AAF's error: \
                 the equal-error numbers below are not reliable (more --truth-spp, or a scene \
                 with less variance)",
                opt(t.noise_relative_rmse, 3)
            );
        }
        let _ = writeln!(
            s,
            "speedup: {}× in samples, {}× in time (AAF {:.1} ms, uniform {} ms)",
            opt(e.sample_speedup, 2),
            opt(e.time_speedup, 2),
            e.aaf_time_ms,
            opt(e.uniform_time_ms, 1)
        );
        let passes: Vec<String> = e
            .passes_ms
            .iter()
            .map(|(n, ms)| format!("{n} {ms:.1}"))
            .collect();
        let _ = writeln!(
            s,
            "AAF passes (ms): {}; gbuffer {:.1}",
            passes.join(", "),
            e.gbuffer_ms
        );
        let _ = writeln!(
            s,
            "filter share {:.1}%, overhead share (β + filter) {:.1}%",
            100.0 * e.filter_share,
            100.0 * e.overhead_share
        );
        let b = &self.bars;
        let verdict = |met: bool| if met { "met" } else { "NOT met" };
        let _ = writeln!(
            s,
            "bars: ≥{}× samples at equal error: {}; overhead ≤{}%: {}",
            b.sample_speedup_min,
            verdict(b.sample_speedup_met),
            100.0 * b.overhead_share_max,
            verdict(b.overhead_share_met)
        );
        if let Some(p) = &self.path_tracer {
            let _ = writeln!(
                s,
                "vs path tracer ({} spp, indirect incl. specular): AAF rel. RMSE {:.4}, energy {:.3}; \
                 truth rel. RMSE {:.4}, energy {:.3}",
                p.spp,
                p.aaf_relative_rmse,
                p.aaf_energy_ratio,
                p.truth_relative_rmse,
                p.truth_energy_ratio
            );
        }
        let m = &self.maps;
        let _ = writeln!(
            s,
            "maps: spp {:.0}..{:.0} (ramp 0..{:.0}), β px mean {:.2} max {:.2} (ramp 0..{:.1}), \
             exposure {:.3}, uniform.png at {} spp",
            m.spp_range[0],
            m.spp_range[1],
            m.spp_ramp_max,
            m.beta_px_mean_max[0],
            m.beta_px_mean_max[1],
            m.beta_ramp_max_px,
            m.exposure,
            m.uniform_image_spp
        );
        if let Some(p) = &self.error_plot {
            let _ = writeln!(
                s,
                "error.png axes: spp {:.3}..{:.1}, rel. RMSE {:.4}..{:.4} (log-log){}",
                p.spp_axis[0],
                p.spp_axis[1],
                p.error_axis[0],
                p.error_axis[1],
                if p.font.is_some() {
                    ""
                } else {
                    ", no text (no font found)"
                }
            );
        }
        for file in &self.files {
            let _ = writeln!(s, "wrote {file}");
        }
        s
    }
}
