//! Circularly symmetric kernels as ZH vectors, convolution, and windowing against ringing.
//!
//! Kernels are functions `k(cos θ)` of the angle to +z; their ZH coefficients are
//! `k_l = 2π ∫ k(μ) Y_l0(μ) dμ`. Convolution (paper 002 eq. 7, docs/architecture.md "Conventions") is
//! `(f ⋆ k)_lm = sqrt(4π/(2l+1)) k_l f_lm`, so that `(f ⋆ k)(n) = ∫ f(s) k(n·s) ds`
//! (Funk–Hecke). All closed forms below use ratio recurrences (no factorials).

use crate::zonal::zh_factor;
use crate::{Result, ShError, bands_of_len, check_bands, check_range};

/// `∫_0^1 μ^n P_l(μ) dμ` for `l < out.len()`, real `n > -1`, via
/// `I_0 = 1/(n+1)`, `I_1 = 1/(n+2)`, `I_{l+2} = I_l (n-l)/(n+l+3)`.
fn hemisphere_power_moments(n: f64, out: &mut [f64]) {
    for l in 0..out.len() {
        out[l] = match l {
            0 => 1.0 / (n + 1.0),
            1 => 1.0 / (n + 2.0),
            _ => {
                let lm2 = (l - 2) as f64;
                out[l - 2] * (n - lm2) / (n + lm2 + 3.0)
            }
        };
    }
}

/// ZH vector of the clamped cosine `max(0, cos θ)` (band count `bands`).
///
/// `k_0 = sqrt(π)/2`, `k_1 = sqrt(π/3)`, `k_l = 0` for odd `l ≥ 3`, and for even `l ≥ 2`
/// `k_l = 2π sqrt((2l+1)/4π) (-1)^{l/2-1} (l-2)! / (2^l (l/2-1)! (l/2+1)!)`, evaluated as the
/// moment recurrence of [`phong_zh`] with exponent 1.
pub fn clamped_cosine_zh(bands: usize) -> Result<Vec<f32>> {
    check_bands(bands)?;
    let mut m = vec![0.0; bands];
    hemisphere_power_moments(1.0, &mut m);
    Ok(moments_to_zh(1.0, &m))
}

fn moments_to_zh(scale: f64, moments: &[f64]) -> Vec<f32> {
    moments
        .iter()
        .enumerate()
        .map(|(l, &i)| {
            let k_l = ((2.0 * l as f64 + 1.0) / (4.0 * std::f64::consts::PI)).sqrt();
            (scale * std::f64::consts::TAU * k_l * i) as f32
        })
        .collect()
}

/// ZH vector of the normalised Phong lobe `(n+1)/(2π) max(0, cos θ)^n` (integrates to 1 over the
/// sphere), `n ≥ 0`. Coefficients `(n+1) sqrt((2l+1)/4π) ∫_0^1 μ^n P_l(μ) dμ`.
pub fn phong_zh(n: f32, bands: usize) -> Result<Vec<f32>> {
    let n = check_range("Phong exponent", f64::from(n), 0.0, 1e6, "0 ≤ n ≤ 1e6")?;
    check_bands(bands)?;
    let mut m = vec![0.0; bands];
    hemisphere_power_moments(n, &mut m);
    Ok(moments_to_zh((n + 1.0) / std::f64::consts::TAU, &m))
}

/// Paper 000 §3.3.1: `r_l` of the Lambertian BRDF `k_d/π cos θ` about the normal
/// (`k_d/π` times [`clamped_cosine_zh`]). `B_lm = sqrt(4π/(2l+1)) r_l Y_lm(n)`.
pub fn lambert_r(kd: f32, bands: usize) -> Result<Vec<f32>> {
    let kd = check_range("k_d", f64::from(kd), 0.0, f64::MAX, "≥ 0")?;
    let mut m = vec![0.0; check_bands(bands)?];
    hemisphere_power_moments(1.0, &mut m);
    Ok(moments_to_zh(kd / std::f64::consts::PI, &m))
}

/// Paper 000 §3.3.2: `r_l` of the Phong BRDF `k_s (n+1)/(2π) cos^n θ` about the reflected
/// direction: `r_l = k_s sqrt((2l+1)/4π) (n+1) (n-1)(n-3)…/((n+l+1)(n+l-1)…)` as printed;
/// equal to `k_s` times [`phong_zh`].
pub fn phong_r(ks: f32, n: f32, bands: usize) -> Result<Vec<f32>> {
    let ks = check_range("k_s", f64::from(ks), 0.0, f64::MAX, "≥ 0")?;
    Ok(phong_zh(n, bands)?
        .into_iter()
        .map(|v| (f64::from(v) * ks) as f32)
        .collect())
}

