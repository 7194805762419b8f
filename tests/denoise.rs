//! The traced signals' denoiser (`denoise_prep`, `denoise_atrous`; issue 47) on the Vulkan
//! device (lavapipe in CI) against its CPU twin (`shine::reference::denoise`), with the
//! validation layer reporting zero messages, on a synthetic G-buffer: a floor and a wall of
//! gold, mirror-smooth, rough, fading and untraced columns, a noisy specular signal with
//! fireflies; and (the `diffuse` variant: the sky's and the near field's light) the same
//! floor and wall as receivers, matte in two colours, under a noisy light that steps at the
//! wall's edge.
//!
//! - GPU == twin within 2% of the pixel's value plus the image's mean (both round the signal
//!   to f16 between iterations; 0.3% at worst when written, 1.7% since the lone firefly below
//!   was added: that pixel alone, whose neighbours come in through the luminance weight's
//!   tail, where the f16 roundings of three iterations add up).
//! - A mirror column (footprint under half a pixel) keeps every pixel as traced, bit for bit
//!   (sharp stays sharp), its bright pixel too: a mirror's rays agree, so it is a highlight,
//!   not a firefly.
//! - A lone firefly on the rough floor is gone, also one on the wall whose roughness fails
//!   every neighbour's roughness test (a tile's edge); a mirror pixel's glint among rough ones
//!   stays;
//!   the rough region's mean is kept within 5% (the clamp's loss stated); the error against
//!   the noise-free signal falls more than 2.5×.
//! - Untraced and background pixels are 0.
//! - Diffuse: GPU == twin within the same 2%, in the sky's footprint (pixels) and the near
//!   field's (hit distances); in the sky's, kd comes back per receiver (the colours' checker
//!   stays sharp); the error against the noise-free light falls more than 2.5× with the floor's
//!   and the wall's means within 3%; next to the edge neither side takes the other's light
//!   (within 10% of its own).

mod common;

use common::{
    assert_clean, bytes_f16, bytes_unorm8, decode_rgba16f, device, hash01, q16, read_by_copy,
    run_graph, storage_image_with, transfer_storage, uploaded_state,
};
use glam::{Mat4, Vec3, Vec4};
use shine::graph::{Executor, ExternalState, Handle, Image, ImageDesc, RenderGraph, vk};
use shine::passes::denoise::{self, DenoiseParams, Footprint, pixel_angle};
use shine::passes::gbuffer::{GBuffer, View};
use shine::passes::receivers::Receivers;
use shine::reference::denoise::{Guide, Signal, atrous, prep};

const W: u32 = 40;
const H: u32 = 32;
const EYE: Vec3 = Vec3::new(0.0, 1.0, 4.0);
const FOV: f32 = 0.8;
const LIMIT: f32 = 0.5;
const GOLD: Vec4 = Vec4::new(1.0, 0.78, 0.34, 1.0);

/// Roughness of column x: mirror, rough, fading out, untraced.
fn roughness(x: u32) -> f32 {
    match x {
        0..10 => 0.04,
        10..30 => 0.3,
        30..35 => 0.45,
        _ => 0.8,
    }
}

/// The synthetic frame: G-buffer texels and the specular pass's output (rgb, a parallax).
struct Frame {
    position: Vec<Vec4>,
    normal: Vec<Vec4>,
    albedo: Vec<Vec4>,
    material: Vec<Vec4>,
    specular: Vec<Vec4>,
}

/// A firefly on the rough wall whose own roughness (0.38, a tile's edge) fails every
/// neighbour's roughness test.
const LONE_FIREFLY: (u32, u32) = (16, 10);
/// A polished glint on the rough wall: a mirror pixel (0.04) holding a light's highlight, ten
/// times its rough neighbours.
const GLINT: (u32, u32) = (24, 10);

