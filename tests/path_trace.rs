//! The reference path tracer (src/reference/mod.rs, shaders/path_trace.comp) against closed-form
//! answers, and its BVH traversal (shaders/include/trace.glsl) against the CPU BVH.

mod common;

use glam::{Mat4, Quat, Vec3};
use shine::capture::image_compare::rmse;
use shine::gpu::vk;
use shine::gpu_scene::bvh::world_bvh;
use shine::gpu_scene::{FrameUpdate, GpuScene};
use shine::graph::{Executor, ExternalState};
use shine::reference::{PathTracer, ReferenceImages, ReferenceParams, render_reference};
use shine_scene::bvh::Ray;
use shine_scene::environment::Environment;
use shine_scene::{Light, Material, Scene, Transform};

/// A scene of one mesh (flat-shaded triangles) with one material, a camera and `lights`.
fn one_mesh_scene(
    triangles: &[[Vec3; 3]],
    material: Material,
    camera: Mat4,
    lights: Vec<Light>,
    environment: Option<Environment>,
) -> Scene {
    common::scenes::mesh_scene(
        &[(triangles.to_vec(), material)],
        camera,
        lights,
        environment,
    )
}

/// A UV sphere of radius `r` at the origin.
fn sphere(r: f32, outward: bool) -> Vec<[Vec3; 3]> {
    common::scenes::sphere(Vec3::ZERO, r, outward)
}

fn lambert(albedo: f32, emissive: f32) -> Material {
    Material {
        base_color: [albedo, albedo, albedo, 1.0],
        emissive: [emissive; 3],
        metallic: 0.0,
        double_sided: 1,
        ..Material::default()
    }
}

/// Lambertian paths through pixel centres, lights found by BRDF sampling alone: every sample
/// of the closed-form scenes below is then exact.
fn params(size: u32, bounces: u32) -> ReferenceParams {
    ReferenceParams {
        width: size,
        height: size,
        bounces,
        jitter: false,
        emissive_lighting: true,
        lambert_only: true,
        light_sampling: false,
        seed: 0,
        primary_specular: None,
    }
}

/// Asserts that the mean `on` of a light-sampled image and `off` of one without agree within
/// `tolerance` (relative).
fn assert_same_mean(what: &str, on: f64, off: f64, tolerance: f64) {
    assert!(
        (on / off - 1.0).abs() < tolerance,
        "{what}: mean {on} with light sampling, {off} without"
    );
}

/// Asserts that `spp` samples (seed `seed`) of `run(light_sampling, spp, seed)` are at least
/// twice as close to `truth` with light sampling as without.
fn assert_light_sampling_halves_the_error(
    run: impl Fn(bool, u32, u32) -> ReferenceImages,
    spp: u32,
    seed: u32,
    truth: &ReferenceImages,
) {
    let (on, off) = (run(true, spp, seed), run(false, spp, seed));
    let (e_on, e_off) = (
        rmse(&on.full, &truth.full).expect("rmse"),
        rmse(&off.full, &truth.full).expect("rmse"),
    );
    assert!(
        e_on < 0.5 * e_off,
        "{spp}-spp RMSE {e_on} with light sampling, {e_off} without"
    );
}

/// Mean of the red channel over the texels `keep` selects (by their index).
fn mean_red(image: &shine::capture::image_io::HdrImage, keep: impl Fn(usize) -> bool) -> f64 {
    let picked: Vec<f64> = image
        .texels
        .iter()
        .enumerate()
        .filter(|(i, _)| keep(*i))
        .map(|(_, t)| f64::from(t[0]))
        .collect();
    picked.iter().sum::<f64>() / picked.len().max(1) as f64
}

fn assert_all(
    image: &shine::capture::image_io::HdrImage,
    expected: f32,
    tolerance: f32,
    what: &str,
) {
    for (i, t) in image.texels.iter().enumerate() {
        for c in &t[..3] {
            assert!(
                (c - expected).abs() <= tolerance * expected.max(1e-3),
                "{what}: pixel {i} = {t:?}, expected {expected}"
            );
        }
    }
}

