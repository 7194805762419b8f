//! The lab's `index.html`: one self-contained page (every image inlined as a `data:` URI, so it
//! opens from disk without a server) with the run's conditions, each scene's Pareto plot, its
//! truth beside the Pareto front's images and FLIP maps, a table of every point, and the
//! failures.
//!
//! The page counts its own images once loaded: the body gets `data-images-loaded="N/T"` and
//! the title `lab: N/T images`, so a headless browser can check that every image decodes
//! (`tests/lab_page.rs`).

use std::path::{Path, PathBuf};

use base64::Engine as _;
use base64::engine::general_purpose::STANDARD;

use super::{LabError, LabPoint, LabReport};
use crate::capture::image_io::write_bytes_atomically;

/// The page's style: small images scaled up without smoothing, front rows highlighted.
const STYLE: &str = "body{font-family:sans-serif;margin:24px;color:#222;background:#fff}\
h2{margin-top:40px;border-bottom:1px solid #ccc}\
dl{display:grid;grid-template-columns:max-content auto;gap:2px 16px}dt{font-weight:bold}\
.row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}\
figure{margin:0}figure img{display:block;image-rendering:pixelated;width:192px}\
figcaption{font-size:13px;max-width:192px;overflow-wrap:anywhere}\
img.plot{max-width:100%;margin-bottom:16px}\
table{border-collapse:collapse;font-size:13px}\
th,td{border:1px solid #ccc;padding:3px 8px;text-align:right}\
td.text,th.text{text-align:left}tr.front{background:#fff3c4;font-weight:bold}\
.failures li{color:#a00}";

/// Once the page has loaded, counts the images that decoded and says so on the body and in the
/// title.
const SCRIPT: &str = "window.addEventListener('load',function(){\
var images=document.images,loaded=0;\
for(var i=0;i<images.length;i++){if(images[i].complete&&images[i].naturalWidth>0){loaded++;}}\
document.body.dataset.imagesLoaded=loaded+'/'+images.length;\
document.title='lab: '+loaded+'/'+images.length+' images';});";

/// Writes `dir/index.html` for `report`, atomically, and returns its path.
///
/// `fronts` gives, per scene, the indices into `report.points_of(scene)` of the Pareto front's
/// configurations (sorted by cost); `plots` gives, per scene, its Pareto plot (PNG) relative to
/// `dir`. Every image the page shows (truths, the front's images and FLIP maps, the plots) is
/// read from `dir` and inlined; a missing one is an error naming the file, and a front index
/// past the scene's points is [`LabError::Invalid`].
pub fn write_page(
    dir: &Path,
    report: &LabReport,
    fronts: &[(String, Vec<usize>)],
    plots: &[(String, String)],
) -> Result<PathBuf, LabError> {
    let html = render(dir, report, fronts, plots)?;
    let path = dir.join("index.html");
    write_bytes_atomically(&path, html.as_bytes())?;
    Ok(path)
}

/// The whole page.
fn render(
    dir: &Path,
    report: &LabReport,
    fronts: &[(String, Vec<usize>)],
    plots: &[(String, String)],
) -> Result<String, LabError> {
    let mut html = String::with_capacity(64 * 1024);
    html.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    html.push_str("<title>shine lab</title>\n");
    html.push_str(&format!("<style>{STYLE}</style>\n"));
    html.push_str(&format!("<script>{SCRIPT}</script>\n</head>\n<body>\n"));
    html.push_str("<h1>shine lab: global illumination side by side</h1>\n");
    html.push_str(&conditions(report));

    // The front's points of each scene, checked once, for the figures and the table.
    let mut front_points: Vec<(&str, Vec<&LabPoint>)> = Vec::new();
    for scene in report.scenes() {
        let points: Vec<&LabPoint> = report.points_of(scene).collect();
        let indices = lookup(fronts, scene).map_or(&[][..], Vec::as_slice);
        let mut front = Vec::with_capacity(indices.len());
        for &i in indices {
            let point = points.get(i).copied().ok_or_else(|| {
                LabError::Invalid(format!(
                    "the Pareto front of {scene} names point {i}, but the scene has {} points",
                    points.len()
                ))
            })?;
            front.push(point);
        }
        front_points.push((scene, front));
    }

    for (scene, front) in &front_points {
        html.push_str(&format!("<h2>{}</h2>\n", escape(scene)));
        if let Some(plot) = lookup(plots, scene) {
            html.push_str(&format!(
                "<img class=\"plot\" alt=\"Pareto plot of {}\" src=\"{}\">\n",
                escape(scene),
                data_uri(dir, plot)?
            ));
        }
        html.push_str("<div class=\"row\">\n");
        if let Some(truth) = lookup(&report.truths, scene) {
            html.push_str(&format!(
                "<figure><img alt=\"truth\" src=\"{}\"><figcaption>truth ({} spp)</figcaption></figure>\n",
                data_uri(dir, truth)?,
                report.setup.truth_spp
            ));
        }
        for point in front {
            html.push_str(&figure(dir, point)?);
        }
        html.push_str("</div>\n");
    }

    html.push_str(&table(report, &front_points));

    if !report.failures.is_empty() {
        html.push_str("<h2>Failures</h2>\n<ul class=\"failures\">\n");
        for failure in &report.failures {
            html.push_str(&format!(
                "<li><b>{}</b>: {}</li>\n",
                escape(&failure.scene),
                escape(&failure.reason)
            ));
        }
        html.push_str("</ul>\n");
    }
    html.push_str("</body>\n</html>\n");
    Ok(html)
}

