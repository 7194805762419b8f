//! The GI lab's `index.html` (`shine::lab::page`) opened in a real browser: a synthetic report
//! of two scenes, its page written, then Debian's Chromium, headless, loads it from disk with
//! no server and must decode every inlined image and draw a page that is not blank. Also: a
//! missing image is an error naming the file, and labels are escaped.
//!
//! Never skips: without `/usr/bin/chromium` the test fails with the install command
//! (`scripts/install-deps.sh` installs it).

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use shine::capture::image_io::{LdrImage, write_png};
use shine::lab::page::write_page;
use shine::lab::{
    Cost, LabConfig, LabPoint, LabReport, LabSetup, Motion, SceneFailure, StillError,
};

const CHROMIUM: &str = "/usr/bin/chromium";
/// A label with every character the page must escape.
const SPECIAL_LABEL: &str = r#"igi<count & "8">"#;

/// A fresh directory of this test process.
fn scratch(test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lab_page_{test}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// A 64×64 PNG at `dir/relative`, a gradient distinct for each `seed`.
fn png(dir: &Path, relative: &str, seed: u32) {
    let path = dir.join(relative);
    std::fs::create_dir_all(path.parent().expect("parent")).expect("image dir");
    let texels = (0..64u32 * 64)
        .map(|i| {
            let (x, y) = (i % 64, i / 64);
            [
                (x * 4 + seed * 37) as u8,
                (y * 4 + seed * 71) as u8,
                ((x ^ y) * 4 + seed * 13) as u8,
                255,
            ]
        })
        .collect();
    let image = LdrImage {
        width: 64,
        height: 64,
        texels,
    };
    write_png(&path, &image).expect("write test PNG");
}

fn point(scene: &str, tag: &str, label: &str, i: usize) -> LabPoint {
    let f = i as f64;
    LabPoint {
        scene: scene.to_owned(),
        config: LabConfig {
            label: label.to_owned(),
            set: vec![("gi".to_owned(), label.to_owned())],
        },
        error: StillError {
            relative_rmse: 0.30 - 0.05 * f,
            energy_ratio: 0.92 + 0.02 * f,
            flip: 0.12 - 0.01 * f,
            regions: vec![0.2 + 0.01 * f; 16],
            region_energy: vec![0.95; 16],
        },
        cost: Cost {
            frame_ms: 1.5 + 2.0 * f,
            passes: vec![
                ("gbuffer".to_owned(), 0.4),
                ("gi".to_owned(), 1.1 + 2.0 * f),
            ],
            clock: "gpu".to_owned(),
        },
        motion: Motion {
            flicker: 0.05 + 0.01 * f,
            cold_flicker: 0.09 + 0.01 * f,
            truth_flicker: 0.02,
            truth_flicker_noise_free: 0.01,
            flicker_ratio: (0.05 + 0.01 * f) / 0.02,
            sequence_rmse: 0.31 - 0.05 * f,
            cold_rmse: 0.30 - 0.05 * f,
            lag: 0.01,
        },
        image: format!("{tag}/{i}.png"),
        flip_map: format!("{tag}/{i}.flip.png"),
    }
}

/// A two-scene report (three points each, one label to escape, one failed scene) with every
/// image it names written under `dir`; its fronts and plots; and how many images the page shows.
#[allow(clippy::type_complexity)]
fn synthetic(
    dir: &Path,
) -> (
    LabReport,
    Vec<(String, Vec<usize>)>,
    Vec<(String, String)>,
    usize,
) {
    let scenes = [
        ("builtin:cornell-box", "cornell"),
        ("scenes/room.gltf", "room"),
    ];
    let labels = ["hvl.count=16", "hvl", SPECIAL_LABEL];
    let mut points = Vec::new();
    let mut truths = Vec::new();
    let mut plots = Vec::new();
    let mut seed = 0;
    for (scene, tag) in scenes {
        for (i, label) in labels.iter().enumerate() {
            let p = point(scene, tag, label, i);
            png(dir, &p.image, seed);
            png(dir, &p.flip_map, seed + 1);
            seed += 2;
            points.push(p);
        }
        truths.push((scene.to_owned(), format!("{tag}/truth.png")));
        png(dir, &format!("{tag}/truth.png"), seed);
        plots.push((scene.to_owned(), format!("{tag}/pareto.png")));
        png(dir, &format!("{tag}/pareto.png"), seed + 1);
        seed += 2;
    }
    let fronts = vec![
        (scenes[0].0.to_owned(), vec![0, 2]),
        (scenes[1].0.to_owned(), vec![1]),
    ];
    let front_points: usize = fronts.iter().map(|(_, f)| f.len()).sum();
    let images = truths.len() + 2 * front_points + plots.len();
    let report = LabReport {
        device: "llvmpipe (LLVM 15.0.6, 256 bits)".to_owned(),
        driver: "Mesa 22.3.6".to_owned(),
        revision: "0123abc".to_owned(),
        setup: LabSetup::default(),
        points,
        failures: vec![SceneFailure {
            scene: "scenes/broken.gltf".to_owned(),
            reason: "cannot read <buffer 0>".to_owned(),
        }],
        truths,
        part: None,
    };
    (report, fronts, plots, images)
}

/// Runs Chromium headless with `args` (after the common flags) on `page`, stdout into
/// `stdout`; fails the test when Chromium is missing, fails or takes over two minutes.
fn chromium(dir: &Path, page: &Path, args: &[String], stdout: &Path) -> Duration {
    assert!(
        Path::new(CHROMIUM).exists(),
        "the lab page test drives a headless browser: {CHROMIUM} is missing \
         (Debian: apt-get install chromium, or scripts/install-deps.sh)"
    );
    let profile = dir.join(format!("chromium-profile-{}", args.len()));
    let _ = std::fs::remove_dir_all(&profile);
    std::fs::create_dir_all(&profile).expect("profile dir");
    let page = page.canonicalize().expect("absolute page path");
    let stderr_path = dir.join("chromium.stderr");
    let start = Instant::now();
    let mut child = Command::new(CHROMIUM)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("--virtual-time-budget=5000")
        .args(args)
        .arg(format!("file://{}", page.display()))
        .stdin(Stdio::null())
        .stdout(File::create(stdout).expect("stdout file"))
        .stderr(File::create(&stderr_path).expect("stderr file"))
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {CHROMIUM}: {e}"));
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for chromium") {
            break status;
        }
        if start.elapsed() > Duration::from_secs(120) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{CHROMIUM} {args:?} ran over two minutes");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let took = start.elapsed();
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    assert!(
        status.success(),
        "{CHROMIUM} {args:?} failed ({status}):\n{stderr}"
    );
    eprintln!("chromium {args:?}: {:.2} s", took.as_secs_f64());
    took
}

