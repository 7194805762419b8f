//! Histories (src/passes/accumulate.rs): `accumulate` against its CPU twin (reprojection,
//! disocclusion, variance clip, blend; the indirect light's geometry-tested mode and TAA's
//! colour-only mode), history rejected on a disocclusion, and a static scene accumulated over
//! frames against its single frame, and a switched-off light gone the next frame; the
//! indirect light's trend and temporal clip (issue 43) against the spatial clip alone on a
//! noisy ramp.

mod common;

use common::{Rng, bytes_f16, f16_to_f32, f32_to_f16, q16, storage_image_with, uploaded_state};
use glam::{Vec2, Vec3, Vec4};
use shine::graph::{Executor, ExternalState, History, RenderGraph, vk};
use shine::passes::accumulate::{AccumulateHistory, AccumulateParams, accumulate};
use shine::passes::gbuffer::GBuffer;
use shine::reference::accumulate::{AccumulateInputs, Accumulated, accumulate_cpu};
use shine::{FrameUpdate, Renderer, Settings};
use shine_scene::{Light, Scene};

/// Runs `accumulate` on the GPU over `inp` (as uploaded: f16 values where the images are f16)
/// and returns the accumulated light and the filter state.
fn accumulate_gpu(
    device: &shine::gpu::Device,
    inp: &AccumulateInputs<'_>,
    params: &AccumulateParams,
) -> Accumulated {
    let [w, h] = inp.extent;
    let rgba16 = vk::Format::R16G16B16A16_SFLOAT;
    let rgba32 = vk::Format::R32G32B32A32_SFLOAT;
    let current: Vec<Vec4> = inp.current.iter().map(|c| c.extend(0.0)).collect();
    let current = storage_image_with(device, "current", rgba16, inp.extent, &bytes_f16(&current));
    let position = storage_image_with(
        device,
        "gb_position",
        rgba32,
        inp.extent,
        bytemuck::cast_slice(inp.position),
    );
    let normals: Vec<Vec4> = inp.normal.iter().map(|n| n.extend(0.0)).collect();
    let normal = storage_image_with(
        device,
        "gb_normal",
        rgba16,
        inp.extent,
        &bytes_f16(&normals),
    );
    let motion = common::motion_image(device, inp.extent, inp.motion);
    let geometry = storage_image_with(
        device,
        "history geometry",
        rgba32,
        inp.extent,
        bytemuck::cast_slice(inp.history_geometry),
    );
    let light = storage_image_with(
        device,
        "history light",
        rgba16,
        inp.extent,
        &bytes_f16(inp.history_light),
    );
    let state = storage_image_with(
        device,
        "history state",
        rgba16,
        inp.extent,
        &bytes_f16(inp.history_state),
    );
    let out = common::transfer_storage(device, "out", u64::from(w * h) * 8, None);
    let out_state = common::transfer_storage(device, "out state", u64::from(w * h) * 8, None);
    let mut executor = Executor::new(device, 1).expect("executor");
    let mut rg = executor.begin_frame();
    let import = |rg: &mut RenderGraph, image| {
        rg.import_gpu_image(image, uploaded_state(), ExternalState::UNDEFINED)
    };
    let g = GBuffer {
        position: import(&mut rg, &position),
        normal: import(&mut rg, &normal),
        albedo: import(&mut rg, &current),
        material: import(&mut rg, &current),
        emissive: import(&mut rg, &current),
        geometric_normal: import(&mut rg, &normal),
        motion: import(&mut rg, &motion),
        depth: import(&mut rg, &position),
        extent: inp.extent,
    };
    let current_handle = import(&mut rg, &current);
    let geometry_handle = import(&mut rg, &geometry);
    let mut history = AccumulateHistory {
        light: History {
            previous: import(&mut rg, &light),
            current: rg.create_image("accumulated", shine::graph::ImageDesc::new_2d(rgba16, w, h)),
        },
        state: History {
            previous: import(&mut rg, &state),
            current: rg.create_image("state", shine::graph::ImageDesc::new_2d(rgba16, w, h)),
        },
    };
    let accumulated = accumulate(
        &mut rg,
        "accumulate",
        &current_handle,
        &g,
        &geometry_handle,
        &mut history,
        params,
        inp.has_history,
    )
    .expect("accumulate");
    let mut out_handle =
        rg.import_gpu_buffer(&out, ExternalState::UNDEFINED, common::read_by_copy());
    rg.copy_image_to_buffer("read accumulated", &accumulated, &mut out_handle);
    let mut state_handle =
        rg.import_gpu_buffer(&out_state, ExternalState::UNDEFINED, common::read_by_copy());
    rg.copy_image_to_buffer("read state", &history.state.current, &mut state_handle);
    common::run_graph(device, &mut executor, rg);
    Accumulated {
        light: common::decode_rgba16f(&device.read_buffer(&out).expect("read")),
        state: common::decode_rgba16f(&device.read_buffer(&out_state).expect("read state")),
    }
}

