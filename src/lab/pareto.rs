//! The Pareto front of a scene's points (frame time against still-frame error, both to be
//! minimised) and its plot: every configuration as a dot coloured by its flicker, the front as
//! a staircase through the configurations nothing beats on both counts.
//!
//! The plot's text needs a TrueType font, found at run time as the studies' plots find theirs
//! ([`crate::study::plot`]); without one the plot is drawn without any text. Files are written
//! atomically ([`crate::capture::image_io::write_png`]).

use std::path::Path;

use plotters::backend::RGBPixel;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::{LabError, LabPoint};
use crate::capture::image_io::{LdrImage, write_png};
use crate::study::plot::{font, one_two_five, ramp, tick};

/// Size of the Pareto plot in pixels.
pub const PLOT_SIZE: [u32; 2] = [900, 600];

/// The flicker ratio (over the truth's) at the top of the colour key; 1× is at its bottom.
/// The key is logarithmic, so each factor of two is the same step of colour.
pub const FLICKER_SPAN: f64 = 64.0;

/// The ratios the colour key is labelled at.
const KEY_TICKS: [f64; 4] = [1.0, 4.0, 16.0, 64.0];

/// Width of the colour key beside the chart, pixels.
const KEY_WIDTH: u32 = 120;

/// Colour of a point whose flicker ratio is unknown (not a number, or negative).
const UNKNOWN: RGBColor = RGBColor(150, 150, 150);

/// The indices into `points` of the Pareto-optimal ones for least `cost.frame_ms` and least
/// `error.relative_rmse`, sorted by frame time ascending (so by error descending).
///
/// These are the configurations worth choosing between: a point is on the front when no
/// other point is at most as slow and at most as wrong while strictly better on one of the
/// two. Of exact duplicates only the first is kept; a point with a non-finite time or error
/// is never on the front and beats no other.
pub fn front(points: &[&LabPoint]) -> Vec<usize> {
    let finite: Vec<(usize, f64, f64)> = points
        .iter()
        .enumerate()
        .map(|(i, p)| (i, p.cost.frame_ms, p.error.relative_rmse))
        .filter(|(_, ms, err)| ms.is_finite() && err.is_finite())
        .collect();
    let beaten = |&(i, ms, err): &(usize, f64, f64)| {
        finite.iter().any(|&(j, other_ms, other_err)| {
            let no_worse = other_ms <= ms && other_err <= err;
            let better = other_ms < ms || other_err < err;
            // Neither better nor worse: an exact duplicate, of which the first stays.
            no_worse && (better || j < i)
        })
    };
    let mut on: Vec<(usize, f64, f64)> = finite.iter().copied().filter(|p| !beaten(p)).collect();
    on.sort_by(|a, b| {
        a.1.total_cmp(&b.1)
            .then(a.2.total_cmp(&b.2))
            .then(a.0.cmp(&b.0))
    });
    on.into_iter().map(|(i, _, _)| i).collect()
}

/// Draws the scene's points (frame ms against relative RMSE, both logarithmic,
/// coloured by [`crate::lab::Motion::flicker_ratio`] from 1× to [`FLICKER_SPAN`]×) with the
/// Pareto `front` (indices into `points`, as [`front`] gives them) as a staircase through
/// its labelled points, and writes it to `path` (PNG, [`PLOT_SIZE`]), atomically.
///
/// One picture shows what each configuration costs, how wrong it is and how much it
/// flickers, and which configurations are worth their cost. Points whose time or error is
/// not positive and finite cannot be placed on log axes and are left out; out-of-range
/// indices in `front` are ignored. Titled with `scene`; drawn without text when no font is
/// found.
pub fn write_plot(
    path: &Path,
    scene: &str,
    points: &[&LabPoint],
    front: &[usize],
) -> Result<(), LabError> {
    let image = render(scene, points, front, PLOT_SIZE, font().is_some())
        .map_err(|e| LabError::Plot(format!("{}: {e}", path.display())))?;
    write_png(path, &image)?;
    Ok(())
}

