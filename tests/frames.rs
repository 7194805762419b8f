//! Frames that move (issue 15): the update path (one upload, then `Renderer::update` per
//! frame) against cold starts, the `update vertices` pass against its CPU twin, and device
//! memory over a long run.

mod common;

use glam::{Mat4, Vec3};
use shine::gpu::vk;
use shine::gpu_scene::{FrameUpdate, GpuScene, Vertex};
use shine::graph::{Executor, ExternalState};
use shine::reference::{PathTracer, ReferenceParams};
use shine::{Renderer, Settings};
use shine_scene::Scene;

/// A small frame with `gi` (and nothing else changed from the defaults).
fn settings(gi: &str) -> Settings {
    let mut s = Settings {
        width: 32,
        height: 32,
        ..Settings::default()
    };
    s.set("gi", gi).expect("gi");
    s.set("shadow.size", "128").expect("shadow size");
    // No history: a sequence's frame then owes nothing to the frames before it, which is what
    // these tests compare (tests/accumulate.rs covers the history).
    s.set("history.frames", "1").expect("history");
    s
}

/// Frame k of a sequence (scene uploaded once, then updated) equals a cold render of the scene
/// at the same time, in every GI mode, within 1e-4 of the mean (`builtin:animated`: skinning,
/// morphing, a moving spot light, sky through a window).
#[test]
fn sequence_frames_equal_cold_renders() {
    let device = common::device();
    let scene = Scene::builtin("spheres").expect("scene");
    let times = [0.0, 1.1];
    let mut live = Renderer::new(&device).expect("renderer");
    let mut cold = Renderer::new(&device).expect("renderer");
    for gi in [
        "none",
        "hvl",
        "igi",
        "proxy",
        "aaf",
        "hvl,proxy",
        "igi,proxy",
    ] {
        let settings = settings(gi);
        live.set_scene(&scene, times[0]).expect("scene");
        for &t in &times {
            live.update(&FrameUpdate::at(t)).expect("update");
            let frame = live.render(&settings).expect("render");
            cold.set_scene(&scene, t).expect("scene");
            let expected = cold.render(&settings).expect("render");
            let e = common::relative_rmse(&frame.hdr, &expected.hdr);
            assert!(e <= 1e-4, "gi {gi}, t {t}: relative RMSE {e:e}");
        }
    }
    // The frames differ from each other: the scene does move.
    live.set_scene(&scene, 0.0).expect("scene");
    let first = live.render(&settings("proxy")).expect("render");
    live.update(&FrameUpdate::at(1.1)).expect("update");
    let later = live.render(&settings("proxy")).expect("render");
    let moved = common::relative_rmse(&later.hdr, &first.hdr);
    assert!(moved > 1e-2, "nothing moved: {moved:e}");
    common::assert_clean(&device);
}

/// The path tracer moved to another instant by an update matches one started cold there
/// (the skinned walker's refitted bottom level against one built at that instant).
#[test]
fn path_tracer_update_matches_cold_start() {
    let device = common::device();
    let scene = Scene::builtin("animated").expect("scene");
    let params = ReferenceParams {
        width: 24,
        height: 24,
        ..ReferenceParams::default()
    };
    let mut moved = PathTracer::new(&device, &scene, 0.0, &params).expect("tracer");
    moved.accumulate(2).expect("accumulate");
    moved.update(&FrameUpdate::at(0.9)).expect("update");
    moved.accumulate(4).expect("accumulate");
    let mut cold = PathTracer::new(&device, &scene, 0.9, &params).expect("tracer");
    cold.accumulate(4).expect("accumulate");
    let (a, b) = (moved.read().expect("read"), cold.read().expect("read"));
    assert_eq!(a.samples, 4);
    let e = common::relative_rmse(&a.full, &b.full);
    assert!(e <= 1e-4, "relative RMSE {e:e}");
    common::assert_clean(&device);
}

