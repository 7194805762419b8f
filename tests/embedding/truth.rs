//! The path-traced truth of the host bench's frame 0, in chunks whose spread estimates its own
//! noise, and an image's error against it with that noise taken out.

use super::gi_context::{Bench, EXTENT, rgb};
use shine::reference::{PathTracer, ReferenceParams};
use shine::study::metrics::{TruthAccumulator, image_error, mean_over};
use shine::{CameraPose, FrameUpdate};

/// Samples per pixel of each chunk of the path-traced truth.
const CHUNK_SPP: u32 = 128;
/// Chunks of the truth: their spread estimates the truth's own noise, which is taken out of
/// every error (`TruthAccumulator::noise_mse`).
const CHUNKS: u32 = 8;

/// The path-traced one-bounce indirect light from the bench's camera of frame 0, in chunks;
/// `primary_specular`: the truth of the specular output at that `specular.limit`
/// (`ReferenceParams::primary_specular`).
pub fn truth(bench: &Bench, primary_specular: Option<f32>) -> TruthAccumulator {
    let params = ReferenceParams {
        width: EXTENT[0],
        height: EXTENT[1],
        bounces: 1,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        light_sampling: true,
        seed: 0,
        primary_specular,
    };
    let mut tracer = PathTracer::new(bench.device(), &bench.scene, 0.0, &params).expect("tracer");
    let camera = bench.camera(0);
    tracer
        .update(&FrameUpdate {
            camera: Some(CameraPose {
                world: camera.view.inverse(),
                projection: bench.scene.cameras[0].projection,
            }),
            ..FrameUpdate::default()
        })
        .expect("camera");
    let pixels = (EXTENT[0] * EXTENT[1]) as usize;
    let mut truth = TruthAccumulator::new(pixels);
    let mut previous = vec![[0.0f32; 3]; pixels];
    for k in 1..=CHUNKS {
        tracer.accumulate(CHUNK_SPP).expect("trace");
        // The running mean of k chunks; chunk k is k·mean_k − (k − 1)·mean_(k−1).
        let mean = rgb(tracer.read().expect("read").indirect.texels);
        let chunk: Vec<[f32; 3]> = mean
            .iter()
            .zip(&previous)
            .map(|(m, p)| [0, 1, 2].map(|c| k as f32 * m[c] - (k - 1) as f32 * p[c]))
            .collect();
        truth.add(&chunk);
        previous = mean;
    }
    truth
}

/// Relative RMSE with the truth's noise taken out, and the energy ratio, of `image` over the
/// pixels of `mask`.
pub fn error_over(image: &[[f32; 3]], truth: &TruthAccumulator, mask: &[bool]) -> (f64, f64) {
    let mean = truth.mean();
    let e = image_error(image, &mean, mask).expect("signal");
    let noise = truth.noise_mse(mask).expect("chunks");
    let signal = mean_over(&mean, mask);
    ((e.mse - noise).max(0.0).sqrt() / signal, e.energy_ratio)
}

/// [`error_over`] every pixel.
pub fn error_of(image: &[[f32; 3]], truth: &TruthAccumulator) -> (f64, f64) {
    error_over(image, truth, &vec![true; image.len()])
}