/// The GPU pass equals its CPU twin with history kept, moved between texels (bilinear), partly
/// and wholly rejected (other depth or normal, off screen), clipped and not, without history,
/// and in TAA's mode (blend space, background, still and moving pixels).
#[test]
fn accumulate_matches_the_cpu_twin() {
    let device = common::device();
    let extent = [13u32, 11];
    let n = (extent[0] * extent[1]) as usize;
    let mut rng = Rng(77);
    let mut position = Vec::new();
    let mut normal = Vec::new();
    for _ in 0..n {
        let background = rng.next() < 0.1;
        let depth = 1.0 + 4.0 * rng.next();
        position.push(Vec4::new(
            0.0,
            0.0,
            0.0,
            if background { 0.0 } else { depth },
        ));
        normal.push(
            q16(Vec3::new(rng.next() - 0.5, rng.next() - 0.5, 1.0)
                .normalize()
                .extend(0.0))
            .truncate(),
        );
    }
    let current: Vec<Vec3> = (0..n)
        .map(|_| q16(Vec4::new(rng.next(), rng.next(), rng.next(), 0.0)).truncate())
        .collect();
    let history_light: Vec<Vec4> = (0..n)
        .map(|_| {
            q16(Vec4::new(
                2.0 * rng.next(),
                rng.next(),
                rng.next(),
                (8.0 * rng.next()).floor(),
            ))
        })
        .collect();
    // Filter state: a trend of either sign and an innovations' variance.
    let history_state: Vec<Vec4> = (0..n)
        .map(|_| {
            q16(Vec4::new(
                0.2 * (rng.next() - 0.5),
                0.2 * (rng.next() - 0.5),
                0.2 * (rng.next() - 0.5),
                0.05 * rng.next(),
            ))
        })
        .collect();
    // History geometry: mostly the pixel's own, sometimes another depth or normal.
    let history_geometry: Vec<Vec4> = (0..n)
        .map(|i| {
            let r = rng.next();
            let (nn, d) = (normal[i], position[i].w);
            if r < 0.7 {
                nn.extend(d)
            } else if r < 0.85 {
                nn.extend(d * 1.5)
            } else {
                (-nn).extend(d)
            }
        })
        .collect();
    // Motion: none, sub-texel, or several texels (some off screen).
    let motion: Vec<Vec2> = (0..n)
        .map(|_| match rng.next() {
            r if r < 0.3 => Vec2::ZERO,
            r if r < 0.7 => (Vec2::new(rng.next(), rng.next()) - 0.5) * 0.15,
            _ => (Vec2::new(rng.next(), rng.next()) - 0.5) * 0.8,
        })
        .map(|m| Vec2::new(f16_to_f32(f32_to_f16(m.x)), f16_to_f32(f32_to_f16(m.y))))
        .collect();
    let mut restarted = 0;
    let still = vec![Vec2::ZERO; n];
    for (has_history, max_frames, clip, geometry, moving, trend, temporal) in [
        (true, 8, 1.0, true, true, 0.0, false),
        (true, 8, 3.0, true, true, 0.1, true),
        (true, 8, 1.0, true, false, 0.5, true),
        (true, 4, 0.0, true, true, 0.1, false),
        (false, 8, 1.0, true, true, 0.1, true),
        (true, 16, 1.0, false, true, 0.0, false),
        (true, 16, 1.0, false, false, 0.0, false),
    ] {
        let inputs = AccumulateInputs {
            extent,
            current: &current,
            position: &position,
            normal: &normal,
            motion: if moving { &motion } else { &still },
            history_geometry: &history_geometry,
            history_light: &history_light,
            history_state: &history_state,
            has_history,
        };
        let params = AccumulateParams {
            max_frames,
            clip,
            geometry,
            reseed: false,
            trend,
            temporal,
            ..AccumulateParams::default()
        };
        let cpu = accumulate_cpu(&inputs, &params);
        let gpu = accumulate_gpu(&device, &inputs, &params);
        let case = format!(
            "history {has_history}, n {max_frames}, clip {clip}, geometry {geometry}, trend {trend}, temporal {temporal}"
        );
        for (i, (c, g)) in cpu.light.iter().zip(&gpu.light).enumerate() {
            assert!(
                (*c - *g).abs().max_element() <= 4e-3 * c.abs().max_element().max(1.0),
                "{case}, pixel {i}: cpu {c} gpu {g}"
            );
            restarted += usize::from(position[i].w > 0.0 && c.w == 1.0);
        }
        for (i, (c, g)) in cpu.state.iter().zip(&gpu.state).enumerate() {
            assert!(
                (*c - *g).abs().max_element() <= 4e-3 * c.abs().max_element().max(0.1),
                "{case}, pixel {i}: state cpu {c} gpu {g}"
            );
        }
        if geometry && has_history && trend > 0.0 {
            assert!(
                cpu.state.iter().any(|s| s.truncate() != Vec3::ZERO),
                "{case}: no trend carried"
            );
        }
    }
    assert!(restarted > n, "restarted {restarted}");
    common::assert_clean(&device);
}

