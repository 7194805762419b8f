//! Image tests: frames of the Cornell box against the path-traced reference (src/reference/mod.rs)
//! with PSNR/SSIM or relative-RMSE and energy thresholds (src/capture/image_compare.rs: metrics on linear radiance clamped to
//! [0, 1]). Same lights on both sides: the spot lamp only (emissive surfaces are seen but light
//! nothing, `emissive_lighting: false`), camera rays through pixel centres as the raster samples.

mod common;

use shine::capture::image_compare::{Comparison, compare};
use shine::capture::regions::{SurfacePixels, surface_metrics, surface_pixels};
use shine::frame::renderer::Renderer;
use shine::passes::composite::Component;
use shine::reference::{ReferenceParams, render_reference};
use shine::settings::{GiTechniques, Settings};
use shine_scene::Scene;
use std::str::FromStr;

const SIZE: u32 = 128;

fn raster(component: Component) -> shine::capture::image_io::HdrImage {
    let gi = if component == Component::Direct {
        GiTechniques::none()
    } else {
        Settings::default().gi
    };
    raster_with(component, gi)
}

fn raster_with(component: Component, gi: GiTechniques) -> shine::capture::image_io::HdrImage {
    let device = common::device();
    let scene = Scene::builtin("cornell-box").expect("scene");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("upload");
    let mut settings = Settings {
        width: SIZE,
        height: SIZE,
        gi,
        ..Settings::default()
    };
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
        light_sampling: true,
        seed: 0,
        primary_specular: None,
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

/// HVL and IGI one-bounce indirect light (default settings: 400 HVLs by flux, receivers at
/// 1/2, 8 sampled shadow rays, a traced near field; 256 VPLs by flux, 4×4 sets) against the path-traced one-bounce
/// indirect light of the same lamp, by relative RMSE (RMSE / mean of the reference) and
/// energy ratio: HVL within 5% of the truth's energy (issue 16's bar), IGI within 8% (its
/// VPL footprint, issue 43, trades light near the VPLs for stillness). The reference has 64
/// spp; its own noise adds about 0.2 to the relative RMSE (docs/quality.md has the 1024-spp
/// numbers).
#[test]
fn indirect_light_against_the_path_traced_reference() {
    let reference = reference(1, 64);
    // (technique, largest relative RMSE, energy range). Measured on lavapipe against this
    // 64-spp reference: HVL 0.485 / 0.992 (unshadowed, without the near field 0.536 / 1.120),
    // IGI 0.530 / 0.943 (before the samples had identities, issue 43: HVL 0.474 / 0.992, IGI
    // 0.547 / 0.966).
    let cases = [("hvl", 0.56, 0.95..=1.05), ("igi", 0.6, 0.92..=1.05)];
    for (name, worst, energy) in cases {
        let gi = GiTechniques::from_str(name).expect("technique");
        let image = raster_with(Component::Indirect, gi);
        let c = compare(&image, &reference.indirect).expect("compare");
        println!(
            "{name} indirect: relative RMSE {:.4}, energy {:.4}, FLIP {:.4}",
            c.relative_rmse, c.energy_ratio, c.flip
        );
        assert!(c.relative_rmse <= worst, "{name}: {c:?}");
        assert!(energy.contains(&c.energy_ratio), "{name}: {c:?}");
    }
    // HVL per surface (issue 16): every wall and the ceiling within 15% of the truth's energy,
    // the floor (with the box tops, which face the same way) within 20%. Measured: 0.83 (floor
    // and box tops) to 1.02; the floor's light comes from the few HVLs on the grazed walls and
    // box sides, so it moves with their pattern: 0.87 with the earlier Hammersley pattern,
    // 0.79 with Halton points, 0.83 with the Sobol (0, 2)-sequence (issue 43). Unshadowed and
    // without the near field the walls reached 1.33 and the floor 1.42, shadowed without the
    // near field the floor 0.80.
    let normals = raster_with(
        Component::Normal,
        GiTechniques::from_str("hvl").expect("hvl"),
    );
    let image = raster_with(
        Component::Indirect,
        GiTechniques::from_str("hvl").expect("hvl"),
    );
    let surfaces = surface_metrics(&image, &reference.indirect, &normals, None).expect("surfaces");
    let axis_aligned: Vec<_> = surfaces
        .iter()
        .filter(|s| s.normal.iter().any(|c| c.abs() > 0.99))
        .collect();
    assert_eq!(
        axis_aligned.len(),
        5,
        "floor, ceiling and three walls: {surfaces:?}"
    );
    for s in axis_aligned {
        println!("hvl surface {:?}: energy {:.3}", s.normal, s.energy_ratio);
        let lowest = if s.normal[1] > 0.99 { 0.8 } else { 0.85 };
        assert!((lowest..=1.15).contains(&s.energy_ratio), "{s:?}");
    }
}

/// `output.component = "position"` shows each pixel's world position, and with it
/// `surface_pixels` parts parallel planes: the Cornell box's floor and the short box's top
/// (the tall one's is above the eye) both face up. By their normals alone they are one
/// surface, which holds pixels at the box top's height; with the positions the floor keeps
/// only its own, every one at y = 0 (where the scene builds it) within 1 cm, 1% of the box's
/// diagonal, and the box top falls under the 1% share of pixels a surface needs. Its
/// `geometric-normal` image equals the shading normals' (no normal maps).
#[test]
fn positions_part_the_floor_from_the_box_tops() {
    let normals = raster_with(Component::Normal, GiTechniques::none());
    let positions = raster_with(Component::Position, GiTechniques::none());
    let up = |surfaces: Vec<SurfacePixels>| -> Vec<SurfacePixels> {
        surfaces
            .into_iter()
            .filter(|s| s.normal[1] > 0.99)
            .collect()
    };
    let heights = |s: &SurfacePixels| -> (f32, f32) {
        let ys = s.pixels.iter().map(|&i| positions.texels[i][1]);
        (
            ys.clone().fold(f32::MAX, f32::min),
            ys.fold(f32::MIN, f32::max),
        )
    };
    let alone = up(surface_pixels(&normals, None).expect("surfaces"));
    let parted = up(surface_pixels(&normals, Some(&positions)).expect("surfaces"));
    assert_eq!((alone.len(), parted.len()), (1, 1), "{alone:?} {parted:?}");
    let (low, high) = heights(&alone[0]);
    let (floor_low, floor_high) = heights(&parted[0]);
    println!(
        "up-facing: {} px at y {low:.3}..{high:.3} by normals, {} px at y {floor_low:.4}..{floor_high:.4} with positions",
        alone[0].pixels.len(),
        parted[0].pixels.len()
    );
    assert!(high > 0.1, "the box top joins the floor by normals alone");
    assert!(parted[0].pixels.len() < alone[0].pixels.len());
    assert!(
        floor_low.abs() < 1e-3 && floor_high < 0.01,
        "{floor_low}..{floor_high}"
    );
    // The Cornell box has no normal maps: its geometric normals are its shading normals.
    let geometric = raster_with(Component::GeometricNormal, GiTechniques::none());
    let apart = normals
        .texels
        .iter()
        .zip(&geometric.texels)
        .map(|(a, b)| (0..3).map(|c| (a[c] - b[c]).abs()).fold(0.0, f32::max))
        .fold(0.0, f32::max);
    assert!(apart < 2e-3, "geometric and shading normals {apart} apart");
}

/// Paper 002's frame (`--gi proxy`: the sky shadowed by the sphere proxies plus their indirect
/// light) of the `spheres` scene against the path-traced reference of the same scene with the
/// proxies' real meshes, lit by the same sky, one bounce; both show the sky behind the scene.
/// Compared where the raster frame is not black, which now leaves out almost nothing: the
/// fully metallic torus, black under paper 002's Lambert receivers, reflects the sky through
/// the specular pass (issue 21), and is compared with the rest.
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
    // The metal torus's reflections: enough rays that their noise does not hide the bias.
    settings.specular.samples = 16;
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
        light_sampling: true,
        seed: 0,
        primary_specular: None,
    };
    let reference = render_reference(&device, &scene, 0.0, &params, 256).expect("reference");
    common::assert_clean(&device);
    let shaded = |t: &[f32; 4]| t[0] + t[1] + t[2] > 0.0;
    let masked = frame.texels.iter().filter(|t| !shaded(t)).count();
    assert!(
        masked < (SIDE * SIDE / 100) as usize,
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
    // Measured on lavapipe (64², 256 spp): PSNR 31.1 dB (brute force 31.3), SSIM 0.961,
    // mean 0.992× the reference, 1 pixel masked (before the specular pass: 32.4 dB without the
    // torus, whose 136 pixels were black).
    assert!(
        splat.psnr > 30.0 && splat.ssim > 0.94,
        "PSNR {} SSIM {}",
        splat.psnr,
        splat.ssim
    );
    assert!((0.85..1.15).contains(&ratio), "mean ratio {ratio}");
    assert!(exact.psnr > 30.0, "brute force PSNR {}", exact.psnr);
}
