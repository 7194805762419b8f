//! `shine study aaf` and `shine study temporal` as a user runs them: tiny studies whose JSON
//! reports have every field, finite, and whose pictures are written; and bad input (exit
//! status 1, a message, no panic).

mod common;

use common::cli::{fails_cleanly, scratch, shine, text};
use std::path::Path;
use std::process::Output;

use serde_json::Value;

/// The number at `pointer`, which must be finite.
fn finite(report: &Value, pointer: &str) -> f64 {
    let v = report
        .pointer(pointer)
        .and_then(Value::as_f64)
        .unwrap_or_else(|| panic!("{pointer} is not a number in {report:#}"));
    assert!(v.is_finite(), "{pointer} = {v}");
    v
}

fn tiny_study(out: &Path, format: &str) -> Output {
    shine(&[
        "study",
        "aaf",
        "builtin:cornell-box",
        "--width",
        "32",
        "--height",
        "32",
        "--truth-spp",
        "32",
        "--truth-chunk",
        "8",
        "--spp",
        "1,4,16",
        "--mu",
        "0.9,4",
        "--path-tracer-spp",
        "4",
        "--format",
        format,
        "--out",
        out.to_str().expect("utf-8 path"),
    ])
}

#[test]
fn tiny_aaf_study_reports_every_number_and_writes_the_pictures() {
    let dir = scratch("cli_study_aaf");
    let out = tiny_study(&dir, "json");
    assert!(out.status.success(), "{}", text(&out));
    let report: Value = serde_json::from_slice(&out.stdout).expect("study prints JSON");

    assert_eq!(report["extent"], serde_json::json!([32, 32]));
    // A default frame's AAF: the quadratic fit, the specular pass's limit.
    assert_eq!(
        report["setup"]["filter_degree"],
        shine_sh::aaf::FILTER_DEGREE
    );
    assert!(finite(&report, "/setup/specular_limit") > 0.0);
    assert!(finite(&report, "/truth/mean") > 0.0);
    assert!(finite(&report, "/truth/noise_relative_rmse") > 0.0);
    assert!(finite(&report, "/truth/pixels") > 0.0);
    for (curve, points) in [("uniform", 3), ("uniform_filtered", 3), ("aaf", 2)] {
        let list = report["curves"][curve].as_array().expect("curve");
        assert_eq!(list.len(), points, "{curve}");
        for k in 0..points {
            for field in ["spp", "relative_rmse", "mse", "energy_ratio", "time_ms"] {
                let v = finite(&report, &format!("/curves/{curve}/{k}/{field}"));
                assert!(v >= 0.0, "{curve}[{k}].{field} = {v}");
            }
        }
    }
    // Uniform Monte Carlo: more samples, less error; AAF's average spp grows with μ.
    let uniform = |k: usize| finite(&report, &format!("/curves/uniform/{k}/relative_rmse"));
    assert!(uniform(2) < uniform(0), "{report:#}");
    let aaf_spp = |k: usize| finite(&report, &format!("/curves/aaf/{k}/spp"));
    assert!(aaf_spp(1) > aaf_spp(0) && aaf_spp(0) >= 16.0, "{report:#}");

    for field in [
        "aaf_spp",
        "aaf_relative_rmse",
        "uniform_spp",
        "sample_speedup",
        "aaf_time_ms",
        "uniform_time_ms",
        "time_speedup",
        "gbuffer_ms",
    ] {
        assert!(
            finite(&report, &format!("/equal_error/{field}")) > 0.0,
            "{field}"
        );
    }
    for field in ["filter_share", "overhead_share"] {
        let share = finite(&report, &format!("/equal_error/{field}"));
        assert!((0.0..=1.0).contains(&share), "{field} = {share}");
    }
    assert_eq!(
        report["equal_error"]["passes_ms"].as_array().map(Vec::len),
        Some(5)
    );
    assert!(report["bars"]["sample_speedup_met"].is_boolean());
    assert!(report["equal_error"]["reliable"].is_boolean());
    assert!(report["bars"]["overhead_share_met"].is_boolean());
    for field in [
        "aaf_relative_rmse",
        "aaf_energy_ratio",
        "truth_relative_rmse",
        "truth_energy_ratio",
    ] {
        finite(&report, &format!("/path_tracer/{field}"));
    }
    for axis in ["spp_axis", "error_axis"] {
        let [lo, hi] = [0, 1].map(|i| finite(&report, &format!("/error_plot/{axis}/{i}")));
        assert!(0.0 < lo && lo < hi, "{axis}: {lo}..{hi}");
    }

    for (name, size) in [
        ("error.png", None),
        ("spp.png", Some((32, 40))),
        ("beta.png", Some((32, 40))),
        ("aaf_error.png", Some((32, 40))),
        ("filter_bias.png", Some((32, 40))),
        ("truth.png", Some((32, 32))),
        ("aaf.png", Some((32, 32))),
        ("uniform.png", Some((32, 32))),
    ] {
        let path = dir.join(name);
        let image = shine::capture::image_io::read_png(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if let Some((w, h)) = size {
            assert_eq!((image.width, image.height), (w, h), "{name}");
        }
        assert!(
            report["files"]
                .as_array()
                .is_some_and(|f| f.iter().any(|p| p.as_str() == path.to_str())),
            "{name} not listed in {report:#}"
        );
    }
    // No temporary file is left behind.
    let left: Vec<_> = std::fs::read_dir(&dir)
        .expect("read dir")
        .filter_map(Result::ok)
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| !n.ends_with(".png"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn study_refuses_bad_input_cleanly() {
    let dir = scratch("cli_study_bad");
    let out_dir = dir.to_str().expect("utf-8 path");
    let study = |extra: &[&str]| {
        let mut args = vec!["study", "aaf", "builtin:cornell-box", "--out", out_dir];
        args.extend_from_slice(extra);
        shine(&args)
    };
    fails_cleanly(
        &shine(&["study", "aaf", "builtin:no-such-scene", "--out", out_dir]),
        "no-such-scene",
    );
    fails_cleanly(&study(&["--width", "0"]), "out of range");
    fails_cleanly(&study(&["--height", "100000"]), "out of range");
    fails_cleanly(&study(&["--format", "xml"]), "--format");
    fails_cleanly(
        &study(&["--truth-spp", "100", "--truth-chunk", "64"]),
        "multiple",
    );
    fails_cleanly(&study(&["--spp", "4,2"]), "increase");
    fails_cleanly(&study(&["--spp", "0"]), "out of range");
    fails_cleanly(&study(&["--mu", "1000"]), "out of range");
    fails_cleanly(&study(&["--repeats", "0"]), "at least 1");
    // Nothing was written by a refused study.
    assert_eq!(std::fs::read_dir(&dir).expect("read dir").count(), 0);
}

/// `shine study temporal` on a tiny sequence: every number of the JSON report is finite, a
/// mode without history flickers exactly as its cold frames do (nothing carries over), and
/// the plots and flicker maps are written.
#[test]
fn tiny_temporal_study_reports_flicker_and_writes_the_pictures() {
    let dir = scratch("cli_study_temporal");
    let out = shine(&[
        "study",
        "temporal",
        "builtin:animated",
        "--frames",
        "4",
        "--warmup",
        "1",
        "--width",
        "16",
        "--height",
        "16",
        "--truth-spp",
        "4",
        "--mode",
        "hvl=gi=hvl",
        "--mode",
        "igi cold=gi=igi;history.frames=1;history.samples=1",
        "--format",
        "json",
        "--out",
        dir.to_str().expect("utf-8 path"),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let report: Value = serde_json::from_slice(&out.stdout).expect("study prints JSON");
    assert_eq!(report["extent"], serde_json::json!([16, 16]));
    assert!(finite(&report, "/truth_flicker") > 0.0);
    finite(&report, "/truth_still_flicker");
    for k in 0..2 {
        for field in [
            "ms_per_frame",
            "relative_rmse",
            "flicker",
            "still_flicker",
            "last_rmse",
            "cold_flicker",
            "cold_still_flicker",
            "cold_last_rmse",
        ] {
            let v = finite(&report, &format!("/modes/{k}/{field}"));
            assert!(v >= 0.0, "modes[{k}].{field} = {v}");
        }
        assert_eq!(
            report["modes"][k]["flicker_by_frame"]
                .as_array()
                .map(Vec::len),
            Some(2)
        );
    }
    let (flicker, cold) = (
        finite(&report, "/modes/1/flicker"),
        finite(&report, "/modes/1/cold_flicker"),
    );
    assert!(
        (flicker - cold).abs() <= 1e-4 * cold,
        "{flicker} against {cold}"
    );
    for (name, size) in [
        ("plot.png", None),
        ("flicker-by-frame.png", None),
        ("flicker-truth.png", Some((256, 264))),
        ("flicker-hvl.png", Some((256, 264))),
        ("flicker-igi_cold.png", Some((256, 264))),
        ("still.png", Some((256, 264))),
    ] {
        let path = dir.join(name);
        let image = shine::capture::image_io::read_png(&path)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        if let Some((w, h)) = size {
            assert_eq!((image.width, image.height), (w, h), "{name}");
        }
    }
}