/// A pixel whose history shows another surface (depth 1.5× or a flipped normal) restarts from
/// this frame's light; one that shows its surface blends it in.
#[test]
fn disocclusion_rejects_history() {
    let device = common::device();
    let extent = [2u32, 2];
    let position = vec![Vec4::new(0.0, 0.0, 0.0, 2.0); 4];
    let normal = vec![Vec3::Z; 4];
    let current = vec![Vec3::new(1.0, 0.5, 0.25); 4];
    let history_light = vec![Vec4::new(0.0, 0.0, 8.0, 4.0); 4];
    let motion = vec![Vec2::ZERO; 4];
    let params = AccumulateParams {
        max_frames: 8,
        clip: 0.0,
        geometry: true,
        ..AccumulateParams::default()
    };
    let history_state = vec![Vec4::ZERO; 4];
    for (geometry, keeps) in [
        (Vec4::new(0.0, 0.0, 1.0, 2.0), true),
        (Vec4::new(0.0, 0.0, 1.0, 3.0), false),
        (Vec4::new(0.0, 0.0, -1.0, 2.0), false),
    ] {
        let history_geometry = vec![geometry; 4];
        let inputs = AccumulateInputs {
            extent,
            current: &current,
            position: &position,
            normal: &normal,
            motion: &motion,
            history_geometry: &history_geometry,
            history_light: &history_light,
            history_state: &history_state,
            has_history: true,
        };
        let gpu = accumulate_gpu(&device, &inputs, &params).light;
        let expected = if keeps {
            // n = 5: a fifth of this frame's light into the history.
            Vec4::new(0.2, 0.1, 6.45, 5.0)
        } else {
            current[0].extend(1.0)
        };
        for g in &gpu {
            assert!(
                (*g - expected).abs().max_element() <= 4e-3,
                "history geometry {geometry}: {g} against {expected}"
            );
        }
    }
    common::assert_clean(&device);
}

