//! The study's pictures: the log-log error plot (plotters, bitmap backend), per-pixel maps on a
//! colour ramp, and tonemapped previews. Every file is written atomically
//! ([`crate::capture::image_io::write_png`]).
//!
//! Text needs a TrueType font, and shine ships none and links no system font library: the plot
//! is labelled with the first font found at run time (`SHINE_PLOT_FONT`, else a few usual
//! paths of DejaVu Sans or Liberation Sans); without one it is drawn without any text, and the
//! axis ranges are in the study's report ([`ErrorPlot`]).

use std::path::Path;
use std::sync::OnceLock;

use glam::Vec3;
use plotters::backend::RGBPixel;
use plotters::prelude::*;

use super::StudyError;
use crate::capture::image_io::{LdrImage, write_png};
use crate::capture::tonemap::{DEFAULT_TONEMAP, encode_ldr};

/// Where a sans-serif TrueType font is usually found (Debian/Ubuntu, Fedora, Arch, macOS,
/// Windows).
const FONT_PATHS: [&str; 7] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu-sans-fonts/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
    "/System/Library/Fonts/Supplemental/Arial.ttf",
    "C:\\Windows\\Fonts\\arial.ttf",
];

/// The font the plots' text is drawn with, loaded and registered once (`None`: no text).
pub(crate) fn font() -> Option<&'static str> {
    static FONT: OnceLock<Option<(String, Vec<u8>)>> = OnceLock::new();
    let loaded = FONT.get_or_init(|| {
        let chosen = std::env::var("SHINE_PLOT_FONT").ok();
        let candidates = chosen
            .iter()
            .map(String::as_str)
            .chain(FONT_PATHS.iter().copied().filter(|_| chosen.is_none()));
        candidates
            .filter_map(|path| Some((path.to_owned(), std::fs::read(path).ok()?)))
            .next()
    });
    let (path, bytes) = loaded.as_ref()?;
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    let ok = *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes).is_ok()
    });
    ok.then_some(path.as_str())
}

/// One curve of the error plot.
#[derive(Debug, Clone)]
pub struct Curve {
    /// Legend text.
    pub label: String,
    /// `(average spp, relative RMSE)` points, spp increasing.
    pub points: Vec<(f64, f64)>,
    /// Line colour (RGB).
    pub colour: [u8; 3],
}

/// What an error plot shows, for a reader without its labels.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ErrorPlot {
    /// The x axis (average spp, logarithmic) from, to.
    pub spp_axis: [f64; 2],
    /// The y axis (relative RMSE, logarithmic) from, to.
    pub error_axis: [f64; 2],
    /// The font the text was drawn with; `None`: drawn without text (no font found).
    pub font: Option<String>,
}

/// The least and greatest of `values` that are positive and finite (what a logarithmic axis
/// can show); `None` when there is none.
pub fn positive_bounds(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    (lo <= hi).then_some((lo, hi))
}

/// A logarithmic axis range around `values` (positive, finite), with some room.
fn log_range(values: impl Iterator<Item = f64>) -> [f64; 2] {
    let Some((lo, hi)) = positive_bounds(values) else {
        return [0.1, 1.0];
    };
    let (lo, hi) = (lo / 1.25, hi * 1.25);
    if hi / lo < 2.0 {
        [lo / 2.0, hi * 2.0]
    } else {
        [lo, hi]
    }
}

/// Ticks at the powers of two in `[lo, hi]` (the spp axis).
fn powers_of_two([lo, hi]: [f64; 2]) -> Vec<f64> {
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Vec::new();
    }
    let first = lo.log2().ceil() as i32;
    let last = hi.log2().floor() as i32;
    (first..=last).map(|k| 2f64.powi(k)).collect()
}

/// Ticks at 1, 2 and 5 times the powers of ten in `[lo, hi]` (the error axis).
pub(crate) fn one_two_five([lo, hi]: [f64; 2]) -> Vec<f64> {
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Vec::new();
    }
    let first = lo.log10().floor() as i32;
    let last = hi.log10().ceil() as i32;
    (first..=last)
        .flat_map(|k| [1.0, 2.0, 5.0].map(|m| m * 10f64.powi(k)))
        .filter(|v| (lo..=hi).contains(v))
        .collect()
}

/// A tick label: two significant digits, no trailing zeros (0.015, 0.5, 2, 300); the lab's
/// Pareto plot labels its axes with it too.
pub(crate) fn tick(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return format!("{v}");
    }
    let digits = (1 - v.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_owned()
    } else {
        s
    }
}

/// What the error plot marks besides its curves.
#[derive(Debug, Clone, Copy, Default)]
pub struct Marks {
    /// The equal-error construction: AAF's error and the uniform spp that reaches it.
    pub crossing: Option<(f64, f64)>,
    /// The truth's own noise (relative RMSE): a horizontal line every error sits above.
    pub floor: Option<f64>,
}

