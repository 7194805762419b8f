//! Image tests: frames of the Cornell box against the path-traced reference (src/reference/mod.rs)
//! with PSNR/SSIM thresholds (src/capture/image_compare.rs: metrics on linear radiance clamped to
//! [0, 1]). Same lights on both sides: the spot lamp only (emissive surfaces are seen but light
//! nothing, `emissive_lighting: false`), camera rays through pixel centres as the raster samples.

mod common;

use shine::capture::image_compare::{Comparison, compare};
use shine::frame::renderer::Renderer;
use shine::passes::composite::Component;
use shine::reference::{ReferenceParams, render_reference};
use shine::settings::{GiTechniques, Settings};
use shine_scene::Scene;

const SIZE: u32 = 128;

fn raster(component: Component) -> shine::capture::image_io::HdrImage {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let mut settings = Settings {
        width: SIZE,
        height: SIZE,
        ..Settings::default()
    };
    if component == Component::Direct {
        settings.gi = GiTechniques::none();
    }
    settings.output.component = component;
    let frame = renderer.render(&settings).expect("frame");
    drop(renderer);
    common::assert_clean(&device);
    frame.hdr
}

fn reference(bounces: u32, spp: u32) -> shine::reference::ReferenceImages {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let params = ReferenceParams {
        width: SIZE,
        height: SIZE,
        bounces,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        seed: 0,
    };
    let images = render_reference(&device, &scene, 0.0, &params, spp).expect("reference");
    common::assert_clean(&device);
    images
}

fn report(what: &str, c: &Comparison) {
    println!(
        "{what}: RMSE {:.4}, PSNR {:.2} dB, SSIM {:.4}",
        c.rmse, c.psnr, c.ssim
    );
}

/// The raster direct pass (shadow-mapped spot lamp, Lambert + GGX) against the path-traced
/// direct light: both evaluate the same BRDF and light falloff at the same points, so they
/// differ only at shadow edges (PCF against hard ray-traced shadows) and by the G-buffer's
/// 8-bit albedo and material quantisation. No bounce: the estimate is exact (1 spp suffices).
#[test]
fn raster_direct_light_matches_the_path_traced_direct_light() {
    let direct = raster(Component::Direct);
    let reference = reference(0, 1);
    let c = compare(&direct, &reference.direct).expect("compare");
    report("direct", &c);
    // Measured (lavapipe): RMSE 0.0027, PSNR 51.3 dB, SSIM 0.996.
    assert!(c.psnr > 45.0 && c.ssim > 0.99, "{c:?}");
}

/// HVL one-bounce indirect light (default settings: 400 HVLs, receivers at 1/2) against the
/// path-traced one-bounce indirect light of the same lamp.
#[test]
fn hvl_indirect_light_against_the_path_traced_reference() {
    let hvl = raster(Component::Indirect);
    let reference = reference(1, 64);
    let c = compare(&hvl, &reference.indirect).expect("compare");
    report("indirect", &c);
    // Measured (lavapipe, reference at 64 spp whose noise lowers SSIM): RMSE 0.0104,
    // PSNR 39.7 dB, SSIM 0.88.
    assert!(c.psnr > 36.0 && c.ssim > 0.82, "{c:?}");
    // Energy: measured HVL / reference mean indirect radiance 1.19 (HVL is brighter; not yet
    // explained). Kept within 0.8..=1.3 so a regression either way shows.
    let mean = |image: &shine::capture::image_io::HdrImage| {
        image
            .texels
            .iter()
            .map(|t| f64::from(t[0] + t[1] + t[2]))
            .sum::<f64>()
            / image.texels.len() as f64
    };
    let ratio = mean(&hvl) / mean(&reference.indirect);
    println!("indirect mean ratio HVL / reference: {ratio:.3}");
    assert!(
        (0.8..=1.3).contains(&ratio),
        "HVL / reference mean indirect radiance {ratio}"
    );
}

/// Paper 002's frame (`--gi proxy`: the sky shadowed by the sphere proxies plus their indirect
/// light) of the `spheres` scene against the path-traced reference of the same scene with the
/// proxies' real meshes, lit by the same sky, one bounce; both show the sky behind the scene.
/// Compared where the raster frame is not black: the fully metallic torus (the proxy path
/// shades Lambert only; its specular environment term is not part of paper 002) is left out.
#[test]
fn spheres_proxy_frame_against_the_path_traced_reference() {
    const SIDE: u32 = 64;
    let device = common::device();
    let scene = Scene::builtin("spheres").expect("scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let mut settings = Settings {
        width: SIDE,
        height: SIDE,
        gi: "proxy".parse().expect("gi"),
        receiver_scale: 1,
        ..Settings::default()
    };
    settings.shadow.size = 256;
    // The path tracer reads level 0 at each pixel centre: so does the raster here.
    settings.texture.mipmaps = false;
    let frame = renderer.render(&settings).expect("frame").hdr;
    settings.proxy.brute_force = true;
    let brute = renderer.render(&settings).expect("brute-force frame").hdr;
    drop(renderer);
    let params = ReferenceParams {
        width: SIDE,
        height: SIDE,
        bounces: 1,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        seed: 0,
    };
    let reference = render_reference(&device, &scene, 0.0, &params, 256).expect("reference");
    common::assert_clean(&device);
    let shaded = |t: &[f32; 4]| t[0] + t[1] + t[2] > 0.0;
    let masked = frame.texels.iter().filter(|t| !shaded(t)).count();
    assert!(
        masked < (SIDE * SIDE / 10) as usize,
        "{masked} of {} pixels are black in the raster frame",
        SIDE * SIDE
    );
    let keep = |image: &shine::capture::image_io::HdrImage| shine::capture::image_io::HdrImage {
        width: image.width,
        height: image.height,
        texels: image
            .texels
            .iter()
            .zip(&frame.texels)
            .map(|(t, f)| if shaded(f) { *t } else { [0.0; 4] })
            .collect(),
    };
    let sum = |image: &shine::capture::image_io::HdrImage| {
        keep(image)
            .texels
            .iter()
            .map(|t| t[0] + t[1] + t[2])
            .sum::<f32>()
    };
    let splat = compare(&keep(&frame), &keep(&reference.full)).expect("compare");
    let exact = compare(&keep(&brute), &keep(&reference.full)).expect("compare");
    report("spheres, proxy frame vs reference", &splat);
    report("spheres, brute-force proxy frame vs reference", &exact);
    let ratio = sum(&frame) / sum(&reference.full);
    println!("mean ratio {ratio:.3}, {masked} pixels masked");
    // Measured on lavapipe (64², 256 spp): PSNR 32.4 dB (brute force 32.45), SSIM 0.961,
    // mean 0.990× the reference, 136 pixels (the torus) masked.
    assert!(
        splat.psnr > 30.0 && splat.ssim > 0.94,
        "PSNR {} SSIM {}",
        splat.psnr,
        splat.ssim
    );
    assert!((0.85..1.15).contains(&ratio), "mean ratio {ratio}");
    assert!(exact.psnr > 30.0, "brute force PSNR {}", exact.psnr);
}
