//! `shine reference` and `shine compare` as a user runs them, including bad input (exit
//! status 1, a message, no panic).

mod common;

use common::cli::{fails_cleanly, scratch, shine, text};

#[test]
fn reference_then_compare_reports_metrics() {
    let dir = scratch("cli_reference_compare");
    let a = dir.join("a.exr");
    let b = dir.join("b.exr");
    for (path, seed) in [(&a, "1"), (&b, "2")] {
        let out = shine(&[
            "reference",
            "builtin:cornell-box",
            "--spp",
            "2",
            "--width",
            "32",
            "--height",
            "32",
            "--indirect-only",
            "--seed",
            seed,
            "-o",
            path.to_str().expect("utf-8 path"),
        ]);
        assert!(out.status.success(), "{}", text(&out));
        assert!(
            text(&out).contains("ns per sample per pixel"),
            "{}",
            text(&out)
        );
    }
    let out = shine(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    let rmse = report["rmse"].as_f64().expect("rmse");
    let ssim = report["ssim"].as_f64().expect("ssim");
    assert!(
        rmse > 0.0 && rmse < 1.0 && ssim > -1.0 && ssim < 1.0,
        "{report}"
    );
    // An image against itself: RMSE 0, PSNR infinite (null in JSON), SSIM 1.
    let out = shine(&["compare", a.to_str().unwrap(), a.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(text(&out).contains("RMSE    0.000000"), "{}", text(&out));
    assert!(text(&out).contains("SSIM    1.000000"), "{}", text(&out));
    // A time budget stops early and still writes the image.
    let c = dir.join("c.exr");
    let out = shine(&[
        "reference",
        "builtin:cornell-box",
        "--spp",
        "100000",
        "--seconds",
        "0.01",
        "--width",
        "16",
        "--height",
        "16",
        "-o",
        c.to_str().unwrap(),
    ]);
    assert!(out.status.success() && c.exists(), "{}", text(&out));
}

#[test]
fn bad_input_fails_cleanly() {
    let dir = scratch("cli_reference_bad_input");
    let missing = dir.join("missing.exr");
    let out = shine(&[
        "compare",
        missing.to_str().unwrap(),
        missing.to_str().unwrap(),
    ]);
    fails_cleanly(&out, "missing.exr");
    // Size mismatch.
    let (a, b) = (dir.join("a.exr"), dir.join("b.exr"));
    for (path, size) in [(&a, "16"), (&b, "24")] {
        let out = shine(&[
            "reference",
            "builtin:cornell-box",
            "--spp",
            "1",
            "--width",
            size,
            "--height",
            size,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", text(&out));
    }
    let out = shine(&["compare", a.to_str().unwrap(), b.to_str().unwrap()]);
    fails_cleanly(&out, "sizes differ");
    let out = shine(&[
        "compare",
        a.to_str().unwrap(),
        a.to_str().unwrap(),
        "--format",
        "xml",
    ]);
    fails_cleanly(&out, "unknown format");
    // Bad reference arguments: output format, zero spp, zero size, unknown scene.
    let bad = dir.join("x.txt");
    let out = shine(&[
        "reference",
        "builtin:cornell-box",
        "-o",
        bad.to_str().unwrap(),
    ]);
    fails_cleanly(&out, "x.txt");
    let out_path = dir.join("z.exr");
    let z = out_path.to_str().unwrap();
    fails_cleanly(
        &shine(&["reference", "builtin:cornell-box", "--spp", "0", "-o", z]),
        "--spp",
    );
    fails_cleanly(
        &shine(&["reference", "builtin:cornell-box", "--width", "0", "-o", z]),
        "out of range",
    );
    fails_cleanly(
        &shine(&["reference", "builtin:no-such-scene", "-o", z]),
        "no-such-scene",
    );
    assert!(!out_path.exists());
}

/// `shine compare` on PNGs: compared as displayed (the JSON says so, stderr says what it
/// means), a plain capture against a supersampled one differs at the edges, and both maps
/// are written at the image's size (the FLIP map black where the images agree).
#[test]
fn compare_reads_pngs_as_displayed_and_writes_the_maps() {
    let dir = scratch("cli_compare_png");
    let (a, b) = (dir.join("plain.png"), dir.join("ssaa.png"));
    for (path, ssaa) in [(&a, "1"), (&b, "2")] {
        let out = shine(&[
            "render",
            "builtin:cornell-box",
            "--width",
            "24",
            "--height",
            "24",
            "--gi",
            "none",
            "--ssaa",
            ssaa,
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", text(&out));
    }
    let (flip, signed) = (dir.join("flip.png"), dir.join("signed.png"));
    let out = shine(&[
        "compare",
        a.to_str().unwrap(),
        b.to_str().unwrap(),
        "--format",
        "json",
        "--heatmap",
        flip.to_str().unwrap(),
        "--signed-map",
        signed.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(String::from_utf8_lossy(&out.stderr).contains("compared as displayed"));
    let report: serde_json::Value =
        serde_json::from_slice(&out.stdout).expect("compare prints JSON");
    assert_eq!(report["displayed"], serde_json::json!(true));
    let flip_mean = report["flip"].as_f64().expect("flip");
    assert!(flip_mean > 0.0 && flip_mean < 0.5, "FLIP {flip_mean}");
    for path in [&flip, &signed] {
        let map = shine::capture::image_io::read_png(path).expect("map");
        assert_eq!((map.width, map.height), (24, 24));
    }
    // The FLIP map of an image against itself is black.
    let out = shine(&[
        "compare",
        a.to_str().unwrap(),
        a.to_str().unwrap(),
        "--heatmap",
        flip.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let map = shine::capture::image_io::read_png(&flip).expect("map");
    assert!(map.texels.iter().all(|t| t[..3].iter().all(|&c| c < 8)));
}

/// `--surfaces` with `--positions` and `--second-reference`: the noise-free metrics per
/// surface, where a 16×16 floor (y = 0) and an 8×8 box top (y = 1) facing the same way are two surfaces,
/// each with its own pixels and error (the box top's image is off by half its value, the
/// floor's exact); `--positions` alone, or positions as PNG, are refused with a message.
#[test]
fn compare_reports_each_plane_against_the_two_references() {
    use shine::capture::image_io::{HdrImage, write_exr};
    let dir = scratch("cli_compare_planes");
    let (w, h) = (16u32, 16u32);
    let top = |x: u32, y: u32| x >= 8 && y < 8;
    let image = |f: &dyn Fn(u32, u32) -> [f32; 4]| HdrImage {
        width: w,
        height: h,
        texels: (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect(),
    };
    let write = |name: &str, img: &HdrImage| {
        let path = dir.join(name);
        write_exr(&path, img).expect("write");
        path.to_str().expect("utf-8 path").to_string()
    };
    let reference = write("ref.exr", &image(&|_, _| [0.4, 0.4, 0.4, 1.0]));
    let tested = write(
        "test.exr",
        &image(&|x, y| if top(x, y) { [0.2; 4] } else { [0.4; 4] }),
    );
    let normals = write("normals.exr", &image(&|_, _| [0.0, 1.0, 0.0, 1.0]));
    let positions = write(
        "positions.exr",
        &image(&|x, y| [x as f32, if top(x, y) { 1.0 } else { 0.0 }, y as f32, 1.0]),
    );
    let out = shine(&[
        "compare",
        &tested,
        &reference,
        "--second-reference",
        &reference,
        "--surfaces",
        &normals,
        "--positions",
        &positions,
        "--format",
        "json",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let surfaces: Vec<(u64, f64)> = report["noise_free"]
        .as_array()
        .expect("noise_free")
        .iter()
        .filter(|r| r["over"].as_str().is_some_and(|o| o.starts_with("surface")))
        .map(|r| {
            let m = &r["metrics"];
            (
                m["pixels"].as_u64().expect("pixels"),
                m["energy_ratio"].as_f64().expect("energy"),
            )
        })
        .collect();
    assert_eq!(surfaces.len(), 2, "{report}");
    assert_eq!((surfaces[0].0, surfaces[1].0), (192, 64), "{report}");
    assert!(
        (surfaces[0].1 - 1.0).abs() < 1e-6 && (surfaces[1].1 - 0.5).abs() < 1e-6,
        "{report}"
    );
    // --positions without --surfaces: the argument parser refuses it (status 2), naming it.
    let out = shine(&["compare", &tested, &reference, "--positions", &positions]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
    assert!(text(&out).contains("--surfaces"), "{}", text(&out));
    // Positions as PNG lose their negative components: refused with a message.
    let png = dir.join("positions.png");
    let ldr = shine::capture::image_io::LdrImage {
        width: w,
        height: h,
        texels: vec![[0, 0, 0, 255]; (w * h) as usize],
    };
    shine::capture::image_io::write_png(&png, &ldr).expect("png");
    fails_cleanly(
        &shine(&[
            "compare",
            &tested,
            &reference,
            "--surfaces",
            &normals,
            "--positions",
            png.to_str().expect("utf-8 path"),
        ]),
        "needs the positions as EXR",
    );
}