/// Roughness of pixel (x, y): its column's, but [`LONE_FIREFLY`]'s and [`GLINT`]'s.
fn roughness_at(x: u32, y: u32) -> f32 {
    match (x, y) {
        LONE_FIREFLY => 0.38,
        GLINT => 0.04,
        _ => roughness(x),
    }
}

/// The pixel (x, y) of a floor (y = 0) below a wall (z = −2), seen from EYE; row 0 is
/// background. Firefly pixels: (20, 24) on the rough floor, (4, 26) on the mirror floor (kept:
/// a sharp footprint is never clamped),
/// [`LONE_FIREFLY`] on the wall; and the [`GLINT`].
fn frame() -> Frame {
    let mut f = Frame {
        position: Vec::new(),
        normal: Vec::new(),
        albedo: Vec::new(),
        material: Vec::new(),
        specular: Vec::new(),
    };
    let t = (0.5 * FOV).tan();
    for y in 0..H {
        for x in 0..W {
            let u = (2.0 * (x as f32 + 0.5) / W as f32 - 1.0) * t * W as f32 / H as f32;
            let v = (1.0 - 2.0 * (y as f32 + 0.5) / H as f32) * t;
            let dir = Vec3::new(u, v, -1.0).normalize();
            let to_wall = (-2.0 - EYE.z) / dir.z;
            let to_floor = if dir.y < 0.0 {
                -EYE.y / dir.y
            } else {
                f32::MAX
            };
            let (hit, n) = if to_floor < to_wall {
                (EYE + dir * to_floor, Vec3::Y)
            } else {
                (EYE + dir * to_wall, Vec3::Z)
            };
            let depth = if y == 0 {
                0.0
            } else {
                (hit - EYE).dot(Vec3::NEG_Z)
            };
            f.position.push(hit.extend(depth));
            f.normal.push(q16(n.extend(0.0)));
            f.albedo.push(GOLD);
            f.material
                .push(Vec4::new(roughness_at(x, y), 1.0, 0.0, 0.0));
            let smooth = smooth(x, n);
            let noise = 0.4 + 1.2 * hash01(y * W + x);
            let firefly = match (x, y) {
                (20, 24) | (4, 26) | LONE_FIREFLY => 40.0,
                GLINT => 10.0,
                _ => 1.0,
            };
            let value = GOLD.truncate() * smooth * noise * firefly;
            // The hits' parallax varies about the least one the footprint takes.
            let parallax = 0.2 + 0.8 * hash01(y * W + x + 7919);
            f.specular.push(q16(value.extend(parallax)));
        }
    }
    f
}

/// The noise-free specular's scale at column x on a surface of normal n.
fn smooth(x: u32, n: Vec3) -> f32 {
    0.4 + 0.3 * (x as f32 * 0.2).sin() + 0.2 * n.y
}

fn view() -> View {
    View {
        view: Mat4::look_at_rh(EYE, EYE + Vec3::NEG_Z, Vec3::Y),
        proj: Mat4::perspective_rh(FOV, W as f32 / H as f32, 0.1, 100.0),
        eye: EYE,
        orthographic: false,
        extent: FOV,
    }
}

