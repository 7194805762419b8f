//! The GI lab end to end on the Vulkan device (tiny: 16² frames, two configurations): every
//! output written, the truths cached, an interrupted run resumed where it stopped, an
//! unreadable scene failing alone, the budget mode's pick on the measured front, and zero
//! validation messages.

mod common;

use std::path::PathBuf;

use shine::farm::Shard;
use shine::lab::budget::{self, BudgetEntry};
use shine::lab::configs::parse;
use shine::lab::run::{JOURNAL, LabPlan, run};
use shine::lab::{LabPoint, LabSetup};
use shine::study::Progress;
use shine_scene::Scene;

/// Counts the configurations measured (the run advances by one after each).
#[derive(Default)]
struct Count {
    measured: Vec<String>,
}

impl Progress for Count {
    fn stage(&mut self, _: &str, _: u64) {}
    fn advance(&mut self, steps: u64, message: &str) {
        if steps > 0 && message != "truth" {
            self.measured.push(message.to_owned());
        }
    }
    fn finish(&mut self) {}
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("lab_{name}_{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

fn load(scene: &str) -> Result<Scene, String> {
    match scene.strip_prefix("builtin:") {
        Some(name) => Scene::builtin(name).map_err(|e| e.to_string()),
        None => shine_scene::load(scene).map_err(|e| e.to_string()),
    }
}

/// The same points, as read back from the journal (JSON keeps floats to the last digit or
/// two).
fn same_points(a: &[LabPoint], b: &[LabPoint]) -> bool {
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-12 * x.abs().max(1.0);
    a.len() == b.len()
        && a.iter().zip(b).all(|(p, q)| {
            p.config == q.config
                && p.image == q.image
                && close(p.error.relative_rmse, q.error.relative_rmse)
                && close(p.cost.frame_ms, q.cost.frame_ms)
                && close(p.motion.flicker, q.motion.flicker)
        })
}

#[test]
fn a_lab_measures_writes_and_resumes() {
    let device = common::device();
    let dir = scratch("run");
    let setup = LabSetup {
        extent: [16, 16],
        truth_spp: 64,
        sequence_spp: 16,
        sequence_frames: 3,
        cost_frames: 1,
        warmup: 1,
        ..LabSetup::default()
    };
    let configs = parse(
        "[[config]]\nlabel = \"hvl 64\"\nset = { gi = \"hvl\", \"hvl.count\" = 64 }\n\
         [[config]]\nlabel = \"igi\"\nset = { gi = \"igi\", \"igi.vpl_count\" = 64 }\n",
        "test.toml",
        &setup,
    )
    .unwrap();
    let missing = dir.join("no-such-scene.glb").display().to_string();
    let plan = LabPlan {
        scenes: vec!["builtin:cornell-box".into(), missing.clone()],
        configs,
        setup,
        out: dir.join("out"),
        cache: Some(dir.join("cache")),
        revision: "test".into(),
        shard: Shard::WHOLE,
    };
    let mut first = Count::default();
    let report = run(&device, &plan, &load, &mut first).unwrap();
    assert_eq!(first.measured, ["hvl 64", "igi"]);
    assert_eq!(report.points.len(), 2);
    // The unreadable scene failed alone, and said why.
    assert_eq!(report.failures.len(), 1);
    assert_eq!(report.failures[0].scene, missing);
    for p in &report.points {
        let e = &p.error;
        assert!(e.relative_rmse > 0.0 && e.relative_rmse < 1.0, "{e:?}");
        assert!((0.5..2.0).contains(&e.energy_ratio), "{e:?}");
        assert!(
            e.flip > 0.0 && e.flip < 1.0 && e.regions.len() == 16,
            "{e:?}"
        );
        assert!(p.cost.frame_ms > 0.0 && !p.cost.passes.is_empty());
        assert!(
            p.motion.truth_flicker > 0.0,
            "the light moves: {:?}",
            p.motion
        );
        assert!(p.motion.flicker > 0.0 && p.motion.flicker_ratio > 0.0);
        assert!(dir.join("out").join(&p.image).is_file());
        assert!(dir.join("out").join(&p.flip_map).is_file());
    }
    // The techniques differ: their errors are not the same number.
    assert_ne!(
        report.points[0].error.relative_rmse,
        report.points[1].error.relative_rmse
    );
    for file in [
        "lab.json",
        "lab.csv",
        "index.html",
        "pareto-builtin_cornell-box.png",
    ] {
        assert!(dir.join("out").join(file).is_file(), "{file}");
    }
    let csv = std::fs::read_to_string(dir.join("out/lab.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(csv.contains("\"hvl 64\"") && csv.contains(&report.device));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/lab.json")).unwrap()).unwrap();
    assert_eq!(json["points"].as_array().map(Vec::len), Some(2));
    assert_eq!(json["revision"], "test");

    // Run again: nothing is measured again.
    let mut again = Count::default();
    let same = run(&device, &plan, &load, &mut again).unwrap();
    assert!(again.measured.is_empty(), "{:?}", again.measured);
    assert!(same_points(&same.points, &report.points));

    // Interrupted while writing its last point: the torn line is dropped and that point alone
    // is measured again; the truths come from the cache.
    let journal = dir.join("out").join(JOURNAL);
    let text = std::fs::read_to_string(&journal).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let igi = lines.iter().position(|l| l.contains("\"igi\"")).unwrap();
    let mut torn: String = lines[..igi].iter().map(|l| format!("{l}\n")).collect();
    torn.push_str(&lines[igi][..lines[igi].len() / 2]);
    std::fs::write(&journal, torn).unwrap();
    let cached = std::fs::read_dir(dir.join("cache/lab-truth"))
        .unwrap()
        .count();
    let mut resumed = Count::default();
    let after = run(&device, &plan, &load, &mut resumed).unwrap();
    assert_eq!(resumed.measured, ["igi"]);
    assert_eq!(after.points.len(), 2);
    assert!(same_points(&after.points[..1], &report.points[..1]));
    assert_eq!(
        std::fs::read_dir(dir.join("cache/lab-truth"))
            .unwrap()
            .count(),
        cached
    );

    // Other conditions over the same journal are refused.
    let other = LabPlan {
        setup: LabSetup {
            truth_spp: 32,
            ..plan.setup.clone()
        },
        ..plan.clone()
    };
    let refused = run(&device, &other, &load, &mut Count::default()).unwrap_err();
    assert!(
        refused.to_string().contains("other conditions"),
        "{refused}"
    );

    // The budget mode on these measured points: within budget and on the front.
    let key = |s: &str| s.to_owned();
    let entries: Vec<BudgetEntry> = budget::entries_of(&after.points, &after.setup, &key);
    let refs: Vec<&BudgetEntry> = entries.iter().collect();
    let points: Vec<&LabPoint> = after.points.iter().collect();
    let front = shine::lab::pareto::front(&points);
    for budget_ms in entries.iter().map(|e| e.frame_ms) {
        let choice = budget::pick(&refs, budget_ms).unwrap();
        assert!(choice.fits && choice.frame_ms <= budget_ms);
        let on_front = front
            .iter()
            .any(|&i| points[i].config.label == choice.config.label);
        assert!(on_front, "{choice:?} is off the front");
    }

    // A GI context with a frame budget and no results for this device: its first scene runs
    // the quick lab, records it, and the context renders the configuration chosen; a second
    // context at that size chooses from the recorded table at creation.
    let cache = dir.join("context-cache");
    // SAFETY: this test binary runs this one test; nothing else reads the environment now.
    unsafe { std::env::set_var("SHINE_CACHE_DIR", &cache) };
    let mut desc = shine::embed::GiContextDesc::new([16, 16], "hvl").unwrap();
    desc.budget_ms = Some(1e6);
    let mut context = shine::embed::GiContext::new(&device, &desc).unwrap();
    assert!(context.budget_choice().is_none(), "no results yet");
    let scene = Scene::builtin("cornell-box").unwrap();
    context.set_scene(&scene, 0.0).unwrap();
    let chosen = context.budget_choice().cloned().unwrap();
    assert!(chosen.fits && chosen.candidates >= 6, "{chosen:?}");
    let table = budget::load_table(&budget::table_path(
        &cache,
        &device.info().name,
        &device.info().driver,
    ))
    .unwrap();
    assert!(table.entries.len() >= 6);
    // The least error of the candidates, within an unlimited budget.
    let least = table
        .entries
        .iter()
        .map(|e| e.relative_rmse)
        .fold(f64::INFINITY, f64::min);
    assert_eq!(chosen.relative_rmse, least);
    let second = shine::embed::GiContext::new(&device, &desc).unwrap();
    assert_eq!(
        second.budget_choice().map(|c| &c.config),
        Some(&chosen.config)
    );
    let bad = shine::embed::GiContextDesc {
        budget_ms: Some(-1.0),
        ..desc.clone()
    };
    assert!(shine::embed::GiContext::new(&device, &bad).is_err());
    common::assert_clean(&device);
    let _ = std::fs::remove_dir_all(&dir);
}