/// White furnace: inside a closed sphere of Lambertian albedo a emitting L_e, a path that
/// scatters k times carries a^k L_e, so with B bounces the camera sees L_e Σ_{k=0}^{B+1} a^k:
/// direct L_e (1 + a), indirect L_e Σ_{k=2}^{B+1} a^k. Every sample of every pixel gives that
/// exactly (cosine sampling of a Lambertian: weight a; every ray hits the emitter), so the
/// Monte-Carlo standard error is 0 and the tolerance only covers float rounding.
#[test]
fn white_furnace_inside_a_closed_sphere() {
    let device = common::device();
    let (a, le) = (0.6f32, 0.5f32);
    let scene = one_mesh_scene(
        &sphere(1.0, false),
        lambert(a, le),
        Mat4::IDENTITY,
        vec![],
        None,
    );
    for bounces in [0u32, 1, 3] {
        let images =
            render_reference(&device, &scene, 0.0, &params(16, bounces), 4).expect("reference");
        let series = |from: u32| (from..=bounces + 1).map(|k| a.powi(k as i32)).sum::<f32>();
        assert_all(&images.direct, le * (1.0 + a), 1e-3, "direct");
        if bounces > 0 {
            assert_all(&images.indirect, le * series(2), 1e-3, "indirect");
        }
        assert_all(
            &images.full,
            le * series(0),
            1e-3,
            &format!("full, {bounces} bounces"),
        );
    }
    common::assert_clean(&device);
}

/// An outward sphere of albedo a under a uniform environment L: the camera sees L around it
/// and a·L on it (every reflected ray escapes a convex object), all direct light.
#[test]
fn uniform_environment_on_a_convex_sphere() {
    let device = common::device();
    let (a, l) = (0.5f32, 0.8f32);
    let env = Environment {
        zenith: Vec3::splat(l),
        horizon: Vec3::splat(l),
        ground: Vec3::splat(l),
        intensity: 1.0,
        map: None,
    };
    let camera = Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0));
    let scene = one_mesh_scene(
        &sphere(1.0, true),
        lambert(a, 0.0),
        camera,
        vec![],
        Some(env),
    );
    let images = render_reference(&device, &scene, 0.0, &params(32, 2), 2).expect("reference");
    let (mut on, mut off) = (0, 0);
    for t in &images.full.texels {
        if (t[0] - l).abs() < 1e-3 * l {
            off += 1;
        } else {
            assert!(
                (t[0] - a * l).abs() < 1e-3,
                "sphere pixel {t:?}, expected {}",
                a * l
            );
            on += 1;
        }
    }
    assert!(on > 100 && off > 100, "{on} sphere and {off} sky pixels");
    assert_all(&images.indirect, 0.0, 1e-6, "indirect");
    common::assert_clean(&device);
}

