//! `shine lab`, `shine settings` and `--budget-ms` as a user runs them: bad input refused
//! with the file and line, before any work.

mod common;

use common::cli::{fails_cleanly, scratch, shine, text};

#[test]
fn a_bad_configs_file_is_named_with_its_line() {
    let dir = scratch("cli_lab_bad_configs");
    let cases = [
        (
            "unknown.toml",
            "[[config]]\nlabel = \"a\"\nset = { gi = \"hvl\", \"hvl.cuont\" = 5 }\n",
            "unknown.toml:3:",
            "cuont",
        ),
        (
            "range.toml",
            "[[config]]\nset = { gi = \"hvl\" }\n\n[[config]]\nset = { \"igi.n\" = 9 }\n",
            "range.toml:5:",
            "igi.n",
        ),
    ];
    for (name, body, place, what) in cases {
        let path = dir.join(name);
        std::fs::write(&path, body).unwrap();
        let out = shine(&[
            "lab",
            "builtin:cornell-box",
            "--configs",
            path.to_str().unwrap(),
            "--out",
            dir.join("out").to_str().unwrap(),
        ]);
        fails_cleanly(&out, place);
        fails_cleanly(&out, what);
        assert!(!dir.join("out").exists(), "{name}: work began");
    }
    let missing = dir.join("missing.toml");
    let out = shine(&[
        "lab",
        "builtin:cornell-box",
        "--configs",
        missing.to_str().unwrap(),
    ]);
    fails_cleanly(&out, "missing.toml");
}

#[test]
fn the_default_space_lists_every_technique() {
    let out = shine(&["lab", "builtin:cornell-box", "--list"]);
    assert!(out.status.success(), "{}", text(&out));
    let listed = String::from_utf8_lossy(&out.stdout);
    for technique in ["hvl", "igi", "aaf", "proxy"] {
        assert!(
            listed
                .lines()
                .any(|l| l.split_whitespace().next() == Some(technique)),
            "{technique}: {listed}"
        );
    }
    let count: usize = listed
        .lines()
        .last()
        .and_then(|l| l.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0);
    assert!(count >= 30, "{listed}");
}

#[test]
fn settings_print_the_docs_page_and_json() {
    let out = shine(&["settings"]);
    assert!(out.status.success(), "{}", text(&out));
    let page =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/settings.md")).unwrap();
    assert_eq!(String::from_utf8_lossy(&out.stdout), page);
    let out = shine(&["settings", "--format", "json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let keys: Vec<&str> = json
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|s| s["key"].as_str())
        .collect();
    assert!(
        keys.contains(&"aaf.alpha") && keys.contains(&"hvl.count"),
        "{keys:?}"
    );
    let count = json
        .as_array()
        .unwrap()
        .iter()
        .find(|s| s["key"] == "hvl.count")
        .unwrap();
    assert_eq!(count["values"]["int"], serde_json::json!([64, 10000]));
    assert_eq!(count["changes"], "both");
    fails_cleanly(
        &shine(&["settings", "--format", "yaml"]),
        "unknown format `yaml`",
    );
}

#[test]
fn a_budget_must_be_a_positive_time() {
    let dir = scratch("cli_lab_budget");
    let png = dir.join("b.png");
    for bad in ["-3", "0", "nan"] {
        let flag = format!("--budget-ms={bad}");
        let out = shine(&[
            "render",
            "builtin:cornell-box",
            "--width",
            "16",
            "--height",
            "16",
            &flag,
            "-o",
            png.to_str().unwrap(),
        ]);
        fails_cleanly(&out, "--budget-ms");
        assert!(!png.exists(), "{bad}: an image was written");
    }
}
