//! The pictures and table of `shine study temporal` ([`TemporalReport`]): cost against error,
//! flicker frame by frame, and per-pixel flicker maps on one shared scale.

use std::path::{Path, PathBuf};

use plotters::backend::RGBPixel;
use plotters::prelude::*;

use super::StudyError;
use super::plot::{font, write_drawing, write_map};
use super::temporal::TemporalReport;

/// A label as part of a file name: letters, digits, `-` and `_` kept, the rest `_` (a mode's
/// flicker map here, the lab's images, plots and budget tables).
pub(crate) fn file_label(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Size of the plots in pixels.
const PLOT_SIZE: [u32; 2] = [720, 480];

/// Width the flicker maps are magnified to at least (pixels), so small study frames can be seen.
const MAP_WIDTH: u32 = 256;

/// `values` (row-major, `extent`) with every pixel repeated `zoom` × `zoom` times.
fn magnify(values: &[f32], [w, h]: [u32; 2], zoom: u32) -> Vec<f32> {
    (0..h * zoom)
        .flat_map(|y| (0..w * zoom).map(move |x| ((y / zoom) * w + x / zoom) as usize))
        .map(|i| values[i])
        .collect()
}

/// The `q` quantile of `values` (0 when empty).
fn percentile(values: &[f32], q: f32) -> f32 {
    let mut sorted: Vec<f32> = values.iter().copied().filter(|v| v.is_finite()).collect();
    sorted.sort_by(f32::total_cmp);
    sorted
        .get(((sorted.len() as f32 * q) as usize).min(sorted.len().saturating_sub(1)))
        .copied()
        .unwrap_or(0.0)
}

impl TemporalReport {
    /// The report as a table: the sequence's cost, error (the lag: against the cold frames'
    /// error) and flicker over every pixel and over the pixels no moving object covers, each
    /// also as a multiple of the truth's, and the same for the cold frames. The JSON report
    /// also holds the flicker where the truth holds still and the last frames' errors.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{} over {} frames after {} of warm-up; flicker of the path-traced truth {:.4} (two seeds, noise out; one seed reads {:.4}); over the {:.0}% of pixels no moving object covers {:.4}\n",
            self.scene,
            self.frames,
            self.warmup,
            self.truth_flicker,
            self.truth_flicker_one_seed,
            100.0 * self.uncovered_share,
            self.truth_uncovered_flicker,
        );
        out.push_str(&format!(
            "{:<12} {:>8} {:>8} {:>8} {:>6} {:>8} {:>6} | {:>8} {:>8} {:>6} {:>8} {:>6}\n",
            "mode",
            "ms/frame",
            "rel.RMSE",
            "flicker",
            "×truth",
            "uncov.",
            "×truth",
            "rel.RMSE",
            "cold fl.",
            "×truth",
            "uncov.",
            "×truth",
        ));
        if let Some(off) = &self.switch_off {
            out.push_str(&format!(
                "light {} off from measured frame {}; frames until gone (< 5%):{}\n",
                off.light,
                off.frame,
                self.modes
                    .iter()
                    .map(|m| format!(
                        " {} {}",
                        m.label,
                        m.switch_off_frames
                            .map_or_else(|| "never".to_owned(), |f| f.to_string())
                    ))
                    .collect::<String>()
            ));
        }
        let times = |f: f64| f / self.truth_flicker.max(1e-12);
        let times_uncovered = |f: f64| f / self.truth_uncovered_flicker.max(1e-12);
        for m in &self.modes {
            out.push_str(&format!(
                "{:<12} {:>8.1} {:>8.4} {:>8.4} {:>6.2} {:>8.4} {:>6.2} | {:>8.4} {:>8.4} {:>6.2} {:>8.4} {:>6.2}\n",
                m.label,
                m.ms_per_frame,
                m.relative_rmse,
                m.flicker,
                times(m.flicker),
                m.uncovered_flicker,
                times_uncovered(m.uncovered_flicker),
                m.cold_relative_rmse,
                m.cold_flicker,
                times(m.cold_flicker),
                m.cold_uncovered_flicker,
                times_uncovered(m.cold_uncovered_flicker),
            ));
        }
        out
    }

    /// Writes the pictures into `dir`: `plot.png` (cost against error, labelled with flicker),
    /// `flicker-by-frame.png` (each mode's and the truth's flicker at every inner frame) and a
    /// per-pixel flicker map per mode and for the truth (`flicker-LABEL.png`,
    /// `flicker-truth.png`, one shared scale from 0 to the largest 99th percentile, magnified
    /// to at least 256 pixels wide), and `still.png`, the pixels where the truth holds still
    /// (white). Returns the paths written.
    pub fn write_pictures(&self, dir: &Path) -> Result<Vec<PathBuf>, StudyError> {
        let mut written = vec![dir.join("plot.png"), dir.join("flicker-by-frame.png")];
        self.plot(&written[0])?;
        self.plot_by_frame(&written[1])?;
        let maps: Vec<(String, &[f32])> =
            std::iter::once(("truth".to_owned(), &self.truth_flicker_map[..]))
                .chain(
                    self.modes
                        .iter()
                        .map(|m| (file_label(&m.label), &m.flicker_map[..])),
                )
                .collect();
        let top = maps
            .iter()
            .map(|(_, map)| percentile(map, 0.99))
            .fold(f32::MIN_POSITIVE, f32::max);
        let zoom = MAP_WIDTH.div_ceil(self.extent[0].max(1)).max(1);
        let extent = [self.extent[0] * zoom, self.extent[1] * zoom];
        for (label, map) in maps {
            if map.len() != (self.extent[0] * self.extent[1]) as usize {
                continue;
            }
            let path = dir.join(format!("flicker-{label}.png"));
            let map = magnify(map, self.extent, zoom);
            write_map(&path, extent, &map, &vec![true; map.len()], [0.0, top])?;
            written.push(path);
        }
        if self.still.len() == (self.extent[0] * self.extent[1]) as usize {
            let path = dir.join("still.png");
            let values: Vec<f32> = self.still.iter().map(|s| f32::from(u8::from(*s))).collect();
            let values = magnify(&values, self.extent, zoom);
            write_map(
                &path,
                extent,
                &values,
                &vec![true; values.len()],
                [0.0, 1.0],
            )?;
            written.push(path);
        }
        Ok(written)
    }

    /// Draws cost (x) against error (y), each mode a point labelled with its flicker, into
    /// `path` (PNG).
    fn plot(&self, path: &Path) -> Result<(), StudyError> {
        write_drawing(path, PLOT_SIZE, |rgb, [w, h]| self.draw(rgb, (w, h)))
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

    /// Draws each mode's flicker at every inner frame, and the truth's, into `path` (PNG).
    fn plot_by_frame(&self, path: &Path) -> Result<(), StudyError> {
        write_drawing(path, PLOT_SIZE, |rgb, [w, h]| {
            self.draw_by_frame(rgb, (w, h))
        })
    }

    fn draw_by_frame(
        &self,
        rgb: &mut [u8],
        size: (u32, u32),
    ) -> Result<(), Box<dyn std::error::Error>> {
        let root =
            BitMapBackend::<RGBPixel>::with_buffer_and_format(rgb, size)?.into_drawing_area();
        root.fill(&WHITE)?;
        let curves: Vec<(&str, &[f64], RGBAColor)> =
            std::iter::once(("truth", &self.truth_flicker_by_frame[..], BLACK.to_rgba()))
                .chain(self.modes.iter().enumerate().map(|(i, m)| {
                    (
                        m.label.as_str(),
                        &m.flicker_by_frame[..],
                        Palette99::pick(i).to_rgba(),
                    )
                }))
                .collect();
        let frames = curves.iter().map(|c| c.1.len()).max().unwrap_or(0).max(2);
        let top = curves
            .iter()
            .flat_map(|c| c.1.iter().copied())
            .fold(1e-6, f64::max)
            * 1.1;
        let mut builder = ChartBuilder::on(&root);
        builder.margin(16);
        let labels = font().is_some();
        if labels {
            builder.x_label_area_size(40).y_label_area_size(56);
        }
        let mut chart = builder.build_cartesian_2d(1.0..frames as f64, 0.0..top)?;
        let mut mesh = chart.configure_mesh();
        if labels {
            mesh.x_desc("frame k (second difference around it)")
                .y_desc("flicker (RMS 2nd difference / mean)");
        } else {
            mesh.disable_x_axis().disable_y_axis();
        }
        mesh.draw()?;
        for (label, values, colour) in curves {
            let points = values.iter().enumerate().map(|(k, v)| ((k + 1) as f64, *v));
            let series = chart.draw_series(LineSeries::new(points, colour.stroke_width(2)))?;
            if labels {
                series.label(label).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
            }
        }
        if labels {
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::UpperRight)
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()?;
        }
        root.present()?;
        Ok(())
    }
}
