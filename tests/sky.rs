//! The sky light of frames without proxies (issue 16, item 7; src/passes/sky.rs) against the
//! path tracer: a grey floor with a ball above it under a uniform sky, no punctual light. On
//! the floor the frame (`gi = hvl`, which adds nothing without a light) must show the ball's
//! sky shadow where the path tracer does; without the pass the floor is black.

mod common;

use glam::{Mat4, Vec3};
use shine::capture::image_io::HdrImage;
use shine::reference::{ReferenceParams, render_reference};
use shine::{Renderer, Settings};
use shine_scene::environment::Environment;
use shine_scene::{Material, Scene};

const SIZE: u32 = 32;
const BALL: Vec3 = Vec3::new(0.0, 0.7, 0.0);
const RADIUS: f32 = 0.6;

fn grey(albedo: f32) -> Material {
    Material {
        base_color: [albedo, albedo, albedo, 1.0],
        metallic: 0.0,
        roughness: 1.0,
        double_sided: 1,
        ..Material::default()
    }
}

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
            (common::scenes::floor(6.0, 0.0), grey(0.6)),
            (common::scenes::sphere(BALL, RADIUS, true), grey(0.5)),
        ],
        camera,
        vec![],
        Some(sky),
    )
}

fn frame(device: &shine::gpu::Device, scene: &Scene, sky: bool) -> HdrImage {
    let mut s = Settings {
        width: SIZE,
        height: SIZE,
        receiver_scale: 1,
        ..Settings::default()
    };
    s.set("gi", "hvl").expect("gi");
    s.set("sky.enabled", &sky.to_string()).expect("sky");
    s.set("sky.rays", "256").expect("rays");
    let mut renderer = Renderer::new(device).expect("renderer");
    renderer.set_scene(scene, 0.0).expect("scene");
    renderer.render(&s).expect("render").hdr
}

/// The floor pixels, away from the ball's silhouette and the floor's edge: their centre ray
/// meets the floor, and misses a sphere 20% larger than the ball.
fn floor_pixels(device: &shine::gpu::Device, scene: &Scene) -> Vec<usize> {
    let r = 1.2 * RADIUS;
    common::scenes::pixel_rays(device, scene, SIZE)
        .iter()
        .enumerate()
        .filter(|(_, (o, d))| {
            let to_ball = BALL - *o;
            let b = to_ball.dot(*d);
            let misses_ball = b <= 0.0 || to_ball.length_squared() - b * b > r * r;
            let on_floor = d.y < 0.0 && {
                let hit = *o + *d * (-o.y / d.y);
                hit.x.abs() < 5.5 && hit.z.abs() < 5.5
            };
            on_floor && misses_ball
        })
        .map(|(p, _)| p)
        .collect()
}

/// Luminance of `image` at `pixels`.
fn luminance(image: &HdrImage, pixels: &[usize]) -> Vec<f64> {
    pixels
        .iter()
        .map(|&p| {
            let t = image.texels[p];
            f64::from(0.2126 * t[0] + 0.7152 * t[1] + 0.0722 * t[2])
        })
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
    let params = ReferenceParams {
        width: SIZE,
        height: SIZE,
        bounces: 1,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        seed: 3,
    };
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