/// The denoiser's output on the device: `f`'s G-buffer and `input` uploaded, `filter` adding
/// the passes over them (position, normal, albedo, material, input).
fn run_on_device(
    f: &Frame,
    input: &[Vec4],
    filter: impl FnOnce(&mut RenderGraph, [Handle<Image>; 5]) -> Handle<Image>,
) -> Vec<Vec4> {
    let device = device();
    let e = [W, H];
    let rgba16 = vk::Format::R16G16B16A16_SFLOAT;
    let images = [
        storage_image_with(
            &device,
            "gb_position",
            vk::Format::R32G32B32A32_SFLOAT,
            e,
            bytemuck::cast_slice(&f.position),
        ),
        storage_image_with(&device, "gb_normal", rgba16, e, &bytes_f16(&f.normal)),
        storage_image_with(
            &device,
            "gb_albedo",
            vk::Format::R8G8B8A8_UNORM,
            e,
            &bytes_unorm8(&f.albedo),
        ),
        storage_image_with(
            &device,
            "gb_material",
            vk::Format::R8G8B8A8_UNORM,
            e,
            &bytes_unorm8(&f.material),
        ),
        storage_image_with(&device, "input", rgba16, e, &bytes_f16(input)),
    ];
    let readback = transfer_storage(&device, "readback", u64::from(W * H) * 8, None);
    let mut executor = Executor::new(&device, 1).expect("executor");
    let mut rg: RenderGraph = executor.begin_frame();
    let handles = images
        .each_ref()
        .map(|i| rg.import_gpu_image(i, uploaded_state(), ExternalState::UNDEFINED));
    let out = filter(&mut rg, handles);
    let mut back = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_image_to_buffer("read denoised", &out, &mut back);
    run_graph(&device, &mut executor, rg);
    let texels = decode_rgba16f(&device.read_buffer(&readback).expect("read"));
    assert_clean(&device);
    texels
}

/// The specular denoiser's output on the device.
fn gpu(f: &Frame, params: &DenoiseParams) -> Vec<Vec4> {
    run_on_device(
        f,
        &f.specular,
        |rg, [position, normal, albedo, material, specular]| {
            let rgba16 = vk::Format::R16G16B16A16_SFLOAT;
            let mut unused =
                |name: &str, format| rg.create_image(name, ImageDesc::new_2d(format, W, H));
            let g = GBuffer {
                position,
                normal,
                albedo,
                material,
                emissive: unused("unused emissive", rgba16),
                geometric_normal: unused("unused geometric normal", rgba16),
                motion: unused("unused motion", shine::passes::gbuffer::MOTION_FORMAT),
                depth: unused("unused depth", vk::Format::D32_SFLOAT),
                extent: [W, H],
            };
            denoise::specular(rg, &g, &specular, &view(), LIMIT, params).expect("denoise")
        },
    )
}

/// The twin of `signal` over `input` (the diffuse one in `footprint`), rounding to f16 where
/// the device stores an image; the G-buffer as stored.
fn twin(
    f: &Frame,
    input: &[Vec4],
    signal: Signal,
    footprint: Footprint,
    params: &DenoiseParams,
) -> Vec<Vec4> {
    let unorm =
        |v: &[Vec4]| -> Vec<Vec4> { v.iter().map(|t| (*t * 255.0).round() / 255.0).collect() };
    let (albedo, material) = (unorm(&f.albedo), unorm(&f.material));
    let g = Guide {
        extent: [W, H],
        position: &f.position,
        normal: &f.normal,
        albedo: &albedo,
        material: &material,
        camera: EYE,
        limit: LIMIT,
        signal,
    };
    let (footprint, hit_scale, clamp) = match (signal, footprint) {
        (Signal::Specular, _) => (pixel_angle(&view(), H), 0.0, params.clamp),
        (Signal::Diffuse, Footprint::Pixels(r)) => (r, 0.0, false),
        (Signal::Diffuse, Footprint::HitDistance { scale, pixel_angle }) => {
            (pixel_angle, scale, false)
        }
    };
    let (signal, radii) = prep(&g, input, footprint, hit_scale, clamp);
    let mut signal: Vec<Vec4> = signal.into_iter().map(q16).collect();
    let radii: Vec<f32> = radii.into_iter().map(|r| q16(Vec4::splat(r)).x).collect();
    for i in 0..params.iterations {
        let last = i + 1 == params.iterations;
        signal = atrous(&g, &signal, &radii, 1 << i, last.then_some(input))
            .into_iter()
            .map(q16)
            .collect();
    }
    signal
}

fn index(x: u32, y: u32) -> usize {
    (y * W + x) as usize
}