/// A Lambertian plane (albedo a) under a point light of intensity I at height h: radiance
/// a/π · E with E = I cos θ / d² (inverse square law, no range window).
#[test]
fn diffuse_plane_under_a_point_light_matches_analytic_irradiance() {
    let device = common::device();
    let (a, intensity, h) = (0.5f32, 10.0f32, 2.0f32);
    let s = 20.0;
    let corners = [
        Vec3::new(-s, 0.0, -s),
        Vec3::new(-s, 0.0, s),
        Vec3::new(s, 0.0, s),
        Vec3::new(s, 0.0, -s),
    ];
    let plane = [
        [corners[0], corners[1], corners[2]],
        [corners[0], corners[2], corners[3]],
    ];
    let light_position = Vec3::new(0.3, h, -0.2);
    let light = Light {
        position: light_position.to_array(),
        kind: 1,
        direction: [0.0, -1.0, 0.0],
        range: 0.0,
        color: [1.0; 3],
        intensity,
        inner_cone_angle: 0.0,
        outer_cone_angle: 0.0,
        node: u32::MAX,
        _pad: 0,
    };
    // Looking straight down from 5 m.
    let eye = Vec3::new(0.0, 5.0, 0.0);
    let camera =
        Mat4::from_rotation_translation(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2), eye);
    let scene = one_mesh_scene(&plane, lambert(a, 0.0), camera, vec![light], None);
    let size = 24;
    let images = render_reference(&device, &scene, 0.0, &params(size, 0), 1).expect("reference");
    // The camera ray of every pixel centre, as the tracer builds it.
    let rays = common::scenes::pixel_rays(&device, &scene, size);
    for y in 0..size {
        for x in 0..size {
            let (o, d) = rays[(y * size + x) as usize];
            let p = o + d * (-o.y / d.y);
            let to_light = light_position - p;
            let d2 = to_light.length_squared();
            let cos = to_light.y / d2.sqrt();
            let expected = a / std::f32::consts::PI * intensity * cos / d2;
            let got = images.direct.texels[(y * size + x) as usize][0];
            assert!(
                (got - expected).abs() < 1e-3 * expected,
                "pixel ({x}, {y}): {got}, expected {expected}"
            );
        }
    }
    common::assert_clean(&device);
}

/// Light sampling (next-event estimation of the emitting sphere, weighted against BRDF
/// sampling by MIS) keeps the white furnace's answer: each sample is no longer exact, but the
/// mean over the image is L_e Σ a^k within 1%, and every pixel within 12%.
#[test]
fn light_sampling_keeps_the_white_furnace() {
    let device = common::device();
    let (a, le) = (0.6f32, 0.5f32);
    let scene = one_mesh_scene(
        &sphere(1.0, false),
        lambert(a, le),
        Mat4::IDENTITY,
        vec![],
        None,
    );
    let sampled = ReferenceParams {
        light_sampling: true,
        ..params(16, 1)
    };
    let images = render_reference(&device, &scene, 0.0, &sampled, 64).expect("reference");
    let expected = le * (1.0 + a + a * a);
    let mean = mean_red(&images.full, |_| true);
    assert!(
        (mean / f64::from(expected) - 1.0).abs() < 0.01,
        "mean {mean}, expected {expected}"
    );
    assert_all(&images.full, expected, 0.12, "full, light sampling");
    common::assert_clean(&device);
}

/// Under a sky with a sun (a 4×2-texel block of a 64×32 map, 400 times the sky's radiance,
/// 30° from the zenith: the sampling tables' peak ratio far above ENVIRONMENT_PEAK_RATIO), a
/// convex sphere's mean radiance is the same with light sampling as with BRDF sampling alone
/// (within 2.5%: BRDF sampling's rarely hit sun leaves its 4096-spp runs 0.5% apart; light
/// sampling's agree within 0.02%), and light sampling cuts the error at 8 spp at least in half
/// (measured: 4×).
#[test]
fn environment_sampling_keeps_the_mean_under_a_sun() {
    let device = common::device();
    let (w, h) = (64u32, 32u32);
    let texels: Vec<[f32; 3]> = (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            if (20..24).contains(&i) && (5..7).contains(&j) {
                [200.0, 190.0, 170.0]
            } else {
                [0.4, 0.5, 0.7]
            }
        })
        .collect();
    let env = Environment {
        zenith: Vec3::ZERO,
        horizon: Vec3::ZERO,
        ground: Vec3::ZERO,
        intensity: 1.0,
        map: Some(shine_scene::environment::EquirectMap {
            width: w,
            height: h,
            texels: std::sync::Arc::new(texels),
            uri: "sun".into(),
        }),
    };
    let camera = Mat4::from_translation(Vec3::new(0.0, 0.0, 3.0));
    let scene = one_mesh_scene(
        &sphere(1.0, true),
        lambert(0.5, 0.0),
        camera,
        vec![],
        Some(env),
    );
    let run = |light_sampling: bool, spp: u32, seed: u32| {
        let p = ReferenceParams {
            light_sampling,
            seed,
            ..params(32, 1)
        };
        render_reference(&device, &scene, 0.0, &p, spp).expect("reference")
    };
    let (on, off) = (run(true, 1024, 1), run(false, 4096, 2));
    // The sphere's pixels, away from its silhouette: camera rays passing within 0.95 of the
    // centre.
    let rays = common::scenes::pixel_rays(&device, &scene, 32);
    let on_sphere = |i: usize| {
        let (o, d) = rays[i];
        let d = d.normalize();
        (o - d * o.dot(d)).length() < 0.95
    };
    let (m_on, m_off) = (
        mean_red(&on.full, on_sphere),
        mean_red(&off.full, on_sphere),
    );
    assert!(m_on > 0.1, "sphere mean {m_on}");
    assert_same_mean("sphere", m_on, m_off, 0.025);
    assert_light_sampling_halves_the_error(run, 8, 4, &on);
    common::assert_clean(&device);
}

