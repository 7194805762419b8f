//! `shine study temporal`: GI modes judged in motion (issue 18). On an animated sequence,
//! for each mode (a label and settings), the cost per frame, the error of every frame against
//! a path-traced truth of that frame, and the flicker: the RMS of the second temporal
//! difference of the frames over their mean. The truth is a fixed-seed, unjittered path-traced
//! sequence (emissive surfaces lighting nothing, as the raster GI), whose own flicker is
//! reported as the yardstick. A plot of cost against error, each point labelled with its
//! flicker, is written as PNG.

use std::path::Path;
use std::time::Instant;

use plotters::backend::RGBPixel;
use plotters::prelude::*;
use serde::Serialize;
use shine_scene::Scene;

use super::metrics;
use super::plot::font;
use super::{Progress, StudyError};
use crate::capture::image_io::{HdrImage, LdrImage, write_png};
use crate::frame::renderer::Renderer;
use crate::gpu::Device;
use crate::gpu_scene::FrameUpdate;
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
}

/// What the study measured for one mode.
#[derive(Clone, Debug, Serialize)]
pub struct ModeResult {
    /// The mode's label.
    pub label: String,
    /// Median wall time of a frame (submission to readback), ms.
    pub ms_per_frame: f64,
    /// Mean over frames of the relative RMSE against the truth frame.
    pub relative_rmse: f64,
    /// RMS of the second temporal difference over the mean of the frames.
    pub flicker: f64,
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
    /// Flicker of the path-traced truth (the yardstick).
    pub truth_flicker: f64,
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

/// RMS of the second temporal difference `I[k+1] - 2 I[k] + I[k-1]` over the mean of the
/// frames (rgb); 0 for fewer than 3 frames.
pub fn flicker(frames: &[HdrImage]) -> f64 {
    let (mut se, mut n) = (0.0f64, 0usize);
    for w in frames.windows(3) {
        for ((a, b), c) in w[0].texels.iter().zip(&w[1].texels).zip(&w[2].texels) {
            for k in 0..3 {
                se += f64::from(c[k] - 2.0 * b[k] + a[k]).powi(2);
                n += 1;
            }
        }
    }
    let (mut sum, mut m) = (0.0f64, 0usize);
    for f in frames {
        for t in &f.texels {
            sum += f64::from(t[0] + t[1] + t[2]);
            m += 3;
        }
    }
    if n == 0 {
        return 0.0;
    }
    (se / n as f64).sqrt() / (sum / m.max(1) as f64).max(1e-12)
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
    progress.stage("truth", u64::from(config.frames));
    let params = ReferenceParams {
        width: first.settings.width,
        height: first.settings.height,
        jitter: false,
        emissive_lighting: false,
        ..ReferenceParams::default()
    };
    let mut tracer = PathTracer::new(device, scene, times[0], &params)?;
    let mut truth = Vec::new();
    for &t in &times {
        tracer.update(&FrameUpdate::at(t))?;
        tracer.accumulate(config.truth_spp)?;
        truth.push(tracer.read()?.full);
        progress.advance(1, "path tracing");
    }
    let mut results = Vec::new();
    for mode in modes {
        progress.stage(&mode.label, u64::from(config.frames));
        let mut renderer = Renderer::new(device)?;
        renderer.set_scene(scene, config.time)?;
        for k in 0..config.warmup {
            renderer.update(&FrameUpdate::at(at(k)))?;
            renderer.render(&mode.settings)?;
        }
        let (mut images, mut ms) = (Vec::new(), Vec::new());
        for &t in &times {
            renderer.update(&FrameUpdate::at(t))?;
            let start = Instant::now();
            let frame = renderer.render(&mode.settings)?;
            ms.push(start.elapsed().as_secs_f64() * 1e3);
            images.push(frame.hdr);
            progress.advance(1, &mode.label);
        }
        ms.sort_by(f64::total_cmp);
        let error = images
            .iter()
            .zip(&truth)
            .map(|(a, b)| relative_rmse(a, b))
            .sum::<f64>()
            / images.len() as f64;
        results.push(ModeResult {
            label: mode.label.clone(),
            ms_per_frame: ms[ms.len() / 2],
            relative_rmse: error,
            flicker: flicker(&images),
        });
    }
    progress.finish();
    Ok(TemporalReport {
        scene: name.to_owned(),
        frames: config.frames,
        warmup: config.warmup,
        truth_flicker: flicker(&truth),
        modes: results,
    })
}

impl TemporalReport {
    /// The report as a table.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} over {} frames after {} of warm-up; flicker of the path-traced truth {:.4}\n{:<28} {:>12} {:>14} {:>10}\n",
            self.scene,
            self.frames,
            self.warmup,
            self.truth_flicker,
            "mode",
            "ms/frame",
            "rel. RMSE",
            "flicker"
        );
        for m in &self.modes {
            out.push_str(&format!(
                "{:<28} {:>12.1} {:>14.4} {:>10.4}\n",
                m.label, m.ms_per_frame, m.relative_rmse, m.flicker
            ));
        }
        out
    }

    /// Draws cost (x) against error (y), each mode a point labelled with its flicker, into
    /// `path` (PNG).
    pub fn plot(&self, path: &Path) -> Result<(), StudyError> {
        let (w, h) = (720u32, 480u32);
        let mut rgb = vec![255u8; (w * h * 3) as usize];
        self.draw(&mut rgb, (w, h))
            .map_err(|e| StudyError::Plot(format!("{}: {e}", path.display())))?;
        let texels = rgb
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2], 255])
            .collect();
        Ok(write_png(
            path,
            &LdrImage {
                width: w,
                height: h,
                texels,
            },
        )?)
    }

    fn draw(&self, rgb: &mut [u8], size: (u32, u32)) -> Result<(), Box<dyn std::error::Error>> {
        let root =
            BitMapBackend::<RGBPixel>::with_buffer_and_format(rgb, size)?.into_drawing_area();
        root.fill(&WHITE)?;
        let max_ms = self
            .modes
            .iter()
            .map(|m| m.ms_per_frame)
            .fold(1e-3, f64::max)
            * 1.2;
        let max_err = self
            .modes
            .iter()
            .map(|m| m.relative_rmse)
            .fold(1e-3, f64::max)
            * 1.2;
        let mut builder = ChartBuilder::on(&root);
        builder.margin(16);
        let labels = font().is_some();
        if labels {
            builder.x_label_area_size(40).y_label_area_size(56);
        }
        let mut chart = builder.build_cartesian_2d(0.0..max_ms, 0.0..max_err)?;
        let mut mesh = chart.configure_mesh();
        if labels {
            mesh.x_desc("ms per frame").y_desc("relative RMSE vs truth");
        } else {
            mesh.disable_x_axis().disable_y_axis();
        }
        mesh.draw()?;
        for (i, m) in self.modes.iter().enumerate() {
            let colour = Palette99::pick(i).to_rgba();
            chart.draw_series(std::iter::once(Circle::new(
                (m.ms_per_frame, m.relative_rmse),
                6,
                colour.filled(),
            )))?;
            if labels {
                // Offset in pixels to the right of the marker, so the text never covers it.
                let label = EmptyElement::at((m.ms_per_frame, m.relative_rmse))
                    + Text::new(
                        format!("{} (flicker {:.3})", m.label, m.flicker),
                        (10, -7),
                        ("sans-serif", 14).into_font(),
                    );
                chart.draw_series(std::iter::once(label))?;
            }
        }
        root.present()?;
        Ok(())
    }
}
