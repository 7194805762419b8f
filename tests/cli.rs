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

#[test]
fn render_writes_png_and_exr_and_refuses_bad_requests_before_work() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_render");
    std::fs::create_dir_all(&dir).expect("tmp dir");
    for file in ["cb.png", "cb.exr"] {
        let out = dir.join(file);
        let _ = std::fs::remove_file(&out);
        let run = shine()
            .args([
                "render",
                "builtin:cornell-box",
                "--width",
                "32",
                "--height",
                "32",
            ])
            .args(["--gi", "none", "--set", "shadow.size=128", "-o"])
            .arg(&out)
            .output()
            .expect("run shine render");
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let bytes = std::fs::read(&out).expect("output written");
        let magic: &[u8] = if file.ends_with(".png") {
            b"\x89PNG"
        } else {
            b"\x76\x2f\x31\x01"
        };
        assert!(
            bytes.starts_with(magic),
            "{file} is not a {} file",
            &file[3..]
        );
        // a capture this small is supersampled 2×2 unless told otherwise
        let stdout = String::from_utf8_lossy(&run.stdout);
        assert!(stdout.contains("supersampled 2×"), "{stdout}");
    }
    for (args, message) in [
        (vec!["-o", "cb.jpg"], ".png"),
        (vec!["-o", "cb.png", "--set", "hvl.count=5"], "hvl.count"),
        (vec!["-o", "cb.png", "--set", "nonsense=1"], "nonsense"),
        (vec!["-o", "cb.png", "--gi", "magic"], "magic"),
        (vec!["-o", "cb.png", "--ssaa", "5"], "output.ssaa"),
    ] {
        let run = shine()
            .current_dir(&dir)
            .args(["render", "builtin:cornell-box"])
            .args(&args)
            .output()
            .expect("run shine render");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{args:?}: {stderr}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    assert!(!dir.join("cb.jpg").exists());
}

#[test]
fn profile_reports_every_pass_as_json() {
    let run = shine()
        .args([
            "profile",
            "builtin:cornell-box",
            "--frames",
            "3",
            "--warmup",
            "1",
        ])
        .args([
            "--width",
            "32",
            "--height",
            "32",
            "--gi",
            "none",
            "--set",
            "shadow.size=128",
        ])
        .args(["--format", "json"])
        .output()
        .expect("run shine profile");
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let report: serde_json::Value = serde_json::from_str(&stdout).expect("JSON report");
    assert_eq!(report["frames"], 3, "{stdout}");
    // What was measured: scene, resolution, device, driver, settings, revision.
    let run_info = &report["run"];
    assert_eq!(run_info["scene"], "builtin:cornell-box", "{stdout}");
    assert_eq!(
        (run_info["width"].as_u64(), run_info["height"].as_u64()),
        (Some(32), Some(32))
    );
    assert_eq!(run_info["settings"]["width"], 32, "{stdout}");
    for key in ["device", "driver", "revision"] {
        let value = run_info[key].as_str().unwrap_or_default();
        assert!(!value.is_empty(), "run.{key} empty: {stdout}");
    }
    // Three frames: their p95 is their slowest, and the report says so.
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("note: the p95 of 3 frames is their slowest"),
        "{stderr}"
    );
    // lavapipe is a CPU device: `auto` times each pass alone on the host clock.
    assert_eq!(report["clock"], "host", "{stdout}");
    let passes: Vec<_> = report["passes"]
        .as_array()
        .expect("passes")
        .iter()
        .filter_map(|p| p["name"].as_str())
        .collect();
    // The Cornell lamp is a wide spot: its shadow is drawn as cube faces.
    for pass in ["gbuffer", "shadow light 0 -y", "direct", "composite"] {
        assert!(passes.contains(&pass), "{pass} missing from {passes:?}");
    }
}

/// `render --help` and `profile --help` show every flag's default, the settings flags' from
/// `Settings::default()`.
#[test]
fn help_shows_the_defaults() {
    let defaults = shine::Settings::default();
    for command in ["render", "profile"] {
        let run = shine()
            .args([command, "--help"])
            .output()
            .expect("run shine --help");
        assert!(run.status.success());
        let help = String::from_utf8_lossy(&run.stdout);
        for expected in [
            format!("Image width in pixels [default: {}]", defaults.width),
            format!("Image height in pixels [default: {}]", defaults.height),
            "[default: hvl]".to_owned(),
            "[default: pbr-neutral]".to_owned(),
        ] {
            assert!(
                help.contains(&expected),
                "{command}: no `{expected}` in\n{help}"
            );
        }
    }
    let help = shine().args(["profile", "--help"]).output().expect("help");
    let help = String::from_utf8_lossy(&help.stdout);
    assert!(help.contains("Frames measured [default: 60]"), "{help}");
}

