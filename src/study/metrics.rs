//! The study's numbers: the truth as a running mean of independent estimates (with the noise
//! left in it), an image's error against it, and equal-error interpolation on a log-log curve.
//!
//! Definitions (over the `mask`: pixels that are not background):
//!
//! - MSE: the mean over pixels and the three channels of `(x − t)²`.
//! - Relative RMSE: `√MSE / mean(t)`, `mean(t)` the mean over pixels and channels of the truth.
//! - Energy ratio: `Σ x / Σ t` over pixels and channels.
//! - The truth's noise: the truth is the mean of `K` equal chunks; the variance of that mean is
//!   estimated per pixel and channel as `Σ (c_k − c̄)² / (K (K − 1))`, and its mean over the mask
//!   is `τ²`, the part of every method's MSE the truth's own noise adds (independent seeds).

/// A running mean of `K` images of equal weight with the per-texel second moment, for the truth.
#[derive(Debug, Clone)]
pub struct TruthAccumulator {
    sum: Vec<[f64; 3]>,
    sum_sq: Vec<[f64; 3]>,
    chunks: u32,
}

impl TruthAccumulator {
    /// An empty accumulator over `pixels` pixels.
    pub fn new(pixels: usize) -> Self {
        Self {
            sum: vec![[0.0; 3]; pixels],
            sum_sq: vec![[0.0; 3]; pixels],
            chunks: 0,
        }
    }

    /// Adds one chunk's image (the mean of its samples); its length must be the accumulator's.
    pub fn add(&mut self, image: &[[f32; 3]]) {
        for ((s, q), x) in self.sum.iter_mut().zip(&mut self.sum_sq).zip(image) {
            for c in 0..3 {
                let v = f64::from(x[c]);
                s[c] += v;
                q[c] += v * v;
            }
        }
        self.chunks += 1;
    }

    /// Chunks added.
    pub fn chunks(&self) -> u32 {
        self.chunks
    }

    /// The mean image (black before the first chunk).
    pub fn mean(&self) -> Vec<[f32; 3]> {
        let k = f64::from(self.chunks.max(1));
        self.sum.iter().map(|s| s.map(|v| (v / k) as f32)).collect()
    }

    /// Per pixel, the estimated variance of the mean image averaged over the three channels:
    /// where it is large against the pixel's value the truth has not converged there (a
    /// firefly); `None` with fewer than two chunks.
    pub fn pixel_noise(&self) -> Option<Vec<f64>> {
        if self.chunks < 2 {
            return None;
        }
        let k = f64::from(self.chunks);
        Some(
            self.sum
                .iter()
                .zip(&self.sum_sq)
                .map(|(s, q)| {
                    (0..3)
                        .map(|c| ((q[c] - s[c] * s[c] / k) / (k - 1.0)).max(0.0) / k)
                        .sum::<f64>()
                        / 3.0
                })
                .collect(),
        )
    }

    /// `τ²`: the mean over `mask` of the estimated variance of the mean image; `None` with
    /// fewer than two chunks.
    pub fn noise_mse(&self, mask: &[bool]) -> Option<f64> {
        if self.chunks < 2 {
            return None;
        }
        let k = f64::from(self.chunks);
        let (mut total, mut count) = (0.0, 0usize);
        for ((s, q), _) in self
            .sum
            .iter()
            .zip(&self.sum_sq)
            .zip(mask)
            .filter(|(_, m)| **m)
        {
            for c in 0..3 {
                let variance = ((q[c] - s[c] * s[c] / k) / (k - 1.0)).max(0.0);
                total += variance / k;
            }
            count += 3;
        }
        (count > 0).then(|| total / count as f64)
    }
}

/// An image's error against the truth over a mask.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImageError {
    /// Mean squared error over pixels and channels.
    pub mse: f64,
    /// `√MSE / mean(truth)`.
    pub relative_rmse: f64,
    /// `Σ image / Σ truth`.
    pub energy_ratio: f64,
}

