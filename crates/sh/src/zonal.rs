//! Zonal harmonics (ZH): spherical caps and rotation of circularly symmetric functions.
//!
//! A ZH vector `g` holds the `m = 0` coefficients `g_l` (length = band count) of a function
//! circularly symmetric about +z.

use glam::Vec3;

use crate::basis::{recurrence, unit_dir};
use crate::legendre::legendre_all;
use crate::{MAX_BANDS, Result, ShError, check_bands, check_range, num_coeffs};

/// `sqrt(4π/(2l+1))`: the factor that rotates (paper 003 eq. 15) or convolves (paper 002 eq. 7)
/// with a ZH coefficient of band `l`.
#[inline]
pub fn zh_factor(l: usize) -> f64 {
    (4.0 * std::f64::consts::PI / (2.0 * l as f64 + 1.0)).sqrt()
}

/// ZH coefficients of the indicator of a spherical cap about +z with `cos(a) = cos_a`, in `f64`.
///
/// Paper 003 eq. 14 (α = cos a):
/// `L̃_0 = sqrt(π) (1 - α)`, `L̃_l = sqrt(π/(2l+1)) (P_{l-1}(α) - P_{l+1}(α))`.
/// Re-derived: `2π K_l ∫_α^1 P_l = 2π sqrt((2l+1)/4π) (P_{l-1} - P_{l+1})/(2l+1)`, which is the
/// equation as printed. `cos_a` is clamped to `[-1, 1]`.
pub fn cap_zh_f64(cos_a: f64, bands: usize, out: &mut [f64]) -> Result<()> {
    check_bands(bands)?;
    if out.len() < bands {
        return Err(ShError::BandMismatch {
            a: out.len(),
            b: bands,
        });
    }
    let alpha = cos_a.clamp(-1.0, 1.0);
    let mut p = [0.0f64; MAX_BANDS + 1];
    legendre_all(alpha, &mut p[..=bands]);
    let sqrt_pi = std::f64::consts::PI.sqrt();
    out[0] = sqrt_pi * (1.0 - alpha);
    for l in 1..bands {
        out[l] = sqrt_pi / (2.0 * l as f64 + 1.0).sqrt() * (p[l - 1] - p[l + 1]);
    }
    Ok(())
}

/// ZH vector (length `bands`) of a unit-radiance spherical cap of half-angle `a` (radians,
/// `0 ≤ a ≤ π`) centred on +z: paper 003 eq. 14.
pub fn cap_zh(a: f32, bands: usize) -> Result<Vec<f32>> {
    let a = check_half_angle(a)?;
    let mut out = vec![0.0; check_bands(bands)?];
    cap_zh_f64(a.cos(), bands, &mut out)?;
    Ok(out.into_iter().map(|c| c as f32).collect())
}

/// Rotates a ZH vector from +z to direction `dir`: paper 003 eq. 15,
/// `L_lm = sqrt(4π/(2l+1)) Y_lm(dir) L̃_l`. Returns `zh.len()²` coefficients.
pub fn rotate_zh(zh: &[f32], dir: Vec3) -> Result<Vec<f32>> {
    let bands = check_bands(zh.len())?;
    let d = unit_dir(dir)?;
    let mut k = [0.0f64; MAX_BANDS];
    for (l, (kl, &g)) in k.iter_mut().zip(zh).enumerate() {
        *kl = zh_factor(l) * f64::from(g);
    }
    Ok(rotate_scaled(&k, d, bands))
}

/// SH vector of a unit-radiance cap of half-angle `a` around `dir` (eq. 14 then eq. 15).
pub fn cap_sh(dir: Vec3, a: f32, bands: usize) -> Result<Vec<f32>> {
    let a = check_half_angle(a)?;
    let d = unit_dir(dir)?;
    check_bands(bands)?;
    let mut k = [0.0f64; MAX_BANDS];
    cap_zh_f64(a.cos(), bands, &mut k)?;
    for (l, kl) in k.iter_mut().enumerate().take(bands) {
        *kl *= zh_factor(l);
    }
    Ok(rotate_scaled(&k, d, bands))
}