/// `update vertices` writes what the CPU reference computes
/// (`shine_scene::Scene::instance_vertices`: morph, then skin or rigid placement) for every
/// vertex of `builtin:animated` (a skinned walker, a morphing curtain, rigid furniture) at
/// several instants.
#[test]
fn update_vertices_matches_the_cpu() {
    let device = common::device();
    let scene = Scene::builtin("animated").expect("scene");
    let mut gpu = GpuScene::upload(&device, &scene, 0.0).expect("upload");
    let mut executor = Executor::new(&device, 1).expect("executor");
    let readback = common::buffer(
        &device,
        "vertices readback",
        gpu.vertices.size(),
        vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
    );
    let (mut skinned, mut morphed) = (0usize, 0usize);
    for t in [0.0, 1.3, 7.9] {
        gpu.update(&FrameUpdate::at(t)).expect("update");
        let mut rg = executor.begin_frame();
        let handles = gpu.declare(&mut rg).expect("declare");
        let mut out =
            rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, common::read_by_copy());
        rg.copy_buffer("read vertices", &handles.vertices, &mut out);
        common::run_graph(&device, &mut executor, rg);
        let bytes = device.read_buffer(&readback).expect("read");
        let got: &[Vertex] = bytemuck::cast_slice(&bytes);
        let pose = &gpu.state.pose;
        let placed = scene.instances(&pose.world);
        for (range, instance) in gpu.instances.iter().zip(&placed) {
            let mesh = &scene.meshes[range.mesh as usize];
            let mut v = range.first_vertex as usize;
            for p in 0..mesh.primitives.len() {
                let cpu = scene.instance_vertices(pose, instance, p).expect("cpu");
                for (i, position) in cpu.positions.iter().enumerate() {
                    let g = &got[v];
                    let tolerance = 1e-5 * (1.0 + position.abs().max_element());
                    assert!(
                        (Vec3::from(g.position) - *position).abs().max_element() <= tolerance,
                        "t {t}, instance node {}, vertex {i}: {:?} vs {position}",
                        range.node,
                        g.position
                    );
                    assert!(
                        (Vec3::from(g.normal) - cpu.normals[i]).abs().max_element() <= 1e-4,
                        "t {t}, node {}, vertex {i}: normal {:?} vs {}",
                        range.node,
                        g.normal,
                        cpu.normals[i]
                    );
                    let tangent = glam::Vec4::from(g.tangent);
                    assert!(
                        (tangent - cpu.tangents[i]).abs().max_element() <= 1e-4,
                        "t {t}, node {}, vertex {i}: tangent",
                        range.node
                    );
                    v += 1;
                }
            }
            if range.skin != shine_scene::NO_SKIN {
                skinned += range.vertex_count as usize;
            }
            if range.target_count > 0 {
                morphed += range.vertex_count as usize;
            }
        }
    }
    assert!(
        skinned > 0 && morphed > 0,
        "skinned {skinned}, morphed {morphed}"
    );
    common::assert_clean(&device);
}

/// Device memory stays flat over a long animated run, and the validation layer stays silent.
#[test]
fn a_long_run_keeps_device_memory_flat() {
    let device = common::device();
    let scene = Scene::builtin("animated").expect("scene");
    let settings = {
        let mut s = settings("hvl,proxy");
        s.width = 16;
        s.height = 16;
        s
    };
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("scene");
    let mut at = Vec::new();
    for k in 0..300u32 {
        renderer
            .update(&FrameUpdate::at(k as f32 / 30.0))
            .expect("update");
        renderer.render(&settings).expect("render");
        if k == 9 || k == 299 {
            at.push(device.memory_usage());
        }
    }
    println!("device memory at frames 10 and 300: {at:?}");
    assert_eq!(at[0].allocated_bytes, at[1].allocated_bytes, "{at:?}");
    assert_eq!(at[0].allocations, at[1].allocations, "{at:?}");
    common::assert_clean(&device);
}

/// A bad update is refused with a clear message and changes nothing.
#[test]
fn bad_updates_are_refused() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("scene");
    let before = renderer.render(&settings("none")).expect("render");
    let bad = [
        (FrameUpdate::at(f32::NAN), "not finite"),
        (
            FrameUpdate {
                nodes: vec![(9999, shine_scene::Transform::default())],
                ..FrameUpdate::default()
            },
            "node 9999 does not exist",
        ),
        (
            FrameUpdate {
                lights: vec![(77, scene.lights[0])],
                ..FrameUpdate::default()
            },
            "light 77 does not exist",
        ),
        (
            FrameUpdate {
                lights: vec![(
                    0,
                    shine_scene::Light {
                        kind: 1 - scene.lights[0].kind.min(1),
                        ..scene.lights[0]
                    },
                )],
                ..FrameUpdate::default()
            },
            "its kind cannot change",
        ),
        (
            FrameUpdate {
                nodes: vec![(
                    0,
                    shine_scene::Transform {
                        scale: Vec3::new(1.0, 0.0, 1.0),
                        ..Default::default()
                    },
                )],
                ..FrameUpdate::default()
            },
            "zero scale",
        ),
        (
            FrameUpdate {
                camera: Some(shine::CameraPose {
                    world: Mat4::IDENTITY,
                    projection: shine_scene::Projection::Perspective {
                        yfov: 0.8,
                        aspect_ratio: None,
                        znear: 0.0,
                        zfar: None,
                    },
                }),
                ..FrameUpdate::default()
            },
            "projection",
        ),
    ];
    for (update, message) in bad {
        let err = renderer.update(&update).expect_err("refused").to_string();
        assert!(err.contains(message), "{err}");
    }
    let after = renderer.render(&settings("none")).expect("render");
    assert_eq!(after.hdr, before.hdr);
    common::assert_clean(&device);
}