/// The Cornell box's small ceiling emitter: light sampling keeps the mean of the full image
/// (within 1.5%) and of its indirect part (within 2.5%: BRDF sampling alone is noisy there,
/// two of its 4096-spp runs differ by 0.7%) and cuts the error at 16 spp at least in half.
#[test]
fn emitter_sampling_keeps_the_mean_and_cuts_the_noise() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let run = |light_sampling: bool, spp: u32, seed: u32| {
        let p = ReferenceParams {
            width: 32,
            height: 32,
            bounces: 1,
            jitter: false,
            emissive_lighting: true,
            lambert_only: false,
            light_sampling,
            seed,
            primary_specular: None,
        };
        render_reference(&device, &scene, 0.0, &p, spp).expect("reference")
    };
    let (on, off) = (run(true, 1024, 1), run(false, 2048, 2));
    for (what, a, b, tolerance) in [
        ("full", &on.full, &off.full, 0.015),
        ("indirect", &on.indirect, &off.indirect, 0.025),
    ] {
        assert_same_mean(
            what,
            mean_red(a, |_| true),
            mean_red(b, |_| true),
            tolerance,
        );
    }
    assert_light_sampling_halves_the_error(run, 16, 3, &on);
    common::assert_clean(&device);
}

/// trace.glsl's closest hit and occlusion through the two-level BVH equal shine-scene's
/// one-level world-space `Bvh::intersect` on the Cornell box for rays from inside and outside
/// it, at rest and with every instance moved by a host update (rotated, scaled unevenly,
/// translated: the top level and the rays' trip into mesh space are both exercised).
#[test]
fn gpu_traversal_hits_equal_cpu_bvh_hits() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut gpu = GpuScene::upload(&device, &scene, 0.0).expect("upload");
    let hits = check_traversal(&device, &mut gpu);
    assert!(hits > 1.0 / 3.0, "only {hits} of the rays hit");
    let nodes = gpu
        .instances
        .iter()
        .enumerate()
        .map(|(i, r)| {
            let k = i as f32;
            let transform = Transform {
                translation: Vec3::new(0.05 * k, -0.03 * k, 0.02),
                rotation: Quat::from_axis_angle(
                    Vec3::new(1.0, 2.0, 0.5).normalize(),
                    0.1 + 0.07 * k,
                ),
                scale: Vec3::new(1.0, 0.9, 1.1),
            };
            (r.node as usize, transform)
        })
        .collect();
    gpu.update(&FrameUpdate {
        nodes,
        ..FrameUpdate::at(0.0)
    })
    .expect("update");
    let hits = check_traversal(&device, &mut gpu);
    assert!(hits > 1.0 / 3.0, "only {hits} of the rays hit");
    common::assert_clean(&device);
}

