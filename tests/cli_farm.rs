//! Shards and merges as a user runs them (issue 46), without a scheduler: a sequence's parts
//! equal the one-process run bit for bit, a reference's parts merge into the one-process
//! reference, a lab's parts into the whole lab, and a missing, doubled or foreign part is
//! refused by name. tests/slurm.rs runs the same through Slurm's job arrays.

mod common;

use std::path::Path;

use common::cli::{assert_same_files, fails_cleanly, scratch, shine, text, worst_relative};
use shine::capture::image_io::read_exr;

/// Runs `shine` and fails the test unless it succeeds; what it printed.
fn ok(args: &[&str]) -> String {
    let out = shine(args);
    assert!(out.status.success(), "shine {args:?}:\n{}", text(&out));
    text(&out)
}

/// Asserts that frames `frames` of `a` and `b` (`f_NN.exr`) are the same files.
fn same_frames(a: &Path, b: &Path, frames: std::ops::Range<u32>) {
    let names: Vec<String> = frames.map(|k| format!("f_{k:02}.exr")).collect();
    assert_same_files(a, b, &names);
}

#[test]
fn sequence_parts_equal_the_one_process_run_bit_for_bit() {
    let dir = scratch("cli_farm_sequence");
    let run = |out: &Path, extra: &[&str]| {
        std::fs::create_dir_all(out).unwrap();
        let pattern = out.join("f_%02d.exr");
        let mut args = vec![
            "render",
            "builtin:animated",
            "--width",
            "24",
            "--height",
            "24",
        ];
        args.extend_from_slice(&["--frames", "12", "-o", pattern.to_str().unwrap()]);
        args.extend_from_slice(extra);
        ok(&args)
    };
    // With the history: each part warms up from frame 0 (8 × 8 frames ≥ 12).
    let one = dir.join("one");
    run(&one, &[]);
    let parts = dir.join("parts");
    for shard in ["0/3", "1/3", "2/3"] {
        let said = run(&parts, &["--shard", shard]);
        assert!(said.contains(&format!("shard {shard}")), "{said}");
    }
    same_frames(&parts, &one, 0..12);
    let merged = parts.join("sequence.json");
    let manifests: Vec<String> = ["f_0-4.exr.json", "f_4-8.exr.json", "f_8-12.exr.json"]
        .iter()
        .map(|m| parts.join(m).display().to_string())
        .collect();
    let mut merge = vec!["merge"];
    merge.extend(manifests.iter().map(String::as_str));
    merge.extend_from_slice(&["-o", merged.to_str().unwrap()]);
    ok(&merge);

    // Without a history nothing is carried between frames: a range deep in the sequence needs
    // no warm-up, and its frames are still the one-process run's (the frame numbers key the
    // clock, the jitter and the sampling). The samples' own history is one too: with it on,
    // the range warms up.
    let no_history = ["--set", "history.frames=1", "--set", "history.samples=1"];
    let cold = dir.join("cold");
    run(&cold, &no_history);
    let late = dir.join("late");
    let said = run(
        &late,
        &[&no_history[..], &["--frame-range", "9..=11"]].concat(),
    );
    assert!(said.contains("after 0 warm-up frames"), "{said}");
    let said = run(
        &dir.join("late-samples"),
        &["--set", "history.frames=1", "--frame-range", "9..=11"],
    );
    assert!(said.contains("after 9 warm-up frames"), "{said}");
    same_frames(&late, &cold, 9..12);
    assert!(!late.join("f_08.exr").exists(), "a frame outside the range");

    // A changed frame file, a missing range and a doubled range are refused by name.
    let frame = parts.join("f_05.exr");
    let original = std::fs::read(&frame).unwrap();
    std::fs::write(&frame, &original[..original.len() / 2]).unwrap();
    fails_cleanly(&shine(&merge), "frame 5 is not the file its shard wrote");
    std::fs::write(&frame, &original).unwrap();
    let out = shine(&[
        "merge",
        &manifests[0],
        &manifests[2],
        "-o",
        merged.to_str().unwrap(),
    ]);
    fails_cleanly(&out, "missing: frames 4..8 of 12");
    let out = shine(&[
        "merge",
        &manifests[0],
        &manifests[1],
        &manifests[1],
        &manifests[2],
        "-o",
        merged.to_str().unwrap(),
    ]);
    fails_cleanly(&out, "frames 4..8 given twice");
    // Ranges outside the sequence, or empty, are refused before any frame: a range past the
    // end by the command (status 1), malformed ones by the argument parser (status 2).
    let bad = dir.join("bad");
    let pattern = bad.join("f_%02d.exr");
    for (flags, needle, status) in [
        (
            &["--frame-range", "8..16"][..],
            "the sequence has frames 0..12",
            1,
        ),
        (&["--frame-range", "5..5"][..], "holds no frame", 2),
        (&["--shard", "3/3"][..], "must be below 3", 2),
    ] {
        let mut args = vec!["render", "builtin:animated", "--frames", "12", "-o"];
        args.push(pattern.to_str().unwrap());
        args.extend_from_slice(flags);
        let out = shine(&args);
        assert_eq!(out.status.code(), Some(status), "{}", text(&out));
        assert!(text(&out).contains(needle), "{}", text(&out));
        assert!(!bad.exists(), "{flags:?}: a frame was written");
    }
}