/// Runs the frame graph `rg` and reads `images` (one mip and layer, of the given byte sizes)
/// back.
fn run_and_read(
    device: &shine::gpu::Device,
    executor: &mut Executor,
    mut rg: shine::graph::RenderGraph,
    images: &[(&shine::graph::Handle<shine::graph::Image>, u64)],
) -> Vec<Vec<u8>> {
    let buffers: Vec<_> = images
        .iter()
        .map(|(_, bytes)| {
            common::buffer(
                device,
                "readback",
                *bytes,
                vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
            )
        })
        .collect();
    for (i, ((image, _), buffer)) in images.iter().zip(&buffers).enumerate() {
        let mut out =
            rg.import_gpu_buffer(buffer, ExternalState::UNDEFINED, common::read_by_copy());
        rg.copy_image_to_buffer(&format!("read back {i}"), image, &mut out);
    }
    common::run_graph(device, executor, rg);
    buffers
        .iter()
        .map(|b| device.read_buffer(b).expect("read"))
        .collect()
}

/// The G-buffer's motion vectors: on a scene's first frame zero; after the whole scene moved
/// by `d` and the camera moved and jittered, every surface pixel holds where its point is now
/// minus where it was (`p - d` seen by the previous, unjittered camera), in texture
/// coordinates.
#[test]
fn motion_vectors_follow_the_scene_and_the_camera() {
    use shine::frame::motion::MotionState;
    use shine::passes::gbuffer;
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut gpu = GpuScene::upload(&device, &scene, 0.0).expect("upload");
    let mut motion = MotionState::new(&device).expect("motion");
    let mut executor = Executor::new(&device, 1).expect("executor");
    let sampler =
        shine::gpu::Sampler::new(&device, &vk::SamplerCreateInfo::default()).expect("sampler");
    let extent = [32u32, 32];
    let pixels = (extent[0] * extent[1]) as usize;
    let mut frame = |gpu: &mut GpuScene, motion: &mut MotionState| {
        let mut rg = executor.begin_frame();
        let handles = gpu.declare(&mut rg).expect("declare");
        let camera = gbuffer::camera_view(&gpu.state, extent[0], extent[1]);
        let unjittered = gbuffer::unjittered_camera_view(&gpu.state, extent[0], extent[1]);
        let view = motion
            .declare(&mut rg, unjittered.view_proj(), extent)
            .expect("motion view");
        let g = gbuffer::gbuffer(&mut rg, &handles, &camera, &view, extent, sampler.raw());
        let out = run_and_read(
            &device,
            &mut executor,
            rg,
            &[
                (&g.position, pixels as u64 * 16),
                (&g.motion, pixels as u64 * 4),
            ],
        );
        let position: Vec<[f32; 4]> = bytemuck::cast_slice(&out[0]).to_vec();
        let halves: &[u16] = bytemuck::cast_slice(&out[1]);
        let motion: Vec<[f32; 2]> = halves
            .chunks_exact(2)
            .map(|h| [common::f16_to_f32(h[0]), common::f16_to_f32(h[1])])
            .collect();
        (position, motion, unjittered.view_proj())
    };
    let (_, first, previous) = frame(&mut gpu, &mut motion);
    assert!(
        first.iter().all(|m| m == &[0.0, 0.0]),
        "motion on the first frame"
    );

    let d = Vec3::new(0.04, -0.03, 0.05);
    let nodes = gpu
        .instances
        .iter()
        .map(|r| {
            let mut t = scene.nodes[r.node as usize].transform;
            t.translation += d;
            (r.node as usize, t)
        })
        .collect();
    let camera = shine::CameraPose {
        world: Mat4::from_translation(Vec3::new(0.03, 0.02, -0.05))
            * Mat4::from_rotation_y(0.02)
            * gpu.state.camera_world,
        projection: gpu.state.projection,
    };
    gpu.update(&FrameUpdate {
        nodes,
        camera: Some(camera),
        jitter: [0.3, -0.2],
        ..FrameUpdate::default()
    })
    .expect("update");
    let (position, got, current) = frame(&mut gpu, &mut motion);
    let uv = |m: &Mat4, p: Vec3| {
        let c = *m * p.extend(1.0);
        glam::Vec2::new(c.x / c.w, c.y / c.w) * 0.5
    };
    let mut checked = 0;
    for (p, m) in position.iter().zip(&got) {
        if p[3] <= 0.0 {
            continue;
        }
        let p = Vec3::new(p[0], p[1], p[2]);
        let expected = uv(&current, p) - uv(&previous, p - d);
        let m = glam::Vec2::from(*m);
        assert!(
            (m - expected).abs().max_element() <= 2e-3 + 1e-2 * expected.abs().max_element(),
            "motion {m} vs {expected}"
        );
        checked += 1;
    }
    assert!(checked > pixels / 2, "only {checked} surface pixels");
    common::assert_clean(&device);
}