/// Draws the curves on log-log axes with the `marks`, and writes the plot to `path` (PNG,
/// `size` pixels).
pub fn error_plot(
    path: &Path,
    title: &str,
    curves: &[Curve],
    marks: Marks,
    size: [u32; 2],
) -> Result<ErrorPlot, StudyError> {
    let all = || curves.iter().flat_map(|c| c.points.iter().copied());
    let crossing = marks.crossing;
    let spp_axis = log_range(all().map(|p| p.0).chain(crossing.map(|c| c.0)));
    let error_axis = log_range(
        all()
            .map(|p| p.1)
            .chain(crossing.map(|c| c.1))
            .chain(marks.floor),
    );
    let font = font();
    let plot = ErrorPlot {
        spp_axis,
        error_axis,
        font: font.map(str::to_owned),
    };
    write_drawing(path, size, |rgb, size| {
        draw_error_plot(rgb, size, title, curves, marks, &plot)
    })?;
    Ok(plot)
}

/// A drawing on a white `size` canvas (RGB, row-major) written to `path` (PNG): the one way the
/// studies' plots reach a file.
pub(crate) fn write_drawing(
    path: &Path,
    [w, h]: [u32; 2],
    draw: impl FnOnce(&mut [u8], [u32; 2]) -> Result<(), Box<dyn std::error::Error>>,
) -> Result<(), StudyError> {
    let mut rgb = vec![255u8; w as usize * h as usize * 3];
    draw(&mut rgb, [w, h]).map_err(|e| StudyError::Plot(format!("{}: {e}", path.display())))?;
    let texels = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2], 255])
        .collect();
    write_png(
        path,
        &LdrImage {
            width: w,
            height: h,
            texels,
        },
    )?;
    Ok(())
}