/// The error of `image` against `truth` over the pixels where `mask` holds. `None` when the
/// mask is empty or the truth is black there (no relative error is defined).
pub fn image_error(image: &[[f32; 3]], truth: &[[f32; 3]], mask: &[bool]) -> Option<ImageError> {
    let (mut se, mut sum_x, mut sum_t, mut count) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for ((x, t), _) in image.iter().zip(truth).zip(mask).filter(|(_, m)| **m) {
        for c in 0..3 {
            let (x, t) = (f64::from(x[c]), f64::from(t[c]));
            se += (x - t) * (x - t);
            sum_x += x;
            sum_t += t;
        }
        count += 3;
    }
    if count == 0 || sum_t <= 0.0 {
        return None;
    }
    let n = count as f64;
    let mse = se / n;
    Some(ImageError {
        mse,
        relative_rmse: mse.sqrt() / (sum_t / n),
        energy_ratio: sum_x / sum_t,
    })
}

/// Where a curve reaches an error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The samples per pixel at which the curve has the error.
    pub spp: f64,
    /// Whether it lies outside the measured points (extrapolated at the Monte-Carlo rate).
    pub extrapolated: bool,
}

/// The spp at which a Monte-Carlo curve of `(spp, MSE)` points (spp increasing) reaches the MSE
/// `target`: log-log interpolation between the two measured points around it; outside them,
/// extrapolation from the nearest end at the Monte-Carlo rate (variance ∝ 1/spp) after taking
/// the truth's noise `noise_mse` out of both MSEs. `None` without points, or when the target is
/// below the truth's noise (no spp reaches it measurably).
pub fn equal_error_spp(points: &[(f64, f64)], target: f64, noise_mse: f64) -> Option<Crossing> {
    let valid: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|(n, e)| *n > 0.0 && *e > 0.0 && n.is_finite() && e.is_finite())
        .collect();
    let (&first, &last) = (valid.first()?, valid.last()?);
    if !(target.is_finite() && target > 0.0) {
        return None;
    }
    for pair in valid.windows(2) {
        let ((n0, e0), (n1, e1)) = (pair[0], pair[1]);
        if e0 >= target && target >= e1 {
            let spp = if e0 == e1 {
                n0
            } else {
                let f = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
                (n0.ln() + f * (n1.ln() - n0.ln())).exp()
            };
            return Some(Crossing {
                spp,
                extrapolated: false,
            });
        }
    }
    // Beyond the measured points: variance (MSE less the truth's noise) ∝ 1/spp.
    let (n, e) = if target > first.1 { first } else { last };
    let (signal, wanted) = (e - noise_mse, target - noise_mse);
    if signal <= 0.0 || wanted <= 0.0 {
        return None;
    }
    Some(Crossing {
        spp: n * signal / wanted,
        extrapolated: true,
    })
}

/// `y` at `x` on the polyline through `points` (x increasing), extended linearly beyond its
/// ends (time is affine in the sample count). `None` without points.
pub fn interpolate_linear(points: &[(f64, f64)], x: f64) -> Option<f64> {
    let (&first, &last) = (points.first()?, points.last()?);
    if points.len() == 1 {
        // One point: proportional.
        return Some(if first.0 > 0.0 {
            first.1 * x / first.0
        } else {
            first.1
        });
    }
    let pair = points
        .windows(2)
        .find(|p| x <= p[1].0)
        .map_or([points[points.len() - 2], last], |p| [p[0], p[1]]);
    let [(x0, y0), (x1, y1)] = pair;
    if x1 == x0 {
        return Some(y1);
    }
    Some(y0 + (x - x0) * (y1 - y0) / (x1 - x0))
}

/// The mean over `mask` and channels of `image`.
pub fn mean_over(image: &[[f32; 3]], mask: &[bool]) -> f64 {
    let (sum, count) = image
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .fold((0.0f64, 0usize), |(s, n), (t, _)| {
            (s + t.iter().map(|v| f64::from(*v)).sum::<f64>(), n + 3)
        });
    if count == 0 { 0.0 } else { sum / count as f64 }
}

