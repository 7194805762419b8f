//! The `shine` binary as a user runs it: `shine info` (the device and the feature report, and a
//! clear failure without a Vulkan driver) and `shine scene export`.

use std::process::Command;

fn shine() -> Command {
    Command::new(env!("CARGO_BIN_EXE_shine"))
}

#[test]
fn info_reports_the_device_and_required_features() {
    let out = shine().arg("info").output().expect("run shine info");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "shine info failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Selected: "), "{stdout}");
    assert!(stdout.contains("Vulkan:   1.3"), "{stdout}");
    for feature in ["synchronization2", "dynamicRendering", "timestamps"] {
        let line = stdout
            .lines()
            .find(|l| l.starts_with(feature))
            .unwrap_or_else(|| panic!("no line for {feature}:\n{stdout}"));
        assert!(line.contains("required  yes"), "{line}");
    }
}

#[test]
fn info_without_a_driver_fails_cleanly() {
    let out = shine()
        .arg("info")
        .env("VK_DRIVER_FILES", "/nonexistent/icd.json")
        .env("VK_ICD_FILENAMES", "/nonexistent/icd.json")
        .output()
        .expect("run shine info");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("no Vulkan device"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

#[test]
fn info_with_an_unknown_device_names_the_available_ones() {
    let out = shine()
        .args(["info", "--device", "no-such-gpu"])
        .output()
        .expect("run shine info");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(
        stderr.contains("no-such-gpu") && stderr.contains("available: 0:"),
        "{stderr}"
    );
}

#[test]
fn scene_export_writes_the_committed_asset() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_scene_export");
    std::fs::create_dir_all(&dir).expect("tmp dir");
    for name in ["cornell-box", "spheres", "room"] {
        let out = dir.join(format!("{name}.glb"));
        let status = shine()
            .args(["scene", "export", name])
            .arg(&out)
            .status()
            .expect("run shine scene export");
        assert!(status.success());
        let asset = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets")
            .join(format!("{name}.glb"));
        assert_eq!(
            std::fs::read(&out).expect("exported"),
            std::fs::read(asset).expect("asset"),
            "{name}: export differs from assets/"
        );
    }
}

#[test]
fn scene_export_of_an_unknown_scene_lists_the_known_ones() {
    let out = shine()
        .args(["scene", "export", "nope", "/tmp/never.glb"])
        .output()
        .expect("run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(stderr.contains("cornell-box"), "{stderr}");
    assert!(!std::path::Path::new("/tmp/never.glb").exists());
}