/// The plot of [`write_plot`] as an image of `[w, h]` pixels, with text when `labels`.
fn render(
    scene: &str,
    points: &[&LabPoint],
    front: &[usize],
    [w, h]: [u32; 2],
    labels: bool,
) -> Result<LdrImage, Box<dyn std::error::Error>> {
    let mut rgb = vec![255u8; w as usize * h as usize * 3];
    draw(&mut rgb, (w, h), scene, points, front, labels)?;
    let texels = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2], 255])
        .collect();
    Ok(LdrImage {
        width: w,
        height: h,
        texels,
    })
}

/// Where a point sits on the plot: `(frame ms, relative RMSE)`, when both are positive and
/// finite (log axes).
fn placed(p: &LabPoint) -> Option<(f64, f64)> {
    let (ms, err) = (p.cost.frame_ms, p.error.relative_rmse);
    let ok = |v: f64| v.is_finite() && v > 0.0;
    (ok(ms) && ok(err)).then_some((ms, err))
}

/// The colour of a flicker ratio: log2 of it over 1×..[`FLICKER_SPAN`]× on the ramp
/// (clamped), grey when there is none (0: the truth holds still or is too noisy to say) or it
/// is not a number.
fn flicker_colour(ratio: f64) -> RGBColor {
    if ratio.is_nan() || ratio <= 0.0 {
        return UNKNOWN;
    }
    let t = ratio.log2() / FLICKER_SPAN.log2();
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let [r, g, b, _] = ramp(t as f32);
    RGBColor(r, g, b)
}

/// A logarithmic axis range around `values` (positive, finite), with some room; a decade
/// at least.
fn log_range(values: impl Iterator<Item = f64>) -> [f64; 2] {
    let Some((lo, hi)) = crate::study::plot::positive_bounds(values) else {
        return [0.1, 1.0];
    };
    let (lo, hi) = (lo / 1.3, hi * 1.3);
    let short = 10.0 / (hi / lo);
    if short > 1.0 {
        let widen = short.sqrt();
        [lo / widen, hi * widen]
    } else {
        [lo, hi]
    }
}

/// Ticks of a logarithmic axis `[lo, hi]`: 1, 2 and 5 times the powers of ten inside it, or
/// every digit's when that gives fewer than three.
fn log_ticks([lo, hi]: [f64; 2]) -> Vec<f64> {
    if !(lo > 0.0 && hi >= lo && hi.is_finite()) {
        return Vec::new();
    }
    let coarse = one_two_five([lo, hi]);
    if coarse.len() >= 3 {
        return coarse;
    }
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    (first..=last)
        .flat_map(|k| (1..=9).map(move |m| f64::from(m) * 10f64.powi(k)))
        .filter(|v| (lo..=hi).contains(v))
        .collect()
}

