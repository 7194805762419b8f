//! Whole frames of the built-in scenes on the Vulkan device: finite, lit, bounded and
//! bit-identical across runs, with zero validation messages.

mod common;

use shine::renderer::{FrameParams, Renderer};
use shine_scene::Scene;

fn render(name: &str, params: &FrameParams) -> shine::renderer::FrameImage {
    let device = common::device();
    let scene = Scene::builtin(name).expect("built-in scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let frame = renderer.render(params).expect("frame");
    drop(renderer);
    common::assert_clean(&device);
    frame
}

#[test]
fn cornell_box_direct_light_is_finite_lit_and_repeatable() {
    let params = FrameParams {
        width: 64,
        height: 64,
        rsm_size: 64,
        ..FrameParams::default()
    };
    let a = render("cornell-box", &params);
    assert!(a.rgba.iter().all(|v| v.is_finite()), "non-finite radiance");
    let mean: f32 = a.rgba.chunks(4).map(|p| p[0] + p[1] + p[2]).sum::<f32>() / (64.0 * 64.0);
    assert!(mean > 1e-3, "the frame is black (mean {mean})");
    let b = render("cornell-box", &params);
    assert_eq!(a.rgba, b.rgba, "two runs differ");
    let names: Vec<_> = a.timings.iter().map(|t| t.name.as_str()).collect();
    for pass in ["gbuffer", "rsm", "direct"] {
        assert!(names.contains(&pass), "no timing for {pass}: {names:?}");
    }
}