/// The same on a mesh whose bottom level fills several rows of the BVH images (a wavy grid of
/// 2 × 72² triangles: more than `TRACE_ROW_TEXELS` texels of nodes and of triangles), so
/// texels past the first row are addressed.
#[test]
fn gpu_traversal_reads_bvh_images_of_several_rows() {
    let device = common::device();
    let n = 72;
    let point = |i: usize, j: usize| {
        let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
        Vec3::new(x, 0.05 * (17.0 * x).sin() * (11.0 * z).cos(), z)
    };
    let mut grid = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            grid.push([a, b, c]);
            grid.push([a, c, d]);
        }
    }
    let camera = Mat4::look_at_rh(Vec3::new(0.0, 1.0, 1.5), Vec3::ZERO, Vec3::Y);
    let scene = one_mesh_scene(&grid, lambert(0.5, 0.0), camera, vec![], None);
    let mut gpu = GpuScene::upload(&device, &scene, 0.0).expect("upload");
    let row = shine::gpu_scene::bvh::TRACE_ROW_TEXELS;
    assert!(gpu.bvh.nodes.extent()[1] > 1 && gpu.bvh.triangles.extent()[1] > 1);
    assert_eq!(gpu.bvh.nodes.extent()[0], row);
    let hits = check_traversal(&device, &mut gpu);
    // A sheet: a fifth of the rays from all around meet it.
    assert!(hits > 0.2, "only {hits} of the rays hit");
    common::assert_clean(&device);
}

/// Traces 4096 pseudo-random rays through `gpu`'s BVH on the GPU and on the CPU; returns the
/// share of them that hit.
fn check_traversal(device: &shine::gpu::Device, gpu: &mut GpuScene) -> f32 {
    let (cpu_bvh, flat_index) = world_bvh(gpu.rig(), &gpu.state.pose.world).expect("cpu bvh");
    let (lo, hi) = gpu.state.bounds;
    // Deterministic pseudo-random rays: origins in the box grown by 20 %, directions anywhere.
    let mut state = 12345u32;
    let mut rand = move || {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as f32 / u32::MAX as f32
    };
    let count = 4096usize;
    let mut rays: Vec<[f32; 4]> = Vec::new();
    let mut cpu = Vec::new();
    for i in 0..count {
        let grow = (hi - lo) * 0.2;
        let o = lo - grow + (hi - lo + 2.0 * grow) * Vec3::new(rand(), rand(), rand());
        let d = (Vec3::new(rand(), rand(), rand()) * 2.0 - 1.0).normalize_or(Vec3::X);
        // Every fourth ray is a short segment (occlusion with a finite t_max).
        let t_max = if i % 4 == 0 { 0.3 } else { 1e30 };
        rays.push([o.x, o.y, o.z, 0.0]);
        rays.push([d.x, d.y, d.z, t_max]);
        cpu.push(cpu_bvh.intersect(&Ray {
            origin: o,
            dir: d,
            t_min: 0.0,
            t_max,
        }));
    }
    let ray_buffer = common::storage_with(device, "rays", bytemuck::cast_slice(&rays));
    let hits = common::buffer(
        device,
        "hits",
        (count * 32) as u64,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
    );
    let mut executor = Executor::new(device, 1).expect("executor");
    let mut rg = executor.begin_frame();
    let handles = gpu.declare(&mut rg).expect("declare");
    let rays_handle = rg.import_gpu_buffer(
        &ray_buffer,
        common::uploaded_state(),
        common::uploaded_state(),
    );
    let mut hits_handle =
        rg.import_gpu_buffer(&hits, ExternalState::UNDEFINED, common::read_by_copy());
    let mut pass = rg.compute("trace_rays", &shine::shaders::TESTS_TRACE_RAYS_COMP);
    handles.trace.bind(&mut pass);
    pass.read("rays", &rays_handle)
        .write("hits", &mut hits_handle)
        .push(&[count as u32, 0, 0, 0])
        .dispatch([count as u32, 1, 1]);
    common::run_graph(device, &mut executor, rg);
    let gpu_hits: Vec<[f32; 4]> =
        bytemuck::cast_slice(&device.read_buffer(&hits).expect("readback")).to_vec();
    let (mut hit_count, mut ties) = (0, 0);
    for (i, expected) in cpu.iter().enumerate() {
        let (h, occluded) = (gpu_hits[2 * i], gpu_hits[2 * i + 1][0] > 0.5);
        match expected {
            None => {
                assert!(h[0] < 0.0, "ray {i}: GPU hit {h:?}, CPU none");
                assert!(!occluded, "ray {i}: GPU occluded, CPU none");
            }
            Some(hit) => {
                hit_count += 1;
                assert!(occluded, "ray {i}: CPU hit, GPU not occluded");
                assert!(
                    (h[0] - hit.t).abs() <= 1e-4 * hit.t.max(1.0),
                    "ray {i}: t {} vs {}",
                    h[0],
                    hit.t
                );
                let flat = flat_index[hit.triangle];
                if h[3].to_bits() != flat {
                    // Two triangles at the same t (a shared edge): either is the closest hit.
                    ties += 1;
                } else {
                    assert!(
                        (h[1] - hit.u).abs() < 1e-3 && (h[2] - hit.v).abs() < 1e-3,
                        "ray {i}: uv"
                    );
                }
            }
        }
    }
    assert!(ties <= count / 100, "{ties} hits on a different triangle");
    hit_count as f32 / count as f32
}

