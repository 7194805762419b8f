//! The sky light of frames without proxies (issue 16, item 7; src/passes/sky.rs) against the
//! path tracer: a grey floor with a ball above it under a uniform sky, no punctual light. On
//! the floor the frame (`gi = hvl`, which adds nothing without a light) must show the ball's
//! sky shadow where the path tracer does; without the pass the floor is black.

mod common;

use common::scenes::luminance;
use glam::{Mat4, Vec3};
use shine::capture::image_io::HdrImage;
use shine::reference::render_reference;
use shine_scene::Scene;
use shine_scene::environment::Environment;

const SIZE: u32 = 32;
const BALL: Vec3 = Vec3::new(0.0, 0.7, 0.0);
const RADIUS: f32 = 0.6;

fn scene() -> Scene {
    let sky = Environment {
        zenith: Vec3::splat(1.0),
        horizon: Vec3::splat(1.0),
        ground: Vec3::splat(1.0),
        intensity: 1.0,
        map: None,
    };
    let camera = Mat4::look_at_rh(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y).inverse();
    common::scenes::mesh_scene(
        &[
            (common::scenes::floor(6.0, 0.0), common::scenes::matte(0.6)),
            (
                common::scenes::sphere(BALL, RADIUS, true),
                common::scenes::matte(0.5),
            ),
        ],
        camera,
        vec![],
        Some(sky),
    )
}

fn frame(device: &shine::gpu::Device, scene: &Scene, sky: bool) -> HdrImage {
    frame_with(device, scene, sky, 256, None)
}

/// The frame with `rays` sky rays per receiver, filtered by the denoiser (`None`, the default)
/// or by the joint bilateral of radius `Some(r)` (`denoise.diffuse = false`; 0: unfiltered).
fn frame_with(
    device: &shine::gpu::Device,
    scene: &Scene,
    sky: bool,
    rays: u32,
    bilateral: Option<u32>,
) -> HdrImage {
    let radius = bilateral.unwrap_or(shine::passes::sky::FILTER_RADIUS);
    let s = common::scenes::settings(
        SIZE,
        &[
            ("gi", "hvl"),
            ("sky.enabled", &sky.to_string()),
            ("sky.rays", &rays.to_string()),
            ("sky.filter_radius", &radius.to_string()),
            ("denoise.diffuse", &bilateral.is_none().to_string()),
        ],
    );
    common::scenes::render_once(device, scene, &s)
}

/// The floor pixels, away from the ball's silhouette and the floor's edge: their centre ray
/// meets the floor, and misses a sphere 20% larger than the ball.
fn floor_pixels(device: &shine::gpu::Device, scene: &Scene) -> Vec<usize> {
    let r = 1.2 * RADIUS;
    common::scenes::pixel_rays(device, scene, SIZE)
        .iter()
        .enumerate()
        .filter(|(_, (o, d))| {
            let misses_ball = !common::scenes::ray_meets_sphere(*o, *d, BALL, r);
            let on_floor = d.y < 0.0 && {
                let hit = *o + *d * (-o.y / d.y);
                hit.x.abs() < 5.5 && hit.z.abs() < 5.5
            };
            on_floor && misses_ball
        })
        .map(|(p, _)| p)
        .collect()
}

/// On the floor: the frame's energy is the path tracer's to 6% (the frame leaves out the rough
/// floor's glossy reflection of the sky, a few percent), and, each image divided by its own
/// mean, the shadow's shape matches to 4% relative RMSE (256 rays against 1024 paths). The
/// shadow is there: the darkest floor pixel is below 80% of the brightest in both.
#[test]
fn the_sky_lights_the_floor_around_the_balls_shadow() {
    let device = common::device();
    let scene = scene();
    let pixels = floor_pixels(&device, &scene);
    assert!(pixels.len() > 300, "{} floor pixels", pixels.len());
    let params = common::scenes::pixel_centre_reference(SIZE, 3);
    let truth = render_reference(&device, &scene, 0.0, &params, 1024).expect("reference");
    let truth = luminance(&truth.full, &pixels);
    let lit = luminance(&frame(&device, &scene, true), &pixels);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (m_truth, m_lit) = (mean(&truth), mean(&lit));
    let energy = m_lit / m_truth;
    let shape = (truth
        .iter()
        .zip(&lit)
        .map(|(t, l)| (l / m_lit - t / m_truth).powi(2))
        .sum::<f64>()
        / truth.len() as f64)
        .sqrt();
    let contrast = |v: &[f64]| {
        v.iter().copied().fold(f64::MAX, f64::min) / v.iter().copied().fold(0.0, f64::max)
    };
    println!(
        "energy {energy:.4}, shape relative RMSE {shape:.4}, darkest/brightest {:.3} (truth {:.3})",
        contrast(&lit),
        contrast(&truth)
    );
    assert!((energy - 1.0).abs() < 0.06, "energy {energy}");
    assert!(shape < 0.04, "shape {shape}");
    assert!(contrast(&lit) < 0.8 && contrast(&truth) < 0.8);
    let dark = mean(&luminance(&frame(&device, &scene, false), &pixels));
    assert!(dark < 0.01 * m_truth, "without the pass: {dark}");
    common::assert_clean(&device);
}