#[test]
fn denoiser_matches_its_twin_and_keeps_mirrors_sharp() {
    let f = frame();
    let params = DenoiseParams::default();
    let got = gpu(&f, &params);
    let want = twin(
        &f,
        &f.specular,
        Signal::Specular,
        Footprint::Pixels(0.0),
        &params,
    );
    let mean = want.iter().map(|t| t.truncate().length()).sum::<f32>() / want.len() as f32;
    let mut worst = 0.0f32;
    for (i, (a, b)) in got.iter().zip(&want).enumerate() {
        let d = (a.truncate() - b.truncate()).length() / (b.truncate().length() + mean);
        assert!(d < 0.02, "pixel {i}: GPU {a} twin {b}");
        worst = worst.max(d);
    }
    eprintln!("worst relative difference GPU vs twin: {worst:.5}");

    // Untraced columns and the background row give 0.
    for y in 0..H {
        for x in 0..W {
            if y == 0 || roughness(x) > LIMIT {
                assert_eq!(got[index(x, y)].truncate(), Vec3::ZERO, "({x}, {y})");
            }
        }
    }
    // The mirror column keeps its pixels as traced, bit for bit, its bright one (4, 26) too:
    // r < ½ pixel there.
    for y in 1..H {
        for x in 0..10 {
            let (a, b) = (got[index(x, y)], f.specular[index(x, y)]);
            assert_eq!(a.truncate(), b.truncate(), "mirror ({x}, {y})");
        }
    }
}

#[test]
fn fireflies_go_and_the_rough_floor_is_smoothed_with_its_mean_kept() {
    let f = frame();
    let got = gpu(&f, &DenoiseParams::default());
    // The floor's rough columns, away from the firefly and the wall's edge.
    let floor: Vec<usize> = (22..H)
        .flat_map(|y| (12..28).map(move |x| index(x, y)))
        .filter(|&i| f.position[i].y.abs() < 1e-4 && i != index(20, 24))
        .collect();
    assert!(floor.len() > 100, "{} floor pixels", floor.len());
    let lum = |t: Vec4| t.truncate().dot(Vec3::new(0.2126, 0.7152, 0.0722));
    // The noise-free signal is GOLD · smooth (the noise factor's mean is 1).
    let truth: Vec<f32> = (0..W * H)
        .map(|i| lum(GOLD) * smooth(i % W, Vec3::Y))
        .collect();
    let stats = |v: &[Vec4]| {
        let n = floor.len() as f32;
        let m = floor.iter().map(|&i| lum(v[i]) / truth[i]).sum::<f32>() / n;
        let e = floor
            .iter()
            .map(|&i| (lum(v[i]) / truth[i] - 1.0).powi(2))
            .sum::<f32>()
            / n;
        (m, e.sqrt())
    };
    let (mean_in, noise_in) = stats(&f.specular);
    let (mean_out, noise_out) = stats(&got);
    eprintln!(
        "rough floor (over the truth): mean {mean_in:.4} -> {mean_out:.4}, rms error {noise_in:.4} -> {noise_out:.4}"
    );
    assert!(
        (mean_out / mean_in - 1.0).abs() < 0.05,
        "mean {mean_in} -> {mean_out}"
    );
    // 0.342 -> 0.116 when written: the filter spans a 3.4-pixel footprint here.
    assert!(
        noise_out < noise_in / 2.5,
        "rms error {noise_in} -> {noise_out}"
    );
    // The firefly (40× its neighbours) is cut to its neighbourhood.
    let firefly = lum(got[index(20, 24)]);
    assert!(
        firefly < 3.0 * mean_out,
        "firefly {firefly} against the mean {mean_out}"
    );
    // So is the one whose roughness no neighbour shares (the clamp bounds it by its smoother
    // neighbours on the same surface; by the roughness test alone it had none and stayed at
    // 40×), while the glint, a mirror pixel among rougher ones, keeps its highlight: a rougher
    // lobe cannot bound a narrower one.
    let lone = lum(got[index(LONE_FIREFLY.0, LONE_FIREFLY.1)]);
    let wall = lum(GOLD) * smooth(LONE_FIREFLY.0, Vec3::Z);
    assert!(
        lone < 3.0 * wall,
        "lone firefly {lone} against the noise-free wall's {wall}"
    );
    let glint = index(GLINT.0, GLINT.1);
    assert!(
        (got[glint].truncate() - f.specular[glint].truncate()).length()
            <= 0.01 * f.specular[glint].truncate().length(),
        "glint {} from {}",
        got[glint],
        f.specular[glint]
    );
    // Without the clamp the filter spreads it instead.
    let spread = gpu(
        &f,
        &DenoiseParams {
            clamp: false,
            ..DenoiseParams::default()
        },
    );
    assert!(
        lum(spread[index(20, 24)]) > firefly,
        "the clamp removed nothing"
    );
}