/// The Monte-Carlo error falls as 1/√spp: two independent estimates (different seeds) of the
/// Cornell box differ by √2·σ/√N, so 16× the samples divide their RMSE by about 4.
#[test]
fn error_falls_as_inverse_square_root_of_samples() {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let base = ReferenceParams {
        width: 32,
        height: 32,
        bounces: 1,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        light_sampling: true,
        seed: 1,
        primary_specular: None,
    };
    let run = |seed: u32, spp: u32| -> ReferenceImages {
        let mut tracer = PathTracer::new(&device, &scene, 0.0, &ReferenceParams { seed, ..base })
            .expect("tracer");
        tracer.accumulate(spp).expect("accumulate");
        tracer.read().expect("read")
    };
    let error = |spp| {
        let (a, b) = (run(1, spp), run(2, spp));
        rmse(&a.indirect, &b.indirect).expect("rmse")
    };
    let (few, many) = (error(4), error(64));
    let ratio = few / many;
    assert!(
        (3.2..=4.8).contains(&ratio),
        "RMSE {few} at 4 spp, {many} at 64 spp: ratio {ratio}, expected ≈ 4"
    );
    common::assert_clean(&device);
}

/// A buffer copied into an image fills its whole rows, then the start of the next row, and
/// leaves the rest as it was: how the path tracer's scene texels mirror buffers whose sizes
/// are not whole rows (src/reference/scene_texels.rs).
#[test]
fn a_buffer_copy_fills_whole_rows_then_the_start_of_the_next() {
    let device = common::device();
    let (width, height) = (16u32, 4u32);
    let words: Vec<u32> = (0..2 * width + 5).map(|k| 1000 + k).collect();
    let buffer = common::buffer_with(
        &device,
        "words",
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
        bytemuck::cast_slice(&words),
    );
    let before: Vec<u32> = vec![7; (width * height) as usize];
    let image = common::storage_image_with(
        &device,
        "texels",
        vk::Format::R32_UINT,
        [width, height],
        bytemuck::cast_slice(&before),
    );
    let mut executor = Executor::new(&device, 1).expect("executor");
    let mut rg = executor.begin_frame();
    let src = rg.import_gpu_buffer(&buffer, common::uploaded_state(), common::read_by_copy());
    let mut dst = rg.import_gpu_image(&image, common::uploaded_state(), common::uploaded_state());
    rg.copy_buffer_to_image("mirror", &src, &mut dst);
    common::run_graph(&device, &mut executor, rg);
    let after: Vec<u32> = bytemuck::cast_slice(
        &device
            .read_image(&image, vk::ImageLayout::GENERAL)
            .expect("readback"),
    )
    .to_vec();
    for (k, &texel) in after.iter().enumerate() {
        let expected = words.get(k).copied().unwrap_or(7);
        assert_eq!(texel, expected, "texel {k}");
    }
    common::assert_clean(&device);
}