#[test]
fn reference_parts_merge_into_the_one_process_reference() {
    let dir = scratch("cli_farm_reference");
    let path = |name: &str| dir.join(name).display().to_string();
    let trace = |out: &str, extra: &[&str]| {
        let mut args = vec!["reference", "builtin:cornell-box", "--width", "16"];
        args.extend_from_slice(&["--height", "16", "--spp", "64", "-o", out]);
        args.extend_from_slice(extra);
        ok(&args)
    };
    trace(&path("one.exr"), &[]);
    // Four parts of 16 samples: one submission each, added in the one-process run's order.
    for i in 0..4 {
        trace(
            &path(&format!("q{i}.part")),
            &["--shard", &format!("{i}/4")],
        );
    }
    let quarters: Vec<String> = (0..4).map(|i| path(&format!("q{i}.part"))).collect();
    let mut merge = vec!["merge"];
    merge.extend(quarters.iter().map(String::as_str));
    let merged = path("merged.exr");
    merge.extend_from_slice(&["-o", &merged]);
    ok(&merge);
    assert!(
        std::fs::read(&merged).unwrap() == std::fs::read(path("one.exr")).unwrap(),
        "four one-submission parts are not the one-process reference bit for bit"
    );
    // Two parts of 32 samples, two submissions each: the same samples, other additions.
    for i in 0..2 {
        trace(
            &path(&format!("h{i}.part")),
            &["--shard", &format!("{i}/2")],
        );
    }
    let halves = path("halves.exr");
    ok(&["merge", &path("h1.part"), &path("h0.part"), "-o", &halves]);
    let (a, b) = (
        read_exr(Path::new(&halves)).unwrap(),
        read_exr(&dir.join("one.exr")).unwrap(),
    );
    let worst = worst_relative(&a.texels, &b.texels);
    assert!(worst <= 1e-5, "halves differ by {worst} relative");

    // Missing, doubled and foreign parts are refused by name.
    let out = shine(&[
        "merge",
        &quarters[0],
        &quarters[2],
        &quarters[3],
        "-o",
        &merged,
    ]);
    fails_cleanly(&out, "missing: part 1/4");
    let out = shine(&[
        "merge",
        &quarters[0],
        &quarters[1],
        &quarters[1],
        &quarters[3],
        "-o",
        &merged,
    ]);
    fails_cleanly(&out, "part 1/4 given twice");
    trace(&path("seed.part"), &["--shard", "1/4", "--seed", "3"]);
    let out = shine(&[
        "merge",
        &quarters[0],
        &path("seed.part"),
        &quarters[2],
        &quarters[3],
        "-o",
        &merged,
    ]);
    fails_cleanly(&out, "`seed` is 0 there, 3 here");
    let truncated = path("torn.part");
    let bytes = std::fs::read(&quarters[1]).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() - 100]).unwrap();
    let out = shine(&["merge", &quarters[0], &truncated, "-o", &merged]);
    fails_cleanly(&out, "torn.part");
    // Inside a Slurm array task, a reference becomes a part, which is no image; a single frame
    // stays whole.
    let in_array = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_shine"))
            .args(args)
            .env("SLURM_ARRAY_TASK_ID", "1")
            .env("SLURM_ARRAY_TASK_COUNT", "2")
            .output()
            .unwrap()
    };
    let out = in_array(&["reference", "builtin:cornell-box", "-o", &path("task.exr")]);
    fails_cleanly(&out, "name -o something.part");
    let frame = path("task-frame.exr");
    let out = in_array(&[
        "render",
        "builtin:cornell-box",
        "--width",
        "16",
        "-o",
        &frame,
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(Path::new(&frame).exists());
    // A time budget cannot be split into parts.
    let out = shine(&[
        "reference",
        "builtin:cornell-box",
        "--shard",
        "0/2",
        "--seconds",
        "1",
        "-o",
        &path("x.part"),
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", text(&out));
}

#[test]
fn lab_parts_merge_into_the_whole_lab() {
    let dir = scratch("cli_farm_lab");
    let configs = dir.join("configs.toml");
    std::fs::write(
        &configs,
        "[[config]]\nlabel = \"none\"\nset = { gi = \"none\" }\n\
         [[config]]\nlabel = \"hvl\"\nset = { gi = \"hvl\" }\n\
         [[config]]\nlabel = \"igi\"\nset = { gi = \"igi\" }\n",
    )
    .unwrap();
    let out = dir.join("lab");
    let lab = |extra: &[&str]| {
        let mut args = vec!["lab", "builtin:cornell-box", "--configs"];
        args.push(configs.to_str().unwrap());
        args.extend_from_slice(&["--width", "16", "--height", "16", "--truth-spp", "16"]);
        args.extend_from_slice(&["--sequence-spp", "8", "--sequence-frames", "3"]);
        args.extend_from_slice(&["--cost-frames", "1", "--out", out.to_str().unwrap()]);
        args.extend_from_slice(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_shine"))
            .args(&args)
            .env("SHINE_CACHE_DIR", dir.join("cache"))
            .output()
            .unwrap()
    };
    for shard in ["0/2", "1/2"] {
        let run = lab(&["--shard", shard]);
        assert!(run.status.success(), "{}", text(&run));
    }
    let part = |i: u32| out.join(format!("part-{i}-of-2/lab.json"));
    let merged = dir.join("merged");
    let merge = |parts: &[&Path]| {
        let mut args = vec!["merge".to_owned()];
        args.extend(parts.iter().map(|p| p.display().to_string()));
        args.extend(["-o".to_owned(), merged.display().to_string()]);
        std::process::Command::new(env!("CARGO_BIN_EXE_shine"))
            .args(&args)
            .env("SHINE_CACHE_DIR", dir.join("cache"))
            .output()
            .unwrap()
    };
    fails_cleanly(&merge(&[&part(0)]), "missing: part 1/2");
    let done = merge(&[&part(1), &part(0)]);
    assert!(done.status.success(), "{}", text(&done));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(merged.join("lab.json")).unwrap()).unwrap();
    let labels: Vec<&str> = report["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["config"]["label"].as_str().unwrap())
        .collect();
    assert_eq!(labels, ["none", "hvl", "igi"]);
    assert!(report.get("part").is_none(), "the merge is the whole lab");
    for p in report["points"].as_array().unwrap() {
        let image = p["image"].as_str().unwrap();
        assert!(merged.join(image).exists(), "{image} was not brought along");
    }
    assert!(merged.join("index.html").exists());
}