/// The drawing of [`write_plot`] into an RGB buffer of `size`.
fn draw(
    rgb: &mut [u8],
    size: (u32, u32),
    scene: &str,
    points: &[&LabPoint],
    front: &[usize],
    labels: bool,
) -> Result<(), Box<dyn std::error::Error>> {
    let root = BitMapBackend::<RGBPixel>::with_buffer_and_format(rgb, size)?.into_drawing_area();
    root.fill(&WHITE)?;
    let body = if labels {
        root.titled(scene, ("sans-serif", 22))?
    } else {
        root.clone()
    };
    let (plot_area, key_area) = body.split_horizontally(size.0.saturating_sub(KEY_WIDTH));

    let placed_points: Vec<(f64, f64, &LabPoint)> = points
        .iter()
        .filter_map(|p| placed(p).map(|(x, y)| (x, y, *p)))
        .collect();
    let x_axis = log_range(placed_points.iter().map(|p| p.0));
    let y_axis = log_range(placed_points.iter().map(|p| p.1));
    let [x0, x1] = x_axis;
    let [y0, y1] = y_axis;

    let mut builder = ChartBuilder::on(&plot_area);
    builder.margin(16);
    if labels {
        builder.x_label_area_size(44).y_label_area_size(64);
    }
    let mut chart = builder.build_cartesian_2d(
        (x0..x1).log_scale().with_key_points(log_ticks(x_axis)),
        (y0..y1).log_scale().with_key_points(log_ticks(y_axis)),
    )?;
    let mut mesh = chart.configure_mesh();
    mesh.light_line_style(RGBColor(235, 235, 235));
    if labels {
        mesh.x_desc("frame ms")
            .y_desc("relative RMSE")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style(("sans-serif", 14));
    } else {
        mesh.x_labels(0).y_labels(0);
    }
    mesh.draw()?;

    // The front, fastest first, as the boundary of what it beats: down from the top of the
    // chart to the fastest point, then right and down from each point to the next, then right
    // to the edge from the least wrong.
    let mut on: Vec<(f64, f64, &LabPoint)> = front
        .iter()
        .filter_map(|&i| points.get(i))
        .filter_map(|p| placed(p).map(|(x, y)| (x, y, *p)))
        .collect();
    on.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
    if let (Some(first), Some(last)) = (on.first(), on.last()) {
        let mut stairs = vec![(first.0, y1), (first.0, first.1)];
        for pair in on.windows(2) {
            let (a, b) = (pair[0], pair[1]);
            stairs.extend([(b.0, a.1), (b.0, b.1)]);
        }
        stairs.push((x1, last.1));
        let ink = RGBColor(40, 40, 40);
        chart.draw_series(LineSeries::new(stairs, ink.stroke_width(2)))?;
    }

    let outline = RGBColor(90, 90, 90);
    for &(x, y, p) in &placed_points {
        let colour = flicker_colour(p.motion.flicker_ratio);
        chart.draw_series([
            Circle::new((x, y), 6, colour.filled()),
            Circle::new((x, y), 6, outline.stroke_width(1)),
        ])?;
    }
    for &(x, y, _) in &on {
        chart.draw_series([Circle::new((x, y), 9, BLACK.stroke_width(2))])?;
    }
    if labels {
        // Beside the point, above the front's line; on the left near the right edge.
        let span = (x1 / x0).ln().max(f64::MIN_POSITIVE);
        for &(x, y, p) in &on {
            let right_side = (x / x0).ln() / span > 0.75;
            let (dx, h) = if right_side {
                (-10, HPos::Right)
            } else {
                (10, HPos::Left)
            };
            let style = ("sans-serif", 14)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(h, VPos::Bottom));
            let label =
                EmptyElement::at((x, y)) + Text::new(p.config.label.clone(), (dx, -6), style);
            chart.draw_series(std::iter::once(label))?;
        }
    }

    draw_key(&key_area, labels)?;
    root.present()?;
    Ok(())
}