/// The run's conditions as a definition list.
fn conditions(report: &LabReport) -> String {
    let s = &report.setup;
    let rows = [
        ("device", escape(&report.device)),
        ("driver", escape(&report.driver)),
        ("revision", escape(&report.revision)),
        ("extent", format!("{}×{}", s.extent[0], s.extent[1])),
        ("truth spp", s.truth_spp.to_string()),
        ("sequence truth spp", s.sequence_spp.to_string()),
        ("sequence frames", s.sequence_frames.to_string()),
        ("light turn per frame", format!("{}°", s.degrees_per_frame)),
        (
            "timed frames",
            format!("{} (after {} warm-up)", s.cost_frames, s.warmup),
        ),
        ("scene time", format!("{} s", s.time)),
    ];
    let mut out = String::from("<dl class=\"conditions\">\n");
    for (name, value) in rows {
        out.push_str(&format!("<dt>{name}</dt><dd>{value}</dd>\n"));
    }
    out.push_str("</dl>\n");
    out
}

/// A flicker ratio as shown: `×1.23`, or `n/a` where the truth gives none (0).
fn ratio(r: f64) -> String {
    if r > 0.0 {
        format!("×{r:.2}")
    } else {
        "n/a".to_owned()
    }
}

/// One front configuration's figure: its image, its FLIP map under it, and a caption.
fn figure(dir: &Path, point: &LabPoint) -> Result<String, LabError> {
    let label = escape(&point.config.label);
    Ok(format!(
        "<figure><img alt=\"{label}\" src=\"{}\"><img alt=\"FLIP map of {label}\" src=\"{}\">\
         <figcaption><b>{label}</b><br>{:.3} ms · rel. RMSE {:.4}<br>flicker {}</figcaption>\
         </figure>\n",
        data_uri(dir, &point.image)?,
        data_uri(dir, &point.flip_map)?,
        point.cost.frame_ms,
        point.error.relative_rmse,
        ratio(point.motion.flicker_ratio),
    ))
}

/// The table of every point of every scene, the front's rows highlighted.
fn table(report: &LabReport, fronts: &[(&str, Vec<&LabPoint>)]) -> String {
    let mut out = String::from("<h2>Every point</h2>\n<table>\n<thead><tr>");
    let heads = [
        "scene",
        "label",
        "frame ms",
        "relative RMSE",
        "energy ratio",
        "FLIP",
        "flicker",
        "truth flicker (noise-free)",
        "flicker ratio",
        "lag",
    ];
    for (i, head) in heads.iter().enumerate() {
        let class = if i < 2 { " class=\"text\"" } else { "" };
        out.push_str(&format!("<th{class}>{head}</th>"));
    }
    out.push_str("</tr></thead>\n<tbody>\n");
    for point in &report.points {
        let on_front = fronts
            .iter()
            .any(|(_, front)| front.iter().any(|p| std::ptr::eq(*p, point)));
        let class = if on_front { " class=\"front\"" } else { "" };
        out.push_str(&format!(
            "<tr{class}><td class=\"text\">{}</td><td class=\"text\">{}</td><td>{:.3}</td>\
             <td>{:.4}</td><td>{:.3}</td><td>{:.4}</td><td>{:.4}</td><td>{:.4}</td>\
             <td>{}</td><td>{:+.4}</td></tr>\n",
            escape(&point.scene),
            escape(&point.config.label),
            point.cost.frame_ms,
            point.error.relative_rmse,
            point.error.energy_ratio,
            point.error.flip,
            point.motion.flicker,
            point.motion.truth_flicker_noise_free,
            ratio(point.motion.flicker_ratio),
            point.motion.lag,
        ));
    }
    out.push_str("</tbody>\n</table>\n");
    out
}

/// The value of `scene` in a per-scene list.
fn lookup<'a, T>(list: &'a [(String, T)], scene: &str) -> Option<&'a T> {
    list.iter().find(|(s, _)| s == scene).map(|(_, v)| v)
}

/// `dir/relative`, a PNG, as a `data:` URI; a file that cannot be read is an error naming it.
fn data_uri(dir: &Path, relative: &str) -> Result<String, LabError> {
    let path = dir.join(relative);
    let bytes = std::fs::read(&path).map_err(|source| LabError::Io { path, source })?;
    Ok(format!("data:image/png;base64,{}", STANDARD.encode(bytes)))
}

/// `text` with `&`, `<`, `>` and `"` escaped, for element content and attribute values.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            _ => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::escape;

    #[test]
    fn escapes_the_four_special_characters() {
        assert_eq!(escape(r#"a<b & "c">d"#), "a&lt;b &amp; &quot;c&quot;&gt;d");
    }
}