/// A history the clip moves by more than `ACCUMULATE_CHANGE` of its luminance restarts (a
/// light switched off is gone at once); one it moves by less keeps counting, and TAA never
/// restarts this way.
#[test]
fn a_large_change_of_the_light_restarts_the_history() {
    use shine::passes::accumulate::ACCUMULATE_CHANGE;
    let device = common::device();
    let extent = [3u32, 3];
    let position = vec![Vec4::new(0.0, 0.0, 0.0, 2.0); 9];
    let normal = vec![Vec3::Z; 9];
    let current = vec![Vec3::splat(1.0); 9];
    let history_geometry = vec![Vec4::new(0.0, 0.0, 1.0, 2.0); 9];
    let motion = vec![Vec2::ZERO; 9];
    let history_state = vec![Vec4::ZERO; 9];
    // A flat neighbourhood: the clip box is the light itself, so the clip moves a history of
    // 1 + e by e.
    for (excess, geometry, restarts) in [
        (3.0, true, true),
        (1.5 * ACCUMULATE_CHANGE, true, true),
        (0.5 * ACCUMULATE_CHANGE, true, false),
        (3.0, false, false),
    ] {
        let history_light = vec![Vec4::new(1.0 + excess, 1.0 + excess, 1.0 + excess, 4.0); 9];
        let inputs = AccumulateInputs {
            extent,
            current: &current,
            position: &position,
            normal: &normal,
            motion: &motion,
            history_geometry: &history_geometry,
            history_light: &history_light,
            history_state: &history_state,
            has_history: true,
        };
        let params = AccumulateParams {
            max_frames: 8,
            clip: 3.0,
            geometry,
            ..AccumulateParams::default()
        };
        let gpu = accumulate_gpu(&device, &inputs, &params);
        let cpu = accumulate_cpu(&inputs, &params);
        let count = if restarts { 1.0 } else { 5.0 };
        for (g, c) in gpu.light.iter().zip(&cpu.light) {
            assert!((*g - *c).abs().max_element() <= 4e-3, "{g} against {c}");
            assert_eq!(g.w, count, "excess {excess}, geometry {geometry}: {g}");
        }
    }
    common::assert_clean(&device);
}

/// A static scene accumulated over frames renders its single frame (every frame's light is
/// the same, so the blend changes nothing), for HVL and IGI. HVL's sampled shadows and near
/// field draw new rays every frame of a history, so HVL runs without them here (the shadows'
/// mean over seeds is `tests/hvl.rs`'s).
#[test]
fn a_static_scene_accumulated_converges_to_the_single_frame() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    for gi in ["hvl", "igi"] {
        let frame = |history: &str, frames: u32| {
            let mut s = Settings {
                width: 32,
                height: 32,
                ..Settings::default()
            };
            s.set("gi", gi).expect("gi");
            s.set("shadow.size", "128").expect("shadow");
            s.set("history.frames", history).expect("history");
            s.set("hvl.visibility", "false").expect("visibility");
            s.set("hvl.near_range", "0").expect("near field");
            let mut renderer = Renderer::new(&device).expect("renderer");
            renderer.set_scene(&scene, 0.0).expect("scene");
            let mut last = None;
            for _ in 0..frames {
                last = Some(renderer.render(&s).expect("render"));
            }
            last.expect("a frame").hdr
        };
        let single = frame("1", 1);
        let accumulated = frame("8", 5);
        let e = common::relative_rmse(&accumulated, &single);
        assert!(e <= 2e-3, "{gi}: relative RMSE {e}");
    }
    common::assert_clean(&device);
}

/// A light switched off through the frame update is gone from the next frame: the light cut
/// (`LIGHT_CUT_RATIO` in src/frame/renderer/light_cut.rs) restarts the indirect light's
/// histories. `builtin:motion-sweep` (a spot and a second light): after 4 frames the spot is
/// switched off; what the next frame keeps of the spot's light is its mean minus a cold
/// render's with the spot off, over the spot's share (lit minus off). Without the cut the
/// pixels the other light keeps lit pass the history's clip and keep a share for frames (IGI
/// 7.5 % in the first frame, 5 frames to fall below 5 %: docs/quality.md, issue 43).
#[test]
fn a_light_switched_off_is_gone_the_next_frame() {
    let device = common::device();
    let scene = Scene::builtin("motion-sweep").expect("scene");
    let lights = scene.lights_at(&scene.world_transforms_at(0.0));
    let off = FrameUpdate {
        lights: vec![(
            0,
            Light {
                intensity: 0.0,
                ..lights[0]
            },
        )],
        ..FrameUpdate::default()
    };
    let mean = |image: &shine::capture::image_io::HdrImage| {
        image
            .texels
            .iter()
            .map(|t| f64::from(t[0] + t[1] + t[2]))
            .sum::<f64>()
    };
    for gi in ["hvl", "igi"] {
        let mut s = Settings {
            width: 32,
            height: 32,
            ..Settings::default()
        };
        s.set("gi", gi).expect("gi");
        s.set("output.component", "indirect").expect("component");
        let mut renderer = Renderer::new(&device).expect("renderer");
        renderer.set_scene(&scene, 0.0).expect("scene");
        let mut lit = 0.0;
        for _ in 0..4 {
            lit = mean(&renderer.render(&s).expect("render").hdr);
        }
        renderer.update(&off).expect("switch off");
        let after = mean(&renderer.render(&s).expect("render").hdr);
        let mut cold = Renderer::new(&device).expect("renderer");
        cold.set_scene(&scene, 0.0).expect("scene");
        cold.update(&off).expect("switch off");
        let dark = mean(&cold.render(&s).expect("render").hdr);
        let left = (after - dark) / (lit - dark);
        println!(
            "{gi}: {:.2} % of the spot's light left one frame after the switch",
            left * 100.0
        );
        assert!(
            lit > dark * 1.5,
            "{gi}: the spot lights little ({lit} vs {dark})"
        );
        assert!(left.abs() < 0.05, "{gi}: {left} of the light left");
    }
    common::assert_clean(&device);
}

