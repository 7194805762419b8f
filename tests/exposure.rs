//! Automatic exposure (issue 21, item 5; src/passes/exposure.rs): the tonemapped frame is the
//! scene-referred HDR frame times the exposure the CPU twin computes from it (the log-average
//! luminance mapped to the key), and a sequence adapts from one frame's exposure towards the
//! next frame's target by the set fraction. The HDR frame is left alone.

mod common;

use glam::Vec3;
use shine::capture::tonemap::{DEFAULT_TONEMAP, encode_ldr};
use shine::frame::renderer::FrameImage;
use shine::passes::exposure::{KEY, adapt, log_average, target_exposure};
use shine::{Renderer, Settings};
use shine_scene::Scene;

const SIZE: u32 = 32;

fn settings(gi: &str, auto: bool) -> Settings {
    let mut s = Settings {
        width: SIZE,
        height: SIZE,
        ..Settings::default()
    };
    s.set("gi", gi).expect("gi");
    s.set("output.auto_exposure", &auto.to_string())
        .expect("auto exposure");
    s.set("output.adaptation", "0.5").expect("adaptation");
    s
}

/// The exposure the CPU twin gives the HDR frame (scene-referred: exposure 1).
fn twin_target(frame: &FrameImage) -> f32 {
    let radiance = frame.hdr.texels.iter().map(|t| Vec3::new(t[0], t[1], t[2]));
    target_exposure(log_average(radiance).expect("finite pixels"), KEY)
}

/// The share of pixels whose LDR texel is within one step of `hdr × exposure` tonemapped.
fn agreement(frame: &FrameImage, exposure: f32) -> f32 {
    let close = frame
        .hdr
        .texels
        .iter()
        .zip(&frame.ldr.texels)
        .filter(|(h, l)| {
            let want = encode_ldr(DEFAULT_TONEMAP, Vec3::new(h[0], h[1], h[2]) * exposure);
            (0..3).all(|c| want[c].abs_diff(l[c]) <= 1)
        })
        .count();
    close as f32 / frame.hdr.texels.len() as f32
}

/// The dim Cornell box, with and without GI: the PNG frame is exposed by the twin's exposure
/// (every pixel within one step), the EXR frame is the same as with a fixed exposure, and the
/// exposure brightens this scene (a fixed exposure of 1 leaves its log-average far below grey).
#[test]
fn the_tonemapped_frame_is_exposed_to_the_key() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    for gi in ["none", "hvl"] {
        let mut renderer = Renderer::new(&device).expect("renderer");
        renderer.set_scene(&scene, 0.0).expect("scene");
        let auto = renderer.render(&settings(gi, true)).expect("render");
        let mut renderer = Renderer::new(&device).expect("renderer");
        renderer.set_scene(&scene, 0.0).expect("scene");
        let fixed = renderer.render(&settings(gi, false)).expect("render");
        assert_eq!(
            auto.hdr.texels, fixed.hdr.texels,
            "{gi}: the HDR frame moved"
        );
        let e = twin_target(&auto);
        let share = agreement(&auto, e);
        println!(
            "{gi}: exposure {e:.3}, {:.1}% of pixels agree",
            100.0 * share
        );
        assert!(e > 2.0, "{gi}: exposure {e}");
        assert!(share > 0.99, "{gi}: {share}");
        assert!(agreement(&auto, 1.0) < 0.5, "{gi}: exposure 1 fits as well");
    }
    common::assert_clean(&device);
}

/// A sequence: frame 1 direct light only, frame 2 with HVL (brighter). Frame 1 takes its
/// target; frame 2 goes half the way (`output.adaptation = 0.5`) from frame 1's exposure to its
/// own target, in log space.
#[test]
fn a_sequence_adapts_towards_each_frames_target() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("scene");
    let first = renderer.render(&settings("none", true)).expect("frame 1");
    let second = renderer.render(&settings("hvl", true)).expect("frame 2");
    let (e1, target2) = (twin_target(&first), twin_target(&second));
    let e2 = adapt(e1, target2, 0.5);
    println!("frame 1 exposure {e1:.3}; frame 2 target {target2:.3}, adapted {e2:.3}");
    assert!(
        (target2 / e1 - 1.0).abs() > 0.05,
        "the targets hardly differ"
    );
    assert!(agreement(&first, e1) > 0.99);
    assert!(agreement(&second, e2) > 0.99, "frame 2 not at {e2}");
    assert!(
        agreement(&second, target2) < 0.9,
        "frame 2 jumped to its target"
    );
    common::assert_clean(&device);
}
