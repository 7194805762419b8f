//! Antialiasing (issue 21, item 2): a supersampled frame (`output.ssaa`) is the box average of
//! the frame rendered at the larger size, and its edges are smoother than the plain frame's.

mod common;

use shine::capture::image_io::{HdrImage, LdrImage};
use shine::frame::renderer::FrameImage;
use shine::{Renderer, Settings};
use shine_scene::Scene;

/// A frame of `scene` at `size`×`size` with `gi` and `ssaa`.
fn frame(device: &shine::gpu::Device, scene: &Scene, size: u32, gi: &str, ssaa: u32) -> FrameImage {
    let mut s = Settings {
        width: size,
        height: size,
        ..Settings::default()
    };
    s.set("gi", gi).expect("gi");
    s.set("shadow.size", "256").expect("shadow");
    s.set("texture.mipmaps", "false").expect("mipmaps");
    s.set("output.ssaa", &ssaa.to_string()).expect("ssaa");
    // the LDR frames are compared: one fixed exposure for all of them
    s.set("output.auto_exposure", "false").expect("exposure");
    let mut renderer = Renderer::new(device).expect("renderer");
    renderer.set_scene(scene, 0.0).expect("scene");
    renderer.render(&s).expect("render")
}

/// `image` box-filtered by `n` along each axis.
fn box_down(image: &HdrImage, n: u32) -> Vec<[f32; 3]> {
    let (w, h) = (image.width / n, image.height / n);
    (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let mut sum = [0.0f32; 3];
            for j in 0..n {
                for i in 0..n {
                    let t = image.texels[((y * n + j) * image.width + x * n + i) as usize];
                    for c in 0..3 {
                        sum[c] += t[c];
                    }
                }
            }
            sum.map(|v| v / (n * n) as f32)
        })
        .collect()
}

/// At `ssaa = 2`, a 32×32 frame of the room is the 2×2 box average of the 64×64 frame (every
/// pass renders at the larger size; the composite averages before tonemapping), with and
/// without GI, to float rounding; and it differs from the plain 32×32 frame at the edges.
#[test]
fn a_supersampled_frame_is_the_box_average_of_the_larger_frame() {
    let device = common::device();
    let scene = Scene::builtin("room").expect("scene");
    for gi in ["none", "hvl"] {
        let large = frame(&device, &scene, 64, gi, 1).hdr;
        let supersampled = frame(&device, &scene, 32, gi, 2).hdr;
        let plain = frame(&device, &scene, 32, gi, 1).hdr;
        let expected = box_down(&large, 2);
        let mean = expected.iter().flatten().sum::<f32>() / (3 * expected.len()) as f32;
        let (mut worst, mut changed) = (0.0f32, 0.0f32);
        for (k, e) in expected.iter().enumerate() {
            for (c, e) in e.iter().enumerate() {
                worst = worst.max((supersampled.texels[k][c] - e).abs());
                changed = changed.max((plain.texels[k][c] - e).abs());
            }
        }
        assert!(
            worst <= 1e-5 * mean.max(1.0),
            "{gi}: worst {worst}, mean {mean}"
        );
        assert!(
            changed > 0.05 * mean,
            "{gi}: the plain frame equals the supersampled one"
        );
    }
    common::assert_clean(&device);
}

/// RMS of `a - b` over the mean of `b` (rgb of the tonemapped frames: how aliasing is seen,
/// and the sun's and lamps' HDR peaks do not swamp the edges).
fn relative_rmse(a: &LdrImage, b: &LdrImage) -> f32 {
    let (mut se, mut sum) = (0.0f64, 0.0f64);
    for (x, y) in a.texels.iter().zip(&b.texels) {
        for c in 0..3 {
            se += (f64::from(x[c]) - f64::from(y[c])).powi(2);
            sum += f64::from(y[c]);
        }
    }
    let n = (3 * b.texels.len()) as f64;
    ((se / n).sqrt() / (sum / n)) as f32
}

/// TAA on a static scene converges towards the supersampled frame: over the last jitter cycle
/// of 24 frames of the room (32×32, direct light, textures without mipmaps so that they alias
/// too), its mean error against the 4×4-supersampled frame is at most 0.7× the plain frame's
/// (measured: about 0.6×). With mipmaps, TAA samples them one level finer than a frame, not as
/// fine as 4×4 supersampling does: a difference of filter, not of aliasing (docs/quality.md).
#[test]
fn taa_on_a_static_scene_converges_to_the_supersampled_frame() {
    let device = common::device();
    let scene = Scene::builtin("room").expect("scene");
    let reference = frame(&device, &scene, 32, "none", 4).ldr;
    let plain = frame(&device, &scene, 32, "none", 1).ldr;
    let mut s = Settings {
        width: 32,
        height: 32,
        ..Settings::default()
    };
    s.set("gi", "none").expect("gi");
    s.set("shadow.size", "256").expect("shadow");
    s.set("texture.mipmaps", "false").expect("mipmaps");
    s.set("output.taa", "true").expect("taa");
    s.set("output.auto_exposure", "false").expect("exposure");
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(&scene, 0.0).expect("scene");
    let mut errors = Vec::new();
    for _ in 0..24 {
        let image = renderer.render(&s).expect("render").ldr;
        errors.push(relative_rmse(&image, &reference));
    }
    let plain_error = relative_rmse(&plain, &reference);
    eprintln!("plain {plain_error}, TAA frames {errors:?}");
    // A whole jitter cycle, the last 8 frames: their mean error.
    let cycle = errors[errors.len() - 8..].iter().sum::<f32>() / 8.0;
    assert!(
        cycle <= 0.7 * plain_error,
        "TAA {cycle} against plain {plain_error}"
    );
    common::assert_clean(&device);
}