#[test]
fn profile_refuses_an_unknown_clock() {
    let run = shine()
        .args(["profile", "builtin:cornell-box", "--clock", "sundial"])
        .args(["--width", "16", "--height", "16", "--gi", "none"])
        .output()
        .expect("run shine profile");
    assert_eq!(run.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(
        stderr.contains("unknown --clock `sundial`: expected auto, gpu or host"),
        "{stderr}"
    );
}

/// `--clock gpu` on lavapipe (a CPU device whose timestamps miss compute work) is allowed but
/// warned about.
#[test]
fn profile_warns_of_gpu_timestamps_on_a_cpu_device() {
    let run = shine()
        .args(["profile", "builtin:cornell-box", "--clock", "gpu"])
        .args(["--frames", "1", "--warmup", "0"])
        .args(["--width", "16", "--height", "16", "--gi", "none"])
        .output()
        .expect("run shine profile");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(
        stderr.contains("is a CPU device whose timestamps miss compute work"),
        "{stderr}"
    );
}

/// `--environment FILE` lights the spheres with an equirectangular map: a brighter constant
/// map gives a brighter proxy-lit frame than a dimmer one, and a missing or undecodable map is
/// a clear error.
#[test]
fn render_lights_the_scene_with_an_environment_map() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_environment");
    std::fs::create_dir_all(&dir).expect("tmp dir");
    let mut means = Vec::new();
    for level in [0.25f32, 1.0] {
        let map = dir.join(format!("constant_{level}.exr"));
        image::DynamicImage::ImageRgb32F(image::Rgb32FImage::from_pixel(
            16,
            8,
            image::Rgb([level; 3]),
        ))
        .save(&map)
        .expect("map written");
        let out = dir.join(format!("lit_{level}.exr"));
        let run = shine()
            .args([
                "render",
                "builtin:spheres",
                "--width",
                "32",
                "--height",
                "32",
            ])
            .args(["--gi", "proxy", "--set", "shadow.size=128"])
            // The proxy-lit surfaces only: the sky behind them would scale by itself.
            .args(["--set", "output.component=indirect", "--environment"])
            .arg(&map)
            .arg("-o")
            .arg(&out)
            .output()
            .expect("run shine render");
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let frame = shine::capture::image_io::read_exr(&out).expect("EXR");
        let mean: f32 = frame.texels.iter().map(|t| t[0] + t[1] + t[2]).sum::<f32>()
            / frame.texels.len() as f32;
        means.push(mean);
    }
    assert!(
        means[1] > 2.0 * means[0],
        "a 4× brighter map lit the frame only {means:?}"
    );
    std::fs::write(dir.join("broken.hdr"), b"not an image").expect("write");
    for (file, message) in [
        ("missing.exr", "cannot read environment map"),
        ("broken.hdr", "cannot be decoded"),
    ] {
        let run = shine()
            .args([
                "render",
                "builtin:spheres",
                "--gi",
                "proxy",
                "-o",
                "x.png",
                "--environment",
            ])
            .arg(dir.join(file))
            .current_dir(&dir)
            .output()
            .expect("run shine render");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{file}: {stderr}");
        assert!(stderr.contains(message), "{file}: {stderr}");
    }
    assert!(!dir.join("x.png").exists());
}

/// `--frames 12` with a frame field writes 12 images of `builtin:animated`, all different (the
/// walker, the curtain and the spot light move), `--camera-orbit` moves the camera around a
/// static scene, and a sequence without a frame field is refused before any work, writing
/// nothing.
#[test]
fn render_writes_every_frame_of_a_sequence() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_sequence");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("tmp dir");
    let run = shine()
        .args(["render", "builtin:animated", "--frames", "12", "--fps", "8"])
        .args(["--width", "24", "--height", "24"])
        .args(["--gi", "none", "--set", "shadow.size=128", "-o"])
        .arg(dir.join("f_%04d.png"))
        .output()
        .expect("run shine render");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let frames: Vec<Vec<u8>> = (0..12)
        .map(|k| std::fs::read(dir.join(format!("f_{k:04}.png"))).expect("frame written"))
        .collect();
    for (i, a) in frames.iter().enumerate() {
        for b in &frames[i + 1..] {
            assert_ne!(a, b, "two frames are identical");
        }
    }
    assert_eq!(std::fs::read_dir(&dir).expect("dir").count(), 12);

    let orbit = dir.join("orbit");
    std::fs::create_dir_all(&orbit).expect("dir");
    let run = shine()
        .args(["render", "builtin:cornell-box", "--frames", "3"])
        .args(["--camera-orbit", "30", "--width", "24", "--height", "24"])
        .args(["--gi", "none", "--set", "shadow.size=128", "-o"])
        .arg(orbit.join("o%d.png"))
        .output()
        .expect("run shine render");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let views: Vec<Vec<u8>> = (0..3)
        .map(|k| std::fs::read(orbit.join(format!("o{k}.png"))).expect("frame written"))
        .collect();
    assert!(
        views[0] != views[1] && views[1] != views[2],
        "the camera did not move"
    );

    let refused = dir.join("refused");
    std::fs::create_dir_all(&refused).expect("dir");
    let run = shine()
        .args(["render", "builtin:animated", "--frames", "3", "-o"])
        .arg(refused.join("out.png"))
        .output()
        .expect("run shine render");
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("no frame field"), "{stderr}");
    assert_eq!(std::fs::read_dir(&refused).expect("dir").count(), 0);
}

/// Broken skins are refused with a message naming the element, and no image is written: a
/// joint naming a node that does not exist, a joint index past the skin, a NaN weight.
#[test]
fn render_refuses_broken_skins_and_writes_nothing() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_broken_skins");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("tmp dir");
    let broken = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("crates/scene/tests/broken");
    for (file, message) in [
        ("skin-dangling-joint.gltf", "skins[0].joints[1]"),
        ("joint-out-of-range.gltf", "joint index 1 is out of range"),
        ("nan-weight.gltf", "WEIGHTS_0: element 5 has a NaN"),
    ] {
        let run = shine()
            .args(["render"])
            .arg(broken.join(file))
            .args(["--width", "16", "--height", "16", "-o"])
            .arg(dir.join("out.png"))
            .output()
            .expect("run shine render");
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "{file}: {stderr}");
        assert!(stderr.contains(message), "{file}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert_eq!(std::fs::read_dir(&dir).expect("dir").count(), 0, "{file}");
    }
}