/// The drawing of [`error_plot`] into an RGB buffer.
fn draw_error_plot(
    rgb: &mut [u8],
    [w, h]: [u32; 2],
    title: &str,
    curves: &[Curve],
    marks: Marks,
    plot: &ErrorPlot,
) -> Result<(), Box<dyn std::error::Error>> {
    let labels = plot.font.is_some();
    let backend = BitMapBackend::<RGBPixel>::with_buffer_and_format(rgb, (w, h))?;
    let root = backend.into_drawing_area();
    root.fill(&WHITE)?;
    let [x0, x1] = plot.spp_axis;
    let [y0, y1] = plot.error_axis;
    let mut builder = ChartBuilder::on(&root);
    builder.margin(16);
    if labels {
        builder
            .caption(title, ("sans-serif", 20))
            .x_label_area_size(44)
            .y_label_area_size(64);
    }
    let (x_keys, y_keys) = (powers_of_two([x0, x1]), one_two_five([y0, y1]));
    let mut chart = builder.build_cartesian_2d(
        (x0..x1).log_scale().with_key_points(x_keys),
        (y0..y1).log_scale().with_key_points(y_keys),
    )?;
    let mut mesh = chart.configure_mesh();
    if labels {
        mesh.x_desc("average samples per pixel")
            .y_desc("relative RMS error")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .light_line_style(RGBColor(235, 235, 235))
            .label_style(("sans-serif", 14));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw()?;
    for curve in curves {
        let [r, g, b] = curve.colour;
        let colour = RGBColor(r, g, b);
        let series = chart.draw_series(LineSeries::new(
            curve.points.iter().copied(),
            colour.stroke_width(2),
        ))?;
        if labels {
            series.label(curve.label.as_str()).legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        }
        chart.draw_series(
            curve
                .points
                .iter()
                .map(|p| Circle::new(*p, 3, colour.filled())),
        )?;
    }
    if let Some(floor) = marks.floor {
        let grey = RGBColor(160, 160, 160);
        let series = chart.draw_series(LineSeries::new(vec![(x0, floor), (x1, floor)], grey))?;
        if labels {
            series
                .label("truth's own noise")
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
        }
    }
    if let Some((n, e)) = marks.crossing {
        // The equal-error construction: AAF's error across to the uniform curve, down to its spp.
        let grey = RGBColor(96, 96, 96);
        chart.draw_series(LineSeries::new(vec![(x0, e), (n, e), (n, y0)], grey))?;
        chart.draw_series(std::iter::once(Cross::new((n, e), 6, grey.stroke_width(2))))?;
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

/// Viridis at nine stops (perceptually uniform, readable in grey and by colour-blind readers).
const RAMP: [[f32; 3]; 9] = [
    [68.0, 1.0, 84.0],
    [71.0, 44.0, 122.0],
    [59.0, 81.0, 139.0],
    [44.0, 113.0, 142.0],
    [33.0, 144.0, 141.0],
    [39.0, 173.0, 129.0],
    [92.0, 200.0, 99.0],
    [170.0, 220.0, 50.0],
    [253.0, 231.0, 37.0],
];

/// The ramp's colour at `t` in [0, 1] (clamped).
pub fn ramp(t: f32) -> [u8; 4] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (RAMP.len() - 1) as f32;
    let i = (x.floor() as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    let (a, b) = (RAMP[i], RAMP[i + 1]);
    let c = |k: usize| (a[k] + f * (b[k] - a[k])).round().clamp(0.0, 255.0) as u8;
    [c(0), c(1), c(2), 255]
}

/// Rows of the ramp bar under a map.
const BAR_ROWS: u32 = 8;

/// Writes `values` (row-major, `extent`) on the colour ramp from `range[0]` to `range[1]`, with
/// the pixels where `mask` is false black, and the ramp itself as a bar under the map.
pub fn write_map(
    path: &Path,
    extent: [u32; 2],
    values: &[f32],
    mask: &[bool],
    range: [f32; 2],
) -> Result<(), StudyError> {
    let span = (range[1] - range[0]).max(f32::MIN_POSITIVE);
    let texels = values
        .iter()
        .zip(mask)
        .map(|(v, m)| {
            if *m {
                ramp((v - range[0]) / span)
            } else {
                [0, 0, 0, 255]
            }
        })
        .collect();
    write_with_bar(path, extent, texels, ramp)
}

/// A diverging ramp: blue at −1, white at 0, red at +1 (clamped).
pub fn diverging(t: f32) -> [u8; 4] {
    let t = if t.is_finite() {
        t.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (far, f) = if t < 0.0 {
        ([33.0, 102.0, 172.0], -t)
    } else {
        ([178.0, 24.0, 43.0], t)
    };
    let c = |k: usize| (255.0 + f * (far[k] - 255.0)).round().clamp(0.0, 255.0) as u8;
    [c(0), c(1), c(2), 255]
}

/// Writes signed `values` on the diverging ramp from `−range` to `+range`, the pixels where
/// `mask` is false black, with the ramp as a bar under the map.
pub fn write_signed_map(
    path: &Path,
    extent: [u32; 2],
    values: &[f32],
    mask: &[bool],
    range: f32,
) -> Result<(), StudyError> {
    let scale = range.max(f32::MIN_POSITIVE);
    let texels = values.iter().zip(mask).map(|(v, m)| {
        if *m {
            diverging(v / scale)
        } else {
            [0, 0, 0, 255]
        }
    });
    let bar = |t: f32| diverging(2.0 * t - 1.0);
    write_with_bar(path, extent, texels.collect(), bar)
}

/// Writes `texels` (row-major, `extent`) with a bar of `bar(0 … 1)` under them.
fn write_with_bar(
    path: &Path,
    [w, h]: [u32; 2],
    mut texels: Vec<[u8; 4]>,
    bar: impl Fn(f32) -> [u8; 4],
) -> Result<(), StudyError> {
    for row in 0..BAR_ROWS {
        texels.extend((0..w).map(|x| {
            if row < 2 {
                [0, 0, 0, 255]
            } else {
                bar(x as f32 / (w.max(2) - 1) as f32)
            }
        }));
    }
    write_png(
        path,
        &LdrImage {
            width: w,
            height: h + BAR_ROWS,
            texels,
        },
    )?;
    Ok(())
}

/// Writes linear radiance scaled by `exposure`, tonemapped with [`DEFAULT_TONEMAP`] and
/// sRGB-encoded.
pub fn write_tonemapped(
    path: &Path,
    extent: [u32; 2],
    image: &[[f32; 3]],
    exposure: f32,
) -> Result<(), StudyError> {
    let texels = image
        .iter()
        .map(|t| encode_ldr(DEFAULT_TONEMAP, Vec3::from_array(*t) * exposure))
        .collect();
    write_png(
        path,
        &LdrImage {
            width: extent[0],
            height: extent[1],
            texels,
        },
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_ends_and_clamps() {
        assert_eq!(ramp(0.0), [68, 1, 84, 255]);
        assert_eq!(ramp(1.0), [253, 231, 37, 255]);
        assert_eq!(ramp(2.0), ramp(1.0));
        assert_eq!(ramp(f32::NAN), ramp(0.0));
        assert_eq!(ramp(0.5), [33, 144, 141, 255]);
        assert_eq!(diverging(0.0), [255, 255, 255, 255]);
        assert_eq!(diverging(-3.0), [33, 102, 172, 255]);
        assert_eq!(diverging(1.0), [178, 24, 43, 255]);
    }

    #[test]
    fn log_ranges_have_room() {
        let [lo, hi] = log_range([1.0, 256.0].into_iter());
        assert!(lo < 1.0 && hi > 256.0);
        assert_eq!(log_range(std::iter::empty()), [0.1, 1.0]);
        assert_eq!(
            powers_of_two([0.8, 300.0]),
            [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0, 256.0]
        );
        assert_eq!(one_two_five([0.015, 0.3]), [0.02, 0.05, 0.1, 0.2]);
        assert_eq!(tick(0.0153), "0.015");
        assert_eq!(tick(0.5), "0.5");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(300.0), "300");
        let [lo, hi] = log_range([0.5].into_iter());
        assert!(lo < 0.5 && hi > 0.5 && hi / lo >= 2.0);
    }
}
