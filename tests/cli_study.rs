//! `shine study aaf` as a user runs it: a tiny study (32×32, a 32-spp truth, three spp levels,
//! two μ) whose JSON report has every field, finite, and whose pictures are written; and bad
//! input (exit status 1, a message, no panic).

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