/// The sky's filters, the joint bilateral (`denoise.diffuse = false`) and the denoiser (the
/// default): with 4 rays per receiver, each filtered floor is at least twice as close to the
/// 1024-ray unfiltered floor as the unfiltered one (relative RMSE), and keeps its light to 2%.
#[test]
fn the_sky_filter_cuts_the_noise_and_keeps_the_light() {
    let device = common::device();
    let scene = scene();
    let pixels = floor_pixels(&device, &scene);
    let floor = |rays, filter| luminance(&frame_with(&device, &scene, true, rays, filter), &pixels);
    let clean = floor(1024, Some(0));
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let error = |v: &[f64]| {
        (v.iter()
            .zip(&clean)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            / v.len() as f64)
            .sqrt()
            / mean(&clean)
    };
    let raw = floor(4, Some(0));
    for (name, filter) in [
        ("bilateral", Some(shine::passes::sky::FILTER_RADIUS)),
        ("denoised", None),
    ] {
        let filtered = floor(4, filter);
        let energy = mean(&filtered) / mean(&clean);
        println!(
            "4 rays: relative RMSE {:.4} unfiltered, {:.4} {name}; energy {energy:.4}",
            error(&raw),
            error(&filtered)
        );
        assert!(error(&filtered) < 0.5 * error(&raw), "{name}");
        assert!((energy - 1.0).abs() < 0.02, "{name}: energy {energy}");
    }
    common::assert_clean(&device);
}

/// Cavity shading (issue 18, item 2): with a reach beyond the whole scene, the cavity factor
/// of a floor receiver is its visibility past the ball, `1 − (R/d)² cos φ` (Nusselt: the form
/// factor of a sphere wholly above the receiver's plane, d the distance to its centre and φ
/// the centre's angle from the normal). The ratio of HVL's light with and without the pass
/// (a sun lights the scene; 1024 rays) matches it to 0.02 on average over the floor, and to a
/// tenth of the mean occlusion itself.
#[test]
fn cavity_darkens_hvl_light_by_the_visibility_past_the_ball() {
    let device = common::device();
    let mut scene = scene();
    scene.environment = None;
    scene.lights.push(shine_scene::Light {
        position: [0.0; 3],
        kind: 0,
        direction: Vec3::new(0.3, -1.0, -0.4).normalize().to_array(),
        range: 0.0,
        color: [1.0; 3],
        intensity: 3.0,
        inner_cone_angle: 0.0,
        outer_cone_angle: 0.0,
        node: u32::MAX,
        _pad: 0,
    });
    let indirect = |cavity: bool| {
        let s = common::scenes::settings(
            SIZE,
            &[
                ("gi", "hvl"),
                ("output.component", "indirect"),
                ("specular.enabled", "false"),
                ("cavity.rays", "1024"),
                ("cavity.range", "1.0"),
                // Cavity shading is for paper 003's unshadowed HVLs, without the traced near
                // field.
                ("hvl.visibility", "false"),
                ("hvl.near_range", "0"),
                ("cavity.enabled", &cavity.to_string()),
            ],
        );
        common::scenes::render_once(&device, &scene, &s)
    };
    let (open, shaded) = (indirect(false), indirect(true));
    let rays = common::scenes::pixel_rays(&device, &scene, SIZE);
    let mut errors = Vec::new();
    let mut occlusion = 0.0f32;
    for p in floor_pixels(&device, &scene) {
        let light = open.texels[p][1];
        if light <= 1e-4 {
            continue;
        }
        let (o, d) = rays[p];
        let x = o + d * (-o.y / d.y);
        let to_ball = BALL - x;
        let expected = 1.0 - (RADIUS / to_ball.length()).powi(2) * (to_ball.y / to_ball.length());
        errors.push((shaded.texels[p][1] / light - expected).abs());
        occlusion += 1.0 - expected;
    }
    let mean = errors.iter().sum::<f32>() / errors.len() as f32;
    println!(
        "{} floor receivers: mean |ratio − visibility| {mean:.4}",
        errors.len()
    );
    assert!(
        errors.len() > 200 && mean < 0.02,
        "{} receivers, {mean}",
        errors.len()
    );
    // an error far below the occlusion itself: a pass doing nothing would fail
    let occlusion = occlusion / errors.len() as f32;
    assert!(
        mean < 0.1 * occlusion,
        "error {mean} against occlusion {occlusion}"
    );
    common::assert_clean(&device);
}