/// Convolves the SH vector `f` with the circularly symmetric kernel of ZH vector `kernel`:
/// `out_lm = sqrt(4π/(2l+1)) k_l f_lm`. Bands beyond `kernel.len()` are zero.
pub fn convolve(f: &[f32], kernel: &[f32]) -> Result<Vec<f32>> {
    let bands = bands_of_len(f.len())?;
    check_bands(kernel.len())?;
    let mut out = vec![0.0f32; f.len()];
    for (l, &kl) in kernel.iter().enumerate().take(bands) {
        let k = zh_factor(l) * f64::from(kl);
        for i in l * l..(l + 1) * (l + 1) {
            out[i] = (k * f64::from(f[i])) as f32;
        }
    }
    Ok(out)
}

/// A per-band window that damps high bands to reduce ringing (Gibbs) of band-limited SH.
///
/// Band-limited reconstructions of sharp lobes (clamped cosine, small caps, Phong) overshoot and
/// go negative; negative irradiance then wrecks half-float buffers (ANCHORS). Paper 003 §4.2
/// multiplies the coefficients by a sinc window [Sloan 2008]. The parameter `width` is the band at
/// which the window reaches zero; `width = bands` (the default choice in shine) keeps band 0
/// untouched and damps the last band most. Larger `width` damps less.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Window {
    /// No windowing.
    None,
    /// Lanczos / sinc window `sin(π l / w) / (π l / w)` (Sloan 2008, used by paper 003).
    Sinc {
        /// `w`: band where the window reaches zero (> 0).
        width: f32,
    },
    /// Hann window `(1 + cos(π l / w)) / 2` (stronger damping than sinc).
    Hann {
        /// `w`: band where the window reaches zero (> 0).
        width: f32,
    },
}

impl Window {
    /// The factor of band `l` (1 at `l = 0`, 0 for `l ≥ width`).
    pub fn factor(self, l: usize) -> Result<f32> {
        let lf = l as f64;
        match self {
            Window::None => Ok(1.0),
            Window::Sinc { width } | Window::Hann { width } => {
                let w = f64::from(width);
                if !(w > 0.0 && w.is_finite()) {
                    return Err(ShError::OutOfRange {
                        name: "window width",
                        value: w,
                        expected: "finite and > 0",
                    });
                }
                if lf >= w {
                    return Ok(0.0);
                }
                let x = std::f64::consts::PI * lf / w;
                Ok(match self {
                    Window::Hann { .. } => 0.5 * (1.0 + x.cos()),
                    _ if l == 0 => 1.0,
                    _ => x.sin() / x,
                } as f32)
            }
        }
    }

    /// Multiplies a ZH vector (index `l`) by the window.
    pub fn apply_zh(self, zh: &mut [f32]) -> Result<()> {
        for (l, c) in zh.iter_mut().enumerate() {
            *c *= self.factor(l)?;
        }
        Ok(())
    }