/// Albedo of receiver (x, y) in the diffuse test: a checker of 4-pixel squares in two colours.
fn checker(x: u32, y: u32) -> Vec4 {
    if (x / 4 + y / 4).is_multiple_of(2) {
        Vec4::new(0.8, 0.3, 0.2, 1.0)
    } else {
        Vec4::new(0.2, 0.5, 0.8, 1.0)
    }
}

/// The noise-free demodulated light (light / π) at column x on a surface of normal n: the
/// wall three times the floor, so the edge between them is a step.
fn diffuse_truth(x: u32, n: Vec3) -> f32 {
    let base = if n.y > 0.5 { 0.5 } else { 1.5 };
    base * (1.0 + 0.3 * (x as f32 * 0.2).sin())
}

/// The diffuse test's frame: `frame()`'s floor and wall, matte (metallic 0) in the checker's
/// colours, the light the truth times a noise factor of mean 1 (0.4..1.6); returns it, the
/// light, each receiver's kd and the noise-free outgoing light kd · truth.
fn diffuse_frame() -> (Frame, Vec<Vec4>, Vec<Vec3>, Vec<Vec3>) {
    let mut f = frame();
    let mut light = Vec::new();
    let mut kds = Vec::new();
    let mut truth = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let i = index(x, y);
            f.albedo[i] = checker(x, y);
            f.material[i].y = 0.0;
            let n = f.normal[i].truncate().normalize();
            let t = diffuse_truth(x, n);
            let noise = 0.4 + 1.2 * hash01(y * W + x + 104_729);
            // The near field's mean hit distance in alpha (the sky's pass writes 0 there).
            let hit = 0.05 + 0.5 * hash01(y * W + x + 15_485_863);
            light.push(q16(Vec3::splat(t * noise).extend(hit)));
            let albedo = (checker(x, y) * 255.0).round() / 255.0;
            let v = (EYE - f.position[i].truncate()).normalize();
            let (kd, _) =
                shine::passes::brdf_tables::indirect_weights(albedo.truncate(), 0.0, n.dot(v));
            let kd = if y == 0 { Vec3::ZERO } else { kd };
            kds.push(kd);
            truth.push(kd * t);
        }
    }
    (f, light, kds, truth)
}

/// The diffuse denoiser's output on the device in `footprint`, the frame's G-buffer as the
/// receivers.
fn gpu_diffuse(
    f: &Frame,
    light: &[Vec4],
    footprint: Footprint,
    params: &DenoiseParams,
) -> Vec<Vec4> {
    run_on_device(
        f,
        light,
        |rg, [position, normal, albedo, material, light]| {
            let receivers = Receivers {
                position,
                normal,
                albedo,
                material,
                extent: [W, H],
                scale: 1,
            };
            denoise::diffuse(
                rg,
                ["test_prep", "test_atrous", "test_light"],
                &receivers,
                &light,
                EYE,
                footprint,
                params,
            )
            .expect("denoise")
        },
    )
}

