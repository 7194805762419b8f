//! A host that moves things: an instance (a node override) and a light (the per-frame light
//! list) change every frame through `GiContext::update`, and the host redraws its G-buffer
//! with the instance moved. Each frame matches shine's own renderer given the same updates,
//! and a long loop holds its memory flat.

use super::gi_context::{Bench, EXTENT, error_of, exact_desc};
use shine::embed::{DispatchShape, FrameUpdate, GiContext};
use shine::passes::composite::Component;
use shine::{CameraPose, Renderer, Settings};
use shine_scene::{Scene, Transform};

/// Metres the short block slides along +x per frame.
const SLIDE: f32 = 0.03;
/// Metres the lamp moves along −x per frame.
const LAMP_STEP: f32 = 0.04;

/// Frame `k`'s update: the short block slid by `k · SLIDE`, the lamp moved by `k · LAMP_STEP`.
fn update(scene: &Scene, k: u32) -> FrameUpdate {
    let block = scene
        .nodes
        .iter()
        .position(|n| n.name == "short block")
        .expect("short block");
    let rest = scene.local_transforms_at(0.0)[block];
    let mut light = scene.lights_at(&scene.world_transforms_at(0.0))[0];
    light.position[0] -= k as f32 * LAMP_STEP;
    FrameUpdate {
        nodes: vec![(
            block,
            Transform {
                translation: rest.translation + glam::Vec3::X * (k as f32 * SLIDE),
                ..rest
            },
        )],
        lights: vec![(0, light)],
        ..FrameUpdate::default()
    }
}

/// Shine's own renderer's indirect light for each of `frames`, given the same updates and
/// the bench's still camera, with a history of `history` frames.
fn renderer_frames(bench: &Bench, frames: u32, history: u32) -> Vec<Vec<[f32; 3]>> {
    let mut renderer = Renderer::new(bench.device()).expect("renderer");
    renderer.set_scene(&bench.scene, 0.0).expect("scene");
    let mut settings = Settings {
        width: EXTENT[0],
        height: EXTENT[1],
        gi: "hvl".parse().expect("technique"),
        ..Settings::default()
    };
    settings.output.component = Component::Indirect;
    settings.output.exposure = 1.0;
    settings.hvl.shadow_rays = 0;
    settings.hvl.near_range = 0.0;
    settings.history.max_frames = history;
    let camera = bench.camera(0);
    (0..frames)
        .map(|k| {
            renderer
                .update(&FrameUpdate {
                    camera: Some(CameraPose {
                        world: camera.view.inverse(),
                        projection: bench.scene.cameras[0].projection,
                    }),
                    ..update(&bench.scene, k)
                })
                .expect("update");
            let hdr = renderer.render(&settings).expect("render").hdr.texels;
            hdr.iter().map(|p| [p[0], p[1], p[2]]).collect()
        })
        .collect()
}

/// Four frames of a sliding block and a moving lamp: each of the context's frames matches
/// the renderer's frame with the same updates, and the light does change from frame to frame.
/// Without a history (`history.frames = 1`) each frame is the update alone: relative RMSE ≤
/// 3 %, energy within 1 %, as the still comparison. With the default history the host gives
/// no motion vectors, so the moving block's history reprojects by the camera alone where the
/// renderer's follows the block: ≤ 5 % and 2 %, as the moving-camera comparison.
#[test]
fn a_moving_instance_and_light_match_the_renderer_frame_by_frame() {
    let mut bench = Bench::new(false);
    let frames = 4;
    let default_history = shine::Settings::default().history.max_frames;
    for (history, rmse_bound, energy_bound) in [(1, 0.03, 0.01), (default_history, 0.05, 0.02)] {
        let truth = renderer_frames(&bench, frames, history);
        let mut desc = exact_desc(EXTENT, "hvl");
        desc.settings.history.max_frames = history;
        let mut gi = GiContext::new(bench.device(), &desc).expect("context");
        gi.set_scene(&bench.scene, 0.0).expect("scene");
        gi.warm_up(DispatchShape::default()).expect("warm up");
        for k in 0..frames {
            let u = update(&bench.scene, k);
            bench.pose(&u);
            gi.update(&u).expect("update");
            let output = bench.run_still(&mut gi, k);
            let (relative_rmse, energy) = error_of(&output, &truth[k as usize]);
            println!(
                "history {history}, frame {k}: relative RMSE {relative_rmse:.4}, energy {energy:.4}"
            );
            assert!(
                relative_rmse <= rmse_bound,
                "frame {k}: relative RMSE {relative_rmse}"
            );
            assert!(
                (energy - 1.0).abs() <= energy_bound,
                "frame {k}: energy {energy}"
            );
        }
        let (moved, _) = error_of(&truth[0], &truth[frames as usize - 1]);
        assert!(moved > 0.05, "nothing moved: {moved}");
    }
    bench.assert_clean();
}

/// 300 frames of a host loop that moves the block and the lamp every frame: after the first
/// frames the device memory shine holds does not change, and the validation layer reports
/// nothing.
#[test]
fn three_hundred_moving_frames_hold_memory_flat() {
    let mut bench = Bench::new(false);
    let mut gi = GiContext::new(bench.device(), &exact_desc(EXTENT, "hvl")).expect("context");
    gi.set_scene(&bench.scene, 0.0).expect("scene");
    gi.warm_up(DispatchShape::default()).expect("warm up");
    let mut settled = None;
    for k in 0..300 {
        // Back and forth, so the block stays in the box.
        let u = update(&bench.scene, k % 20);
        bench.pose(&u);
        gi.update(&u).expect("update");
        bench.run_still(&mut gi, k);
        if k == 10 {
            settled = Some(bench.device().memory_usage());
        }
        if k % 50 == 49 {
            println!("frame {}: {:?}", k + 1, bench.device().memory_usage());
        }
    }
    assert_eq!(Some(bench.device().memory_usage()), settled);
    bench.assert_clean();
}