/// The mean sample count over `mask`.
pub fn mean_samples(samples: &[f32], mask: &[bool]) -> f64 {
    let (sum, count) = samples
        .iter()
        .zip(mask)
        .filter(|(_, m)| **m)
        .fold((0.0f64, 0usize), |(s, n), (v, _)| {
            (s + f64::from(*v), n + 1)
        });
    if count == 0 { 0.0 } else { sum / count as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_of_a_scaled_image() {
        let truth = vec![[1.0, 2.0, 3.0], [5.0, 5.0, 5.0], [0.0; 3]];
        let image: Vec<[f32; 3]> = truth.iter().map(|t| t.map(|v| v * 1.1)).collect();
        let mask = [true, true, false];
        let e = image_error(&image, &truth, &mask).unwrap();
        assert!((e.energy_ratio - 1.1).abs() < 1e-6);
        let mse = [1.0f64, 4.0, 9.0, 25.0, 25.0, 25.0]
            .iter()
            .map(|v| v * 0.01)
            .sum::<f64>()
            / 6.0;
        assert!((e.mse - mse).abs() < 1e-6 * mse);
        assert!((e.relative_rmse - mse.sqrt() / (21.0 / 6.0)).abs() < 1e-6);
        assert!(image_error(&image, &truth, &[false; 3]).is_none());
    }

    #[test]
    fn truth_noise_of_two_chunks() {
        let mut acc = TruthAccumulator::new(1);
        acc.add(&[[1.0, 1.0, 1.0]]);
        acc.add(&[[3.0, 3.0, 3.0]]);
        assert_eq!(acc.mean(), vec![[2.0, 2.0, 2.0]]);
        // Sample variance 2, variance of the mean of two: 1.
        assert!((acc.noise_mse(&[true]).unwrap() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn equal_error_interpolates_log_log() {
        // MSE = 1/n exactly: the crossing of 1/8 is at 8 spp between 4 and 16.
        let points = [(1.0, 1.0), (4.0, 0.25), (16.0, 1.0 / 16.0)];
        let c = equal_error_spp(&points, 0.125, 0.0).unwrap();
        assert!((c.spp - 8.0).abs() < 1e-9 && !c.extrapolated);
        // Beyond the last point: 1/64 at 64 spp; with noise 0.01 in every MSE, the same.
        let c = equal_error_spp(&points, 1.0 / 64.0, 0.0).unwrap();
        assert!((c.spp - 64.0).abs() < 1e-9 && c.extrapolated);
        let noisy: Vec<_> = points.iter().map(|(n, e)| (*n, e + 0.01)).collect();
        let c = equal_error_spp(&noisy, 1.0 / 64.0 + 0.01, 0.01).unwrap();
        assert!((c.spp - 64.0).abs() < 1e-6 && c.extrapolated);
        // Below the truth's noise: unknown.
        assert!(equal_error_spp(&noisy, 0.005, 0.01).is_none());
        // Worse than 1 spp: below 1 spp.
        let c = equal_error_spp(&points, 2.0, 0.0).unwrap();
        assert!((c.spp - 0.5).abs() < 1e-9 && c.extrapolated);
    }

    #[test]
    fn linear_interpolation_and_extension() {
        let points = [(1.0, 2.0), (2.0, 3.0), (4.0, 5.0)];
        assert_eq!(interpolate_linear(&points, 3.0), Some(4.0));
        assert_eq!(interpolate_linear(&points, 8.0), Some(9.0));
        assert_eq!(interpolate_linear(&points, 0.0), Some(1.0));
        assert_eq!(interpolate_linear(&[(2.0, 4.0)], 3.0), Some(6.0));
        assert_eq!(interpolate_linear(&[], 3.0), None);
    }
}