#[test]
fn diffuse_light_matches_its_twin_is_smoothed_and_keeps_edges_and_texture() {
    let (f, light, kd, truth) = diffuse_frame();
    let params = DenoiseParams::default();
    let sky = Footprint::Pixels(denoise::SKY_RADIUS);
    // The near field's footprint (its radius 1 to 16 pixels over this frame's hit distances).
    let near = Footprint::HitDistance {
        scale: denoise::NEAR_FOOTPRINT_PER_HIT,
        pixel_angle: pixel_angle(&view(), H),
    };
    let mut got = Vec::new();
    for footprint in [near, sky] {
        got = gpu_diffuse(&f, &light, footprint, &params);
        let want = twin(&f, &light, Signal::Diffuse, footprint, &params);
        let mean = want.iter().map(|t| t.truncate().length()).sum::<f32>() / want.len() as f32;
        let mut worst = 0.0f32;
        for (i, (a, b)) in got.iter().zip(&want).enumerate() {
            let d = (a.truncate() - b.truncate()).length() / (b.truncate().length() + mean);
            assert!(d < 0.02, "{footprint:?}, pixel {i}: GPU {a} twin {b}");
            worst = worst.max(d);
        }
        eprintln!("diffuse {footprint:?}: worst relative difference GPU vs twin: {worst:.5}");
    }
    // The rest on the sky's footprint.
    for x in 0..W {
        assert_eq!(
            got[index(x, 0)].truncate(),
            Vec3::ZERO,
            "background ({x}, 0)"
        );
    }

    // The raw frame is kd times the noisy light; both against kd times the truth.
    let lum = |v: Vec3| v.dot(Vec3::new(0.2126, 0.7152, 0.0722));
    let pixels: Vec<usize> = (W as usize..(W * H) as usize).collect();
    let error = |v: &dyn Fn(usize) -> Vec3| {
        let e: f32 = pixels
            .iter()
            .map(|&i| (v(i) - truth[i]).length_squared() / truth[i].length_squared())
            .sum();
        (e / pixels.len() as f32).sqrt()
    };
    let raw = error(&|i| kd[i] * light[i].truncate());
    let filtered = error(&|i| got[i].truncate());
    eprintln!("diffuse: relative rms error {raw:.4} -> {filtered:.4}");
    assert!(filtered < raw / 2.5, "rms error {raw} -> {filtered}");

    // Each surface keeps its mean, and next to the edge neither side takes the other's light.
    let floor = |i: usize| f.normal[i].y > 0.5;
    let ratio = |keep: &dyn Fn(usize) -> bool| {
        let (mut a, mut b) = (0.0f32, 0.0f32);
        for &i in pixels.iter().filter(|&&i| keep(i)) {
            a += lum(got[i].truncate());
            b += lum(truth[i]);
        }
        a / b
    };
    let (floor_mean, wall_mean) = (ratio(&|i| floor(i)), ratio(&|i| !floor(i)));
    eprintln!("diffuse: mean over the truth, floor {floor_mean:.4}, wall {wall_mean:.4}");
    assert!((floor_mean - 1.0).abs() < 0.03, "floor mean {floor_mean}");
    assert!((wall_mean - 1.0).abs() < 0.03, "wall mean {wall_mean}");
    // The edge's rows: the floor's first two below the wall, the wall's last two above it.
    let edge = |i: usize, below: bool| {
        let (x, y) = (i as u32 % W, i as u32 / W);
        let other = |dy: i32| {
            let yy = y as i32 + dy;
            (1..H as i32).contains(&yy) && floor(index(x, yy as u32)) != floor(i)
        };
        (floor(i) == below) && (other(-1) || other(-2) || other(1) || other(2))
    };
    let (floor_edge, wall_edge) = (ratio(&|i| edge(i, true)), ratio(&|i| edge(i, false)));
    eprintln!("diffuse: at the edge, floor {floor_edge:.4}, wall {wall_edge:.4}");
    assert!(
        (floor_edge - 1.0).abs() < 0.1,
        "floor at the edge {floor_edge}"
    );
    assert!(
        (wall_edge - 1.0).abs() < 0.1,
        "wall at the edge {wall_edge}"
    );
}
