//! Whole frames of the built-in scenes on the Vulkan device: finite, lit, bounded and
//! bit-identical across runs, with zero validation messages.

mod common;

use glam::{Mat4, Vec3};
use shine::frame::renderer::Renderer;
use shine::settings::{GiTechniques, Settings};
use shine_scene::{LightKind, Scene};

/// An upper bound on any pixel's radiance: the brightest emission, plus for every light the
/// radiance of a white Lambertian receiving it head-on at the closest distance any vertex of
/// the scene comes to it, times 2 for a specular peak of a normal-incidence GGX lobe with
/// F0 = 1 at roughness 1 (which stays below 1/π·2). Not tight; catches runaway energy.
fn radiance_bound(scene: &Scene) -> f32 {
    let world = scene.rest_world_transforms();
    let positions: Vec<Vec3> = scene
        .instances(&world)
        .iter()
        .flat_map(|i| {
            let m = Mat4::from_cols_array_2d(&i.world);
            scene.meshes[i.mesh as usize]
                .primitives
                .iter()
                .flat_map(move |p| p.positions.iter().map(move |v| m.transform_point3(*v)))
        })
        .collect();
    let emission = scene
        .materials
        .iter()
        .map(|m| m.emissive.iter().copied().fold(0.0, f32::max))
        .fold(0.0, f32::max);
    let lights: f32 = scene
        .lights_at(&world)
        .iter()
        .map(|l| {
            let power = l.intensity * l.color.iter().copied().fold(0.0, f32::max);
            match l.light_kind() {
                Some(LightKind::Directional) => power,
                _ => {
                    let d = positions
                        .iter()
                        .map(|p| p.distance(Vec3::from(l.position)))
                        .fold(f32::MAX, f32::min)
                        .max(1e-3);
                    power / (d * d)
                }
            }
        })
        .sum();
    emission + 2.0 * lights / std::f32::consts::PI
}

fn render(name: &str, settings: &Settings) -> shine::frame::renderer::FrameImage {
    let device = common::device();
    let scene = Scene::builtin(name).expect("built-in scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let frame = renderer.render(settings).expect("frame");
    drop(renderer);
    common::assert_clean(&device);
    frame
}

/// 64×64, direct light only, small shadow map.
fn small_direct_only() -> Settings {
    let mut s = Settings {
        width: 64,
        height: 64,
        gi: GiTechniques::none(),
        ..Settings::default()
    };
    s.shadow.size = 256;
    s
}

/// 64×64 with HVL indirect light (64 HVLs, 3 bands, receivers at 1/2).
fn small_hvl() -> Settings {
    let mut s = Settings {
        gi: GiTechniques::default(),
        receiver_scale: 2,
        ..small_direct_only()
    };
    s.rsm.size = 64;
    s.hvl.count = 64;
    s.hvl.conv_bands = 3;
    s.hvl.emission_bands = 3;
    s
}

/// Sum of RGB over the frame.
fn energy(frame: &shine::frame::renderer::FrameImage) -> f64 {
    frame
        .hdr
        .texels
        .iter()
        .map(|p| f64::from(p[0] + p[1] + p[2]))
        .sum()
}

#[test]
fn cornell_box_with_hvl_is_finite_brighter_bounded_and_repeatable() {
    let scene = Scene::builtin("cornell-box").expect("scene");
    let direct = render("cornell-box", &small_direct_only());
    let a = render("cornell-box", &small_hvl());
    let hdr: Vec<f32> = a.hdr.texels.iter().flatten().copied().collect();
    assert!(
        hdr.iter().all(|v| v.is_finite() && *v >= 0.0),
        "non-finite or negative radiance"
    );
    let (with, without) = (energy(&a), energy(&direct));
    // One bounce adds light, and in a closed box of albedo < 0.8 less than the direct light.
    assert!(
        with > without * 1.01,
        "HVL added nothing: {with} vs {without}"
    );
    assert!(
        with < without * 2.0,
        "HVL more than doubled the light: {with} vs {without}"
    );
    let bound = radiance_bound(&scene);
    let max = hdr.iter().copied().fold(0.0, f32::max);
    assert!(
        max <= bound,
        "a pixel of radiance {max} exceeds the energy bound {bound}"
    );
    let b = render("cornell-box", &small_hvl());
    assert_eq!(a.hdr.texels, b.hdr.texels, "two runs differ");
    let names: Vec<_> = a.timings.iter().map(|t| t.name.as_str()).collect();
    for pass in [
        "rsm",
        "hvl_cache",
        "receivers",
        "hvl_gather",
        "upsample",
        "composite",
    ] {
        assert!(names.contains(&pass), "no timing for {pass}: {names:?}");
    }
    eprintln!("frame energy: direct {without:.1}, direct + HVL {with:.1}");
}

#[test]
fn cornell_box_direct_light_is_finite_lit_and_repeatable() {
    let settings = small_direct_only();
    let a = render("cornell-box", &settings);
    let hdr: Vec<f32> = a.hdr.texels.iter().flatten().copied().collect();
    assert!(hdr.iter().all(|v| v.is_finite()), "non-finite radiance");
    let mean: f32 = a.hdr.texels.iter().map(|p| p[0] + p[1] + p[2]).sum::<f32>() / (64.0 * 64.0);
    assert!(mean > 1e-3, "the frame is black (mean {mean})");
    let bound = radiance_bound(&Scene::builtin("cornell-box").expect("scene"));
    let max = hdr.iter().copied().fold(0.0, f32::max);
    eprintln!("max radiance {max}, bound {bound}");
    assert!(
        max <= bound,
        "a pixel of radiance {max} exceeds the energy bound {bound}"
    );
    let b = render("cornell-box", &settings);
    assert_eq!(a.hdr.texels, b.hdr.texels, "two runs differ (HDR)");
    assert_eq!(a.ldr.texels, b.ldr.texels, "two runs differ (LDR)");
    let names: Vec<_> = a.timings.iter().map(|t| t.name.as_str()).collect();
    // The Cornell lamp is a wide spot: its shadow is drawn as cube faces.
    for pass in ["gbuffer", "shadow light 0 -y", "direct", "composite"] {
        assert!(names.contains(&pass), "no timing for {pass}: {names:?}");
    }
}

#[test]
fn textured_room_renders_finite_and_lit() {
    // Texture arrays (sRGB and linear), normal maps, a point and a spot light.
    let mut settings = small_direct_only();
    settings.width = 32;
    settings.height = 32;
    let frame = render("room", &settings);
    assert!(frame.hdr.texels.iter().flatten().all(|v| v.is_finite()));
    let lit = frame
        .hdr
        .texels
        .iter()
        .filter(|p| p[0] + p[1] + p[2] > 1e-3)
        .count();
    assert!(lit > 32 * 32 / 2, "only {lit} of 1024 pixels are lit");
}
