//! A context's warm-up (no first-dispatch hitch) and its history reset (camera cuts), on the
//! host bench of `gi_context.rs`.

use super::gi_context::{Bench, EXTENT, exact_desc};
use shine::embed::{DispatchShape, GiContext, MemoryReport};

/// After `warm_up`, the host's frames create no pipeline and allocate no device memory: the
/// frame path has nothing left to compile or bind (what made the first dispatch a hitch).
/// Each technique the Cornell box can run without an environment map, on the warm-up's
/// shape (the bench brings neither motion nor an environment).
#[test]
fn warmed_up_frames_create_no_pipeline_and_allocate_nothing() {
    let bench = Bench::new(false);
    for technique in ["hvl", "igi", "aaf"] {
        let mut gi =
            GiContext::new(bench.device(), &exact_desc(EXTENT, technique)).expect("context");
        gi.set_scene(&bench.scene, 0.0).expect("scene");
        gi.warm_up(DispatchShape::default()).expect("warm up");
        let device = bench.device();
        let (pipelines, memory) = (device.pipelines_created(), held(&gi));
        bench.run(&mut gi, 0..4);
        assert_eq!(
            device.pipelines_created(),
            pipelines,
            "{technique}: the host's frames created pipelines"
        );
        assert_eq!(
            held(&gi),
            memory,
            "{technique}: the host's frames allocated"
        );
    }
    bench.assert_clean();
}

/// What `gi` holds on the device, objects another context left for release aside (they go
/// while the host's frames run).
fn held(gi: &GiContext) -> MemoryReport {
    MemoryReport {
        pending_release: 0,
        ..gi.memory_report()
    }
}

/// Without a warm-up the first dispatch does create pipelines: the test above can fail.
#[test]
fn a_cold_first_dispatch_creates_pipelines() {
    let bench = Bench::new(false);
    let mut gi = bench.context("hvl");
    let before = bench.device().pipelines_created();
    bench.run(&mut gi, 0..1);
    assert!(bench.device().pipelines_created() > before);
}

/// A warm-up leaves no trace in the host's frames, and `reset_history` makes the next frame
/// what a fresh context's first frame is: a history carried over frames 0..3 of a turning
/// camera is gone at the cut. Amortised HVL (four slices), whose frames differ most from a
/// first frame.
#[test]
fn reset_history_gives_a_first_frame() {
    let bench = Bench::new(false);
    let context = || {
        let mut desc = exact_desc(EXTENT, "hvl");
        desc.settings.hvl.slices = 4;
        let mut gi = GiContext::new(bench.device(), &desc).expect("context");
        gi.set_scene(&bench.scene, 0.0).expect("scene");
        gi
    };
    let mut fresh = context();
    let first = bench.run(&mut fresh, 6..7);
    let mut warmed = context();
    warmed.warm_up(DispatchShape::default()).expect("warm up");
    assert_eq!(
        bench.run(&mut warmed, 6..7),
        first,
        "the warm-up left a trace"
    );
    let mut cut = context();
    let carried = bench.run(&mut cut, 3..6);
    cut.reset_history();
    let after_cut = bench.run(&mut cut, 6..7);
    assert_ne!(carried, first);
    assert_eq!(after_cut, first, "the reset left a history");
    bench.assert_clean();
}