#[test]
fn chromium_loads_every_image_of_the_page_and_draws_it() {
    let dir = scratch("chromium");
    let (report, fronts, plots, images) = synthetic(&dir);
    let page = write_page(&dir, &report, &fronts, &plots).expect("write the page");
    assert_eq!(page, dir.join("index.html"));
    let html = std::fs::read_to_string(&page).expect("read the page");

    // Self-contained: every image is inlined, and there are as many as expected.
    let sources = html.matches(" src=\"").count();
    let inlined = html.matches(" src=\"data:image/png;base64,").count();
    assert_eq!(sources, images, "images on the page");
    assert_eq!(inlined, images, "every image a data: URI");
    assert_eq!(
        html.matches("<tr class=\"front\">").count(),
        3,
        "front rows"
    );
    assert_eq!(
        html.matches("<tr").count(),
        1 + report.points.len(),
        "table rows"
    );
    assert!(
        html.contains("cannot read &lt;buffer 0&gt;"),
        "the failure is listed"
    );
    assert!(html.contains("llvmpipe") && html.contains("Mesa 22.3.6") && html.contains("0123abc"));

    let dom_path = dir.join("dom.html");
    let dom_time = chromium(&dir, &page, &["--dump-dom".to_owned()], &dom_path);
    let dom = std::fs::read_to_string(&dom_path).expect("read the dumped DOM");
    let expected = format!("data-images-loaded=\"{images}/{images}\"");
    assert!(
        dom.contains(&expected),
        "Chromium's DOM lacks {expected}: the body is {:?}",
        dom.find("<body")
            .map(|i| dom[i..].chars().take(300).collect::<String>())
    );
    assert!(dom.contains(&format!("<title>lab: {images}/{images} images</title>")));

    let shot = dir.join("screenshot.png");
    let shot_time = chromium(
        &dir,
        &page,
        &[
            format!("--screenshot={}", shot.display()),
            "--window-size=1200,2000".to_owned(),
        ],
        &dir.join("screenshot.stdout"),
    );
    let picture = image::open(&shot)
        .unwrap_or_else(|e| panic!("the screenshot {} does not decode: {e}", shot.display()))
        .to_rgba8();
    assert_eq!(picture.dimensions(), (1200, 2000));
    let first = *picture.get_pixel(0, 0);
    let colours_differ = picture.pixels().any(|p| *p != first);
    assert!(colours_differ, "the screenshot is one colour: {first:?}");
    eprintln!(
        "chromium took {:.2} s (DOM) + {:.2} s (screenshot)",
        dom_time.as_secs_f64(),
        shot_time.as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_missing_image_is_an_error_naming_the_file() {
    let dir = scratch("missing");
    let (report, fronts, plots, _) = synthetic(&dir);
    // Point 2 of the first scene is on its front: its FLIP map is inlined.
    let missing = dir.join(&report.points[2].flip_map);
    std::fs::remove_file(&missing).expect("remove a FLIP map");
    let error = write_page(&dir, &report, &fronts, &plots)
        .expect_err("a missing image must fail")
        .to_string();
    assert!(
        error.contains(&missing.display().to_string()),
        "the error does not name {}: {error}",
        missing.display()
    );
    assert!(!dir.join("index.html").exists(), "no page on failure");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn labels_and_scenes_are_escaped() {
    let dir = scratch("escape");
    let (report, fronts, plots, _) = synthetic(&dir);
    let page = write_page(&dir, &report, &fronts, &plots).expect("write the page");
    let html = std::fs::read_to_string(page).expect("read the page");
    let escaped = "igi&lt;count &amp; &quot;8&quot;&gt;";
    // In the figure's caption and alt texts (it is on the first scene's front) and the table.
    assert!(html.matches(escaped).count() >= 4, "escaped label missing");
    assert!(
        !html.contains(SPECIAL_LABEL),
        "the raw label leaked into the HTML"
    );
    assert!(
        !html.contains("<count"),
        "the raw label leaked into the HTML"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
