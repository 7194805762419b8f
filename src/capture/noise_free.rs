//! Errors against a truth with its own noise taken out (issue 47): two path-traced references
//! A and B of independent seeds. The truth is their mean T = (A + B) / 2; its noise adds
//! σ²/2 per value to an image's mean squared error against T, and E[(A − B)²] = 2σ², so
//! `MSE_noise-free = MSE(X, T) − MSE(A, B) / 4` (floored at 0). A one-sample frame judged
//! against a 1024-spp truth is then judged on its own error, not the truth's grain.
//!
//! Channels are clamped to [0, 1] and NaN read as 0, as every metric of
//! [`crate::capture::image_compare`] sees them.
//!
//! Also the tail of the per-pixel error: the q-th percentile of |X − T| (mean of the three
//! channels) over the pixels, relative to T's mean there: speckles, which the RMSE averages
//! away.

use crate::capture::image_compare::{CompareError, check, clamped};
use crate::capture::image_io::HdrImage;

/// The metrics of an image against a two-seed truth over a set of pixels.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct NoiseFree {
    /// Pixels measured.
    pub pixels: usize,
    /// Mean of the truth T over the pixels and channels.
    pub truth_mean: f64,
    /// Σ image / Σ T.
    pub energy_ratio: f64,
    /// RMSE against T over T's mean, the truth's noise included.
    pub relative_rmse: f64,
    /// The same with the truth's noise subtracted.
    pub noise_free_relative_rmse: f64,
    /// RMSE between the two seeds over T's mean: the truth's own noise (its share in T is half
    /// of this).
    pub truth_noise: f64,
    /// The [`PERCENTILE`]th percentile of the per-pixel |image − T| over T's mean.
    pub error_percentile: f64,
}

/// The percentile of the per-pixel error reported ([`NoiseFree::error_percentile`]).
pub const PERCENTILE: f64 = 99.9;

/// The mean of the two seeds, T.
pub fn truth(a: &HdrImage, b: &HdrImage) -> Result<HdrImage, CompareError> {
    check(a, b)?;
    let texels = a
        .texels
        .iter()
        .zip(&b.texels)
        .map(|(x, y)| std::array::from_fn(|c| 0.5 * (x[c] + y[c])))
        .collect();
    Ok(HdrImage {
        width: a.width,
        height: a.height,
        texels,
    })
}

/// [`NoiseFree`] of `image` against seeds `a` and `b` over `pixels` (indices; every pixel when
/// `None`). An empty set is [`CompareError::EmptyMask`].
pub fn noise_free(
    image: &HdrImage,
    a: &HdrImage,
    b: &HdrImage,
    pixels: Option<&[usize]>,
) -> Result<NoiseFree, CompareError> {
    check(image, a)?;
    check(a, b)?;
    let n = image.width as usize * image.height as usize;
    if let Some(&i) = pixels.and_then(|p| p.iter().find(|&&i| i >= n)) {
        return Err(CompareError::PixelOutOfRange(i, n));
    }
    let all: Vec<usize>;
    let pixels = match pixels {
        Some(p) => p,
        None => {
            all = (0..image.texels.len()).collect();
            &all
        }
    };
    if pixels.is_empty() {
        return Err(CompareError::EmptyMask);
    }
    let (mut sum_x, mut sum_t, mut squared, mut seeds) = (0.0, 0.0, 0.0, 0.0);
    let mut errors = Vec::with_capacity(pixels.len());
    for &i in pixels {
        let mut error = 0.0;
        for c in 0..3 {
            let (x, ya, yb) = (
                clamped(image.texels[i][c]),
                clamped(a.texels[i][c]),
                clamped(b.texels[i][c]),
            );
            let t = 0.5 * (ya + yb);
            sum_x += x;
            sum_t += t;
            squared += (x - t) * (x - t);
            seeds += (ya - yb) * (ya - yb);
            error += (x - t) / 3.0;
        }
        errors.push(error.abs());
    }
    let values = 3.0 * pixels.len() as f64;
    let mean = sum_t / values;
    let mse = squared / values;
    let seed_mse = seeds / values;
    errors.sort_by(f64::total_cmp);
    let rank = ((PERCENTILE / 100.0) * (errors.len() - 1) as f64).round() as usize;
    Ok(NoiseFree {
        pixels: pixels.len(),
        truth_mean: mean,
        energy_ratio: sum_x / sum_t,
        relative_rmse: mse.sqrt() / mean,
        noise_free_relative_rmse: (mse - 0.25 * seed_mse).max(0.0).sqrt() / mean,
        truth_noise: seed_mse.sqrt() / mean,
        error_percentile: errors[rank] / mean,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(values: &[f32]) -> HdrImage {
        HdrImage {
            width: values.len() as u32,
            height: 1,
            texels: values.iter().map(|&v| [v, v, v, 1.0]).collect(),
        }
    }

    #[test]
    fn the_truths_noise_is_taken_out() {
        // Truth 0.5 everywhere (inside the metrics' dynamic range); seeds 0.5 ± 0.1; an image
        // off by 0.05 everywhere.
        let n = 1000;
        let a: Vec<f32> = (0..n).map(|i| if i % 2 == 0 { 0.6 } else { 0.4 }).collect();
        let b: Vec<f32> = (0..n).map(|i| if i % 4 < 2 { 0.4 } else { 0.6 }).collect();
        let x = vec![0.55f32; n];
        let m = noise_free(&image(&x), &image(&a), &image(&b), None).expect("metrics");
        // T = (A + B)/2 is 0.5, 0.4, 0.6, 0.5: MSE(X, T) = 0.0075, MSE(A, B)/4 = 0.02/4, so the
        // noise-free RMSE is 0.05, a tenth of the mean.
        assert!((m.noise_free_relative_rmse - 0.1).abs() < 1e-6, "{m:?}");
        assert!(m.relative_rmse > 0.17, "{m:?}");
        assert!((m.energy_ratio - 1.1).abs() < 1e-6);
    }

    #[test]
    fn the_percentile_sees_a_speckle_the_rmse_averages_away() {
        let truth = vec![0.02f32; 2000];
        let mut x = truth.clone();
        x[7] = 0.9;
        x[1000] = 0.8;
        x[1500] = 0.85;
        let m = noise_free(&image(&x), &image(&truth), &image(&truth), None).expect("metrics");
        assert!(m.error_percentile > 30.0, "{m:?}");
        let few = [0usize, 1, 2, 3];
        let clean = noise_free(&image(&x), &image(&truth), &image(&truth), Some(&few));
        assert_eq!(clean.expect("metrics").error_percentile, 0.0);
        assert!(noise_free(&image(&x), &image(&truth), &image(&truth), Some(&[])).is_err());
        let outside = noise_free(&image(&x), &image(&truth), &image(&truth), Some(&[2000]));
        assert_eq!(outside, Err(CompareError::PixelOutOfRange(2000, 2000)));
    }
}