/// `out_lm = k_l Y_lm(d)` for unit `d` (`k` already holds `sqrt(4π/(2l+1)) g_l`).
fn rotate_scaled(k: &[f64], d: glam::DVec3, bands: usize) -> Vec<f32> {
    let mut out = vec![0.0f32; num_coeffs(bands)];
    recurrence(d, bands, |l, i, y| out[i] = (k[l] * y) as f32);
    out
}

fn check_half_angle(a: f32) -> Result<f64> {
    check_range(
        "cap half-angle",
        f64::from(a),
        0.0,
        std::f64::consts::PI + 1e-6,
        "0 ≤ a ≤ π radians",
    )
}

/// Half-angle subtended by a sphere of radius `radius` whose centre is at `distance`:
/// `asin(radius / distance)`, and `π` (the whole sphere of directions) when the point is inside.
pub fn sphere_half_angle(distance: f32, radius: f32) -> Result<f32> {
    let d = check_range("distance", f64::from(distance), 0.0, f64::MAX, "≥ 0")?;
    let r = check_range("radius", f64::from(radius), 0.0, f64::MAX, "≥ 0")?;
    if d <= r {
        Ok(std::f32::consts::PI)
    } else {
        Ok((r / d).asin() as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::{eval_basis, eval_basis_f64};
    use crate::quadrature::{SphereQuadrature, gauss_legendre};
    use glam::DVec3;

    #[test]
    fn cap_zh_against_1d_quadrature() {
        let (x, w) = gauss_legendre(40);
        for &a in &[0.05f64, 0.4, 1.0, std::f64::consts::FRAC_PI_2, 2.5, 3.1] {
            let ca = a.cos();
            let mut zh = vec![0.0; 20];
            cap_zh_f64(ca, 20, &mut zh).unwrap();
            let half = 0.5 * (1.0 - ca);
            for (l, &z) in zh.iter().enumerate() {
                // 2π ∫_{cos a}^1 Y_l0(μ) dμ
                let s: f64 = x
                    .iter()
                    .zip(&w)
                    .map(|(&t, &wt)| {
                        let mu = ca + half * (t + 1.0);
                        let d = DVec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
                        let mut y = vec![0.0; 400];
                        eval_basis_f64(d, 20, &mut y).unwrap();
                        wt * half * y[l * l + l]
                    })
                    .sum::<f64>()
                    * std::f64::consts::TAU;
                assert!((s - z).abs() < 1e-12, "a={a} l={l}: {s} vs {z}");
            }
        }
    }

    #[test]
    fn rotated_cap_against_cap_quadrature() {
        let bands = 9;
        let dir = Vec3::new(-0.3, 0.5, 0.8).normalize();
        let a = 0.6f32;
        let sh = cap_sh(dir, a, bands).unwrap();
        let q = SphereQuadrature::cap(dir.as_dvec3(), f64::from(a).cos(), 20, 40);
        let reference = q.project_f64(bands, |_| 1.0).unwrap();
        for (s, r) in sh.iter().zip(&reference) {
            assert!((f64::from(*s) - r).abs() < 1e-5, "{s} vs {r}");
        }
        // whole sphere: only the DC term survives
        let full = cap_zh(std::f32::consts::PI, 4).unwrap();
        assert!((full[0] - (4.0 * std::f32::consts::PI).sqrt()).abs() < 1e-5);
        assert!(full[1..].iter().all(|c| c.abs() < 1e-6));
        assert!(cap_zh(-0.1, 3).is_err());
    }

    #[test]
    fn rotate_zh_of_delta_is_delta() {
        // a delta at +z has ZH Y_l0(z) = sqrt((2l+1)/4π); rotated it must equal Y(d).
        let bands = 6;
        let zh: Vec<f32> = (0..bands).map(|l| (1.0 / zh_factor(l)) as f32).collect();
        let d = Vec3::new(0.6, -0.64, 0.48);
        let r = rotate_zh(&zh, d).unwrap();
        let y = eval_basis(d, bands).unwrap();
        for (a, b) in r.iter().zip(&y) {
            assert!((a - b).abs() < 1e-6);
        }
        assert_eq!(sphere_half_angle(1.0, 2.0), Ok(std::f32::consts::PI));
        assert!((sphere_half_angle(2.0, 1.0).unwrap() - std::f32::consts::FRAC_PI_6).abs() < 1e-6);
    }
}
