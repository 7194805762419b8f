//! `shine profile --roofline` in a test binary of its own: the FMA peak and the pass it bounds
//! are timed by the CPU that runs lavapipe, so a sibling test loading that CPU while the peak is
//! measured (and not while the pass runs) would put the pass above the peak. Cargo runs test
//! binaries one at a time; this file holds one test so nothing else runs beside it.

use std::process::Command;

/// Largest share of the FMA peak `hvl_gather` may read before its declared work counts as
/// wrong (see the assertion).
const ROOFLINE_SHARE_BOUND: f64 = 5.0;

fn shine() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shine"))
}

/// `--roofline`: the device's peaks are measured once and cached (a second run reads them),
/// and `hvl_gather` reports its achieved GFLOP/s and share of the FMA peak from the work it
/// declares.
#[test]
fn profile_roofline_sets_hvl_gather_against_the_peaks() {
    let cache = std::env::temp_dir().join(format!("shine-roofline-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cache);
    let profile = || {
        shine()
            .env("SHINE_CACHE_DIR", &cache)
            .args(["profile", "builtin:cornell-box", "--roofline"])
            .args(["--frames", "2", "--warmup", "1", "--format", "json"])
            .args([
                "--width",
                "32",
                "--height",
                "32",
                "--set",
                "shadow.size=128",
            ])
            .output()
            .expect("run shine profile")
    };
    let first = profile();
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(first.status.success(), "{stderr}");
    assert!(stderr.contains("GFLOP/s fp32 FMA"), "{stderr}");
    assert!(cache.join("roofline.json").is_file());
    let second = profile();
    assert!(second.status.success());
    let stderr = String::from_utf8_lossy(&second.stderr);
    assert!(
        !stderr.contains("GFLOP/s fp32 FMA"),
        "measured again: {stderr}"
    );
    let stdout = String::from_utf8_lossy(&second.stdout);
    let report: serde_json::Value = serde_json::from_str(&stdout).expect("JSON report");
    let roofline = &report["roofline"];
    let peak = roofline["peaks"]["gflops"].as_f64().unwrap_or(0.0);
    assert!(peak > 1.0, "{stdout}");
    assert!(
        roofline["peaks"]["gbps"].as_f64().unwrap_or(0.0) > 0.1,
        "{stdout}"
    );
    let gather = roofline["passes"]
        .as_array()
        .expect("roofline passes")
        .iter()
        .find(|p| p["name"] == "hvl_gather")
        .unwrap_or_else(|| panic!("no hvl_gather: {stdout}"));
    let gflops = gather["gflops"].as_f64().unwrap_or(0.0);
    let share = gather["flop_share"].as_f64().unwrap_or(0.0);
    assert!(
        gflops > 0.0 && (share - gflops / peak).abs() < 1e-9,
        "{gather}"
    );
    // A count far above what was executed would show as a share far beyond the peak. Not
    // merely beyond it: the peak and the pass are timed seconds apart on the CPU that runs
    // lavapipe, and another process loading it while the peak is timed read 2.3× once (a
    // fresh-clone `make test` beside two studies); an order of magnitude is a wrong count.
    assert!(
        share < ROOFLINE_SHARE_BOUND,
        "hvl_gather at {share} of the peak: {gather}"
    );
    let _ = std::fs::remove_dir_all(&cache);
}