/// Smooth light that pops as a whole while it brightens steadily (issue 43): every pixel of a
/// flat 8×8 wall is a ramp times one common factor per frame, plus a little noise of its own.
/// The 3×3 clip alone sees only the small per-pixel σ and keeps the pops; the temporal clip
/// keeps the history that averages them, and the trend follows the ramp that a plain history
/// trails by n − 1 frames of its change. CPU twin (tied to the pass by
/// `accumulate_matches_the_cpu_twin`), 48 frames, the last 32 measured.
#[test]
fn the_trend_and_temporal_clip_hold_a_popping_ramp_still_without_lag() {
    let extent = [8u32, 8];
    let n = 64;
    let position = vec![Vec4::new(0.0, 0.0, 0.0, 2.0); n];
    let normal = vec![Vec3::Z; n];
    let history_geometry = vec![Vec4::new(0.0, 0.0, 1.0, 2.0); n];
    let motion = vec![Vec2::ZERO; n];
    let ramp = |k: usize| 1.0 + 0.02 * k as f32;
    let mut rng = Rng(5);
    let frames: Vec<Vec<Vec3>> = (0..48)
        .map(|k| {
            let pop = 1.0 + 0.1 * (rng.next() - 0.5);
            (0..n)
                .map(|_| Vec3::splat(ramp(k) * pop * (1.0 + 0.01 * (rng.next() - 0.5))))
                .collect()
        })
        .collect();
    // (flicker: RMS of the second difference over the mean, lag: mean |out − ramp| over the
    // mean) of the centre pixel over the measured frames.
    let run = |params: &AccumulateParams| {
        let mut light = vec![Vec4::ZERO; n];
        let mut state = vec![Vec4::ZERO; n];
        let mut out = Vec::new();
        for (k, current) in frames.iter().enumerate() {
            let inputs = AccumulateInputs {
                extent,
                current,
                position: &position,
                normal: &normal,
                motion: &motion,
                history_geometry: &history_geometry,
                history_light: &light,
                history_state: &state,
                has_history: k > 0,
            };
            let next = accumulate_cpu(&inputs, params);
            out.push(next.light[27].x);
            (light, state) = (next.light, next.state);
        }
        let measured = &out[16..];
        let mean = measured.iter().sum::<f32>() / measured.len() as f32;
        let d2: Vec<f32> = measured
            .windows(3)
            .map(|w| w[0] - 2.0 * w[1] + w[2])
            .collect();
        let flicker = (d2.iter().map(|d| d * d).sum::<f32>() / d2.len() as f32).sqrt() / mean;
        let lag = (16..48).map(|k| (out[k] - ramp(k)).abs()).sum::<f32>() / 32.0 / mean;
        (flicker, lag)
    };
    let base = AccumulateParams::default();
    let spatial = run(&AccumulateParams {
        trend: 0.0,
        temporal: false,
        ..base
    });
    let plain = run(&AccumulateParams { trend: 0.0, ..base });
    let default = run(&base);
    eprintln!("spatial clip {spatial:?}, temporal without trend {plain:?}, default {default:?}");
    assert!(
        default.0 < 0.5 * spatial.0,
        "flicker {default:?} against the spatial clip's {spatial:?}"
    );
    assert!(
        default.1 < 0.5 * plain.1,
        "lag {default:?} against the plain history's {plain:?}"
    );
    assert!(default.1 < 0.02, "lag {default:?}");
}