    /// Multiplies an SH vector (index `l*l+l+m`) by the window.
    pub fn apply_sh(self, sh: &mut [f32]) -> Result<()> {
        let bands = bands_of_len(sh.len())?;
        for l in 0..bands {
            let f = self.factor(l)?;
            for c in &mut sh[l * l..(l + 1) * (l + 1)] {
                *c *= f;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::{eval_basis_f64, evaluate};
    use crate::legendre::legendre;
    use crate::quadrature::{SphereQuadrature, gauss_legendre};
    use glam::{DVec3, Vec3};

    /// `2π ∫_0^1 k(μ) Y_l0(μ) dμ` by Gauss–Legendre.
    fn zh_by_quadrature(k: impl Fn(f64) -> f64, l: usize) -> f64 {
        let (x, w) = gauss_legendre(200);
        let y = ((2.0 * l as f64 + 1.0) / (4.0 * std::f64::consts::PI)).sqrt();
        std::f64::consts::TAU
            * x.iter()
                .zip(&w)
                .map(|(&t, &wt)| {
                    let mu = 0.5 * (t + 1.0);
                    0.5 * wt * k(mu) * y * legendre(l, mu)
                })
                .sum::<f64>()
    }

    #[test]
    fn kernels_against_quadrature() {
        let cc = clamped_cosine_zh(12).unwrap();
        for (l, &c) in cc.iter().enumerate() {
            assert!(
                (f64::from(c) - zh_by_quadrature(|m| m, l)).abs() < 1e-6,
                "l={l}"
            );
        }
        assert!((cc[0] - std::f32::consts::PI.sqrt() / 2.0).abs() < 1e-6);
        for &n in &[0.0f32, 1.0, 7.5, 32.0, 100.0] {
            let p = phong_zh(n, 16).unwrap();
            let nf = f64::from(n);
            for (l, &c) in p.iter().enumerate() {
                let q = zh_by_quadrature(|m| (nf + 1.0) / std::f64::consts::TAU * m.powf(nf), l);
                assert!((f64::from(c) - q).abs() < 1e-5, "n={n} l={l}: {c} vs {q}");
            }
        }
        // paper 000 closed forms for Lambert, l = 0, 1, 2
        let r = lambert_r(0.5, 4).unwrap();
        let pi = std::f32::consts::PI;
        assert!((r[0] - 0.5 / pi * pi.sqrt() / 2.0).abs() < 1e-6);
        assert!((r[1] - 0.5 / pi * (pi / 3.0).sqrt()).abs() < 1e-6);
        let r2 = 0.5 / pi * 2.0 * pi * (5.0 / (4.0 * pi)).sqrt() / 8.0;
        assert!((r[2] - r2).abs() < 1e-6);
        assert!(r[3].abs() < 1e-7);
        // paper 000 Phong closed form for l = 3: ks sqrt(7/4π) (n+1)(n-1)/((n+4)(n+2))
        let (ks, n) = (0.7f32, 12.0f32);
        let ph = phong_r(ks, n, 5).unwrap();
        let expect =
            ks * (7.0 / (4.0 * pi)).sqrt() * (n + 1.0) * (n - 1.0) / ((n + 4.0) * (n + 2.0));
        assert!((ph[3] - expect).abs() < 1e-6);
        let expect4 = ks * (9.0 / (4.0 * pi)).sqrt() * (n + 1.0) * n * (n - 2.0)
            / ((n + 5.0) * (n + 3.0) * (n + 1.0));
        assert!((ph[4] - expect4).abs() < 1e-6);
        assert!(phong_zh(-1.0, 3).is_err());
    }

    /// Funk–Hecke: `(f ⋆ k)(n) = ∫ f(s) k(n·s) ds` for band-limited `f`.
    #[test]
    fn convolution_against_quadrature() {
        let bands = 6;
        let f: Vec<f32> = (0..bands * bands)
            .map(|i| ((i * 7 % 11) as f32 - 5.0) * 0.1)
            .collect();
        let expo = 4.0f32;
        let k = phong_zh(expo, bands).unwrap();
        let g = convolve(&f, &k).unwrap();
        for nrm in [Vec3::Z, Vec3::new(0.3, -0.4, 0.5).normalize(), Vec3::NEG_X] {
            let q = SphereQuadrature::cap(nrm.as_dvec3(), 0.0, 16, 32);
            let mut y = vec![0.0; bands * bands];
            let reference = q.integrate(|s: DVec3| {
                eval_basis_f64(s, bands, &mut y).unwrap();
                let fs: f64 = y.iter().zip(&f).map(|(a, &b)| a * f64::from(b)).sum();
                fs * (f64::from(expo) + 1.0) / std::f64::consts::TAU
                    * s.dot(nrm.as_dvec3()).powf(4.0)
            });
            let v = evaluate(&g, nrm).unwrap();
            assert!(
                (f64::from(v) - reference).abs() < 1e-5,
                "{v} vs {reference}"
            );
        }
    }

    #[test]
    fn window_reduces_ringing() {
        // A sharp Phong lobe at 5 bands rings negative; the sinc window reduces the undershoot.
        let bands = 5;
        let lobe = phong_zh(64.0, bands).unwrap();
        let min_of = |zh: &[f32]| {
            (0..=200)
                .map(|i| {
                    let mu = -1.0 + 2.0 * i as f64 / 200.0;
                    zh.iter()
                        .enumerate()
                        .map(|(l, &c)| {
                            f64::from(c)
                                * ((2.0 * l as f64 + 1.0) / (4.0 * std::f64::consts::PI)).sqrt()
                                * legendre(l, mu)
                        })
                        .sum::<f64>()
                })
                .fold(f64::INFINITY, f64::min)
        };
        let mut windowed = lobe.clone();
        Window::Sinc {
            width: bands as f32,
        }
        .apply_zh(&mut windowed)
        .unwrap();
        let raw_min = min_of(&lobe);
        let win_min = min_of(&windowed);
        assert!(raw_min < -0.05, "{raw_min}");
        assert!(win_min > 0.2 * raw_min, "{win_min} vs {raw_min}");
        let mut hann = lobe;
        Window::Hann {
            width: bands as f32,
        }
        .apply_zh(&mut hann)
        .unwrap();
        assert!(min_of(&hann) > 0.2 * raw_min);
        assert_eq!(Window::Sinc { width: 4.0 }.factor(0), Ok(1.0));
        assert_eq!(Window::Sinc { width: 4.0 }.factor(4), Ok(0.0));
        assert!(Window::Hann { width: 0.0 }.factor(1).is_err());
        let mut sh = vec![1.0f32; 9];
        Window::Hann { width: 2.0 }.apply_sh(&mut sh).unwrap();
        assert_eq!(sh[0], 1.0);
        assert!((sh[1] - 0.5).abs() < 1e-6);
        assert_eq!(sh[8], 0.0);
    }
}