/// The colour key of the flicker ratio: a vertical bar from 1× (bottom) to
/// [`FLICKER_SPAN`]× (top), with its ticks labelled when `labels`.
fn draw_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    labels: bool,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (_, h) = area.dim_in_pixel();
    let (left, right) = (16i32, 36i32);
    let top = 84i32;
    let bottom = (h as i32 - 90).max(top + 16);
    let rows = bottom - top;
    for row in 0..rows {
        // Row 0 is the top: the largest ratio.
        let t = 1.0 - f64::from(row) / f64::from((rows - 1).max(1));
        let colour = flicker_colour(FLICKER_SPAN.powf(t));
        let y = top + row;
        area.draw(&Rectangle::new(
            [(left, y), (right, y + 1)],
            colour.filled(),
        ))?;
    }
    area.draw(&Rectangle::new(
        [(left, top), (right, bottom)],
        BLACK.stroke_width(1),
    ))?;
    for ratio in KEY_TICKS {
        let t = ratio.log2() / FLICKER_SPAN.log2();
        let y = bottom - (t * f64::from(rows)).round() as i32;
        area.draw(&PathElement::new(
            vec![(right, y), (right + 5, y)],
            BLACK.stroke_width(1),
        ))?;
        if labels {
            let style = ("sans-serif", 14)
                .into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Center));
            area.draw(&Text::new(format!("{ratio}×"), (right + 8, y), style))?;
        }
    }
    if labels {
        let style = ("sans-serif", 13)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Bottom));
        area.draw(&Text::new("flicker", (left - 8, top - 24), style.clone()))?;
        area.draw(&Text::new("over truth's", (left - 8, top - 8), style))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capture::image_io::read_png;
    use crate::lab::{Cost, LabConfig, Motion, StillError};

    fn point(label: &str, frame_ms: f64, relative_rmse: f64, flicker_ratio: f64) -> LabPoint {
        LabPoint {
            scene: "builtin:cornell-box".to_owned(),
            config: LabConfig {
                label: label.to_owned(),
                set: vec![("gi".to_owned(), "hvl".to_owned())],
            },
            error: StillError {
                relative_rmse,
                energy_ratio: 1.0,
                flip: 0.1,
                regions: vec![relative_rmse; 16],
                region_energy: vec![1.0; 16],
            },
            cost: Cost {
                frame_ms,
                passes: vec![("gather".to_owned(), frame_ms)],
                clock: "gpu".to_owned(),
            },
            motion: Motion {
                flicker: 0.01 * flicker_ratio,
                cold_flicker: 0.02,
                truth_flicker: 0.01,
                truth_flicker_noise_free: 0.005,
                flicker_ratio,
                sequence_rmse: relative_rmse,
                cold_rmse: relative_rmse,
                lag: 0.0,
            },
            image: format!("{label}.png"),
            flip_map: format!("{label}.flip.png"),
        }
    }

    fn front_of(points: &[LabPoint]) -> Vec<usize> {
        let refs: Vec<&LabPoint> = points.iter().collect();
        front(&refs)
    }

    #[test]
    fn front_excludes_dominated_points_and_sorts_by_time() {
        let points = [
            point("slow-exact", 8.0, 0.05, 1.0),
            point("dominated", 3.0, 0.3, 1.0),
            point("fast-rough", 1.0, 0.5, 1.0),
            point("middle", 2.0, 0.2, 1.0),
            point("slower-same-error", 9.0, 0.05, 1.0),
            point("same-time-worse", 2.0, 0.25, 1.0),
        ];
        assert_eq!(front_of(&points), [2, 3, 0]);
        assert!(front_of(&[]).is_empty());
        assert_eq!(front_of(&points[..1]), [0]);
    }

    #[test]
    fn front_keeps_the_corners() {
        // The fastest and the least wrong are always on it, however far from the others.
        let points = [
            point("a", 5.0, 0.1, 1.0),
            point("least-wrong", 100.0, 0.001, 1.0),
            point("b", 4.0, 0.2, 1.0),
            point("fastest", 0.01, 10.0, 1.0),
        ];
        let f = front_of(&points);
        assert_eq!(f.first(), Some(&3));
        assert_eq!(f.last(), Some(&1));
        assert_eq!(f, [3, 2, 0, 1]);
    }

    #[test]
    fn front_handles_ties() {
        let points = [
            point("twin-b", 2.0, 0.2, 1.0),
            point("other", 1.0, 0.4, 1.0),
            point("twin-a", 2.0, 0.2, 1.0),
            point("same-error-slower", 3.0, 0.2, 1.0),
            point("same-time-worse", 1.0, 0.5, 1.0),
        ];
        // Of the exact duplicates the first stays; an equal time or error with the other worse
        // is beaten.
        assert_eq!(front_of(&points), [1, 0]);
        let all_same = [
            point("x", 1.0, 0.1, 1.0),
            point("y", 1.0, 0.1, 1.0),
            point("z", 1.0, 0.1, 1.0),
        ];
        assert_eq!(front_of(&all_same), [0]);
    }

    #[test]
    fn front_ignores_non_finite_values() {
        let points = [
            point("nan-error", 0.5, f64::NAN, 1.0),
            point("good", 2.0, 0.2, 1.0),
            point("neg-inf-time", f64::NEG_INFINITY, 0.01, 1.0),
            point("nan-time", f64::NAN, 0.0, 1.0),
            point("inf-error", 0.1, f64::INFINITY, 1.0),
            point("fast", 1.0, 0.3, 1.0),
        ];
        // None of the non-finite points is on the front, nor beats a finite one.
        assert_eq!(front_of(&points), [5, 1]);
        let only_bad = [point("nan", f64::NAN, f64::NAN, 1.0)];
        assert!(front_of(&only_bad).is_empty());
    }

    #[test]
    fn flicker_colours_span_the_ramp() {
        let rgb = |[r, g, b, _]: [u8; 4]| RGBColor(r, g, b);
        assert_eq!(flicker_colour(1.0), rgb(ramp(0.0)));
        assert_eq!(flicker_colour(0.5), rgb(ramp(0.0)));
        assert_eq!(flicker_colour(0.0), UNKNOWN);
        assert_eq!(flicker_colour(8.0), rgb(ramp(0.5)));
        assert_eq!(flicker_colour(FLICKER_SPAN), rgb(ramp(1.0)));
        assert_eq!(flicker_colour(f64::INFINITY), rgb(ramp(1.0)));
        assert_eq!(flicker_colour(f64::NAN), UNKNOWN);
        assert_eq!(flicker_colour(-1.0), UNKNOWN);
    }

    #[test]
    fn axes_ticks_and_labels() {
        let [lo, hi] = log_range([0.5, 40.0].into_iter());
        assert!(lo < 0.5 && hi > 40.0);
        let [lo, hi] = log_range([0.2].into_iter());
        assert!(lo < 0.2 && hi > 0.2 && hi / lo >= 9.99);
        assert_eq!(log_range(std::iter::empty()), [0.1, 1.0]);
        assert_eq!(log_range([f64::NAN, -1.0].into_iter()), [0.1, 1.0]);
        assert_eq!(log_ticks([0.015, 0.3]), [0.02, 0.05, 0.1, 0.2]);
        assert_eq!(log_ticks([1.5, 4.5]), [2.0, 3.0, 4.0]);
        assert!(log_ticks([f64::NAN, 1.0]).is_empty());
        assert_eq!(tick(0.0153), "0.015");
        assert_eq!(tick(2.0), "2");
        assert_eq!(tick(300.0), "300");
    }

    fn sample_points() -> Vec<LabPoint> {
        vec![
            point("hvl", 2.0, 0.08, 1.5),
            point("hvl.count=256", 6.5, 0.03, 3.0),
            point("igi", 1.2, 0.2, 20.0),
            point("proxy", 0.4, 0.6, 1.0),
            point("aaf", 12.0, 0.02, 70.0),
            point("dominated", 7.0, 0.5, f64::NAN),
            point("broken", f64::NAN, 0.1, 2.0),
            point("zero-time", 0.0, 0.9, 2.0),
        ]
    }

    fn distinct_colours(image: &LdrImage) -> usize {
        let mut seen: Vec<[u8; 4]> = image.texels.clone();
        seen.sort_unstable();
        seen.dedup();
        seen.len()
    }

    #[test]
    fn plot_writes_a_png_of_the_size() {
        let points = sample_points();
        let refs: Vec<&LabPoint> = points.iter().collect();
        let f = front(&refs);
        // On the front, but not on log axes: left out of the plot.
        assert_eq!(f, [7, 3, 2, 0, 1, 4]);
        let path = std::env::temp_dir().join(format!(
            "shine-lab-pareto-{}-{:?}.png",
            std::process::id(),
            std::thread::current().id()
        ));
        let written = write_plot(&path, "builtin:cornell-box", &refs, &f);
        let read = read_png(&path);
        let _ = std::fs::remove_file(&path);
        written.expect("the plot is written");
        let image = read.expect("the plot decodes");
        assert_eq!([image.width, image.height], PLOT_SIZE);
        assert!(distinct_colours(&image) > 16, "a plot, not a blank");
    }

    #[test]
    fn plot_draws_without_text_and_without_points() {
        let points = sample_points();
        let refs: Vec<&LabPoint> = points.iter().collect();
        let f = front(&refs);
        let bare = render("scene", &refs, &f, PLOT_SIZE, false).expect("drawn without text");
        assert_eq!([bare.width, bare.height], PLOT_SIZE);
        assert!(distinct_colours(&bare) > 16);
        // No points, or an out-of-range front index: an empty chart, not an error.
        let empty = render("scene", &[], &[3], [300, 200], false).expect("an empty chart");
        assert!(distinct_colours(&empty) > 1);
        if font().is_some() {
            let labelled = render("scene", &refs, &f, PLOT_SIZE, true).expect("drawn with text");
            assert_ne!(labelled, bare, "the text shows");
        }
    }
}
