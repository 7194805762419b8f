//! Paper 002 §5: indirect radiance from sphere proxies.
//!
//! Canonical configuration: receiver `p` at the origin, proxy centre at `(0,0,1)`, radius
//! `sin θ` (so `α = sin θ`). The proxy's visibility vector is the cap `V(α)`
//! ([`crate::zonal::cap_zh`]), its solid angle `ω = 2π(1 - sqrt(1 - α²))` (eq. 2).

use glam::Vec3;

use crate::basis::eval_basis_f64;
use crate::quadrature::gauss_legendre;
use crate::zonal::{cap_zh_f64, rotate_zh};
use crate::{Result, ShError, bands_of_len, check_bands, check_range, dot};

/// Solid angle of a proxy of `α = sin θ` (paper 002 eq. 2): `2π (1 - sqrt(1 - α²))`.
pub fn solid_angle(alpha: f32) -> Result<f32> {
    let a = check_range("α = sin θ", f64::from(alpha), 0.0, 1.0, "0..=1")?;
    Ok((std::f64::consts::TAU * (1.0 - (1.0 - a * a).sqrt())) as f32)
}

/// Proxy visibility vector `V_i = rot(V(α_i), d̂_i)` (paper 002 §5), `bands` bands.
pub fn proxy_visibility(dir: Vec3, alpha: f32, bands: usize) -> Result<Vec<f32>> {
    let a = check_range("α = sin θ", f64::from(alpha), 0.0, 1.0, "0..=1")?;
    let mut zh = vec![0.0; check_bands(bands)?];
    cap_zh_f64((1.0 - a * a).sqrt(), bands, &mut zh)?;
    let zh: Vec<f32> = zh.into_iter().map(|x| x as f32).collect();
    rotate_zh(&zh, dir)
}

/// The averaged operator `D(θ)` of paper 002 eq. 14 by numerical integration, `bands` ZH terms:
/// `D_l = (1/ω) ∫ v_θ(s) y_l0(q̂_θ(s)) ds`, with `q̂_θ(s) = (q_θ(s) - z)/sin θ`,
/// `q_θ(s) = s (s_z - sqrt(s_z² - cos² θ))` the first hit of the ray `s` on the sphere.
///
/// By symmetry `D_l = (2π/ω) ∫_{cos θ}^1 y_l0(q̂_z(μ)) dμ`, `q̂_z = (μ t - 1)/sin θ`,
/// `t = μ - sqrt(μ² - cos² θ)`; the square-root endpoint is removed by `μ = cos θ + (1-cos θ)u²`
/// and the integral is done by 64-point Gauss–Legendre. `α = sin θ ∈ (0, 1]`.
pub fn averaged_operator_exact(alpha: f64, bands: usize) -> Result<Vec<f64>> {
    let a = check_range("α = sin θ", alpha, 1e-6, 1.0, "1e-6..=1")?;
    check_bands(bands)?;
    let c = (1.0 - a * a).max(0.0).sqrt();
    let (x, w) = gauss_legendre(64);
    let mut out = vec![0.0; bands];
    let mut y = vec![0.0; bands * bands];
    let mut total = 0.0;
    for (&xi, &wi) in x.iter().zip(&w) {
        let u = 0.5 * (xi + 1.0);
        let mu = c + (1.0 - c) * u * u;
        let jac = 0.5 * wi * 2.0 * (1.0 - c) * u;
        let t = mu - (mu * mu - c * c).max(0.0).sqrt();
        let qz = ((mu * t - 1.0) / a).clamp(-1.0, 1.0);
        let q = glam::DVec3::new((1.0 - qz * qz).max(0.0).sqrt(), 0.0, qz);
        eval_basis_f64(q, bands, &mut y)?;
        for (l, o) in out.iter_mut().enumerate() {
            *o += jac * y[l * l + l];
        }
        total += jac;
    }
    // (2π/ω) ∫ = (1/(1-cos θ)) ∫ dμ; `total` is that measure, integrated by the same rule.
    Ok(out.into_iter().map(|v| v / total).collect())
}

/// Paper 002 eq. 15: polynomial fits of the order-3 averaged operator in `α = sin θ`:
/// `D_0 = 0.28209`, `D_1 ≈ 0.08432 α² − 0.25073 α − 0.32494`,
/// `D_2 ≈ −0.22230 α³ + 0.22502 α² + 0.47398 α + 0.15950`. `α` is clamped to `[0, 1]`.
pub fn averaged_operator_fit(alpha: f32) -> [f32; 3] {
    let a = if alpha.is_finite() {
        alpha.clamp(0.0, 1.0)
    } else {
        0.0
    };
    [
        0.28209,                                                // eq. 15, paper 002
        (0.08432 * a - 0.25073) * a - 0.32494,                  // eq. 15, paper 002
        ((-0.22230 * a + 0.22502) * a + 0.47398) * a + 0.15950, // eq. 15, paper 002
    ]
}

/// Averaged indirect radiance of one proxy (paper 002 §5): `I_i = κ_i V_i`,
/// `κ_i = rot(D(θ_i), d̂_i) · L̃` with `D` from the eq. 15 fit. `irradiance` is the unshadowed
/// diffuse shading vector `L̃` (≥ 3 bands are read; the result has its band count).
pub fn averaged_indirect(dir: Vec3, alpha: f32, irradiance: &[f32]) -> Result<Vec<f32>> {
    let bands = bands_of_len(irradiance.len())?;
    if bands < 3 {
        return Err(ShError::InvalidBands { bands });
    }
    let d = averaged_operator_fit(alpha);
    let d_sh = rotate_zh(&d, dir)?;
    let kappa = dot(&d_sh, &irradiance[..9])?;
    Ok(proxy_visibility(dir, alpha, bands)?
        .into_iter()
        .map(|v| v * kappa)
        .collect())
}

/// Point-sampled indirect radiance of one proxy (paper 002 eq. 13): `I_i = (L̃ · y(-d̂_i)) V_i`.
pub fn point_sampled_indirect(dir: Vec3, alpha: f32, irradiance: &[f32]) -> Result<Vec<f32>> {
    let bands = bands_of_len(irradiance.len())?;
    let y = crate::basis::eval_basis(-dir, bands)?;
    let radiance = dot(&y, irradiance)?;
    Ok(proxy_visibility(dir, alpha, bands)?
        .into_iter()
        .map(|v| v * radiance)
        .collect())
}

/// Paper 002 eq. 12: `ξ_p = (1 − O_p)_0 / (ω_p / √(4π))`, the ratio of the combined solid angle of
/// all proxies (from the DC term of the total occlusion vector `O_p`, eq. 4) to the summed solid
/// angle `ω_p = Σ ω_i`. `I_p = ξ_p Ĩ_p`. Returns 0 when `ω_p ≤ 0` (no proxy: nothing to scale).
///
/// Note: paper 002 names `O_p` the *occlusion* vector, i.e. the visibility of the environment
/// (`1 − V`); so `(1 − O_p)_0 = √(4π) − (O_p)_0` is the DC of the proxies' combined coverage.
pub fn overlap_normalisation(total_occlusion_dc: f32, summed_solid_angle: f32) -> f32 {
    let sqrt_4pi = (4.0 * std::f64::consts::PI).sqrt();
    let w = f64::from(summed_solid_angle);
    if !(w.is_finite() && w > 0.0 && total_occlusion_dc.is_finite()) {
        return 0.0;
    }
    ((sqrt_4pi - f64::from(total_occlusion_dc)) / (w / sqrt_4pi)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::SphereQuadrature;
    use glam::DVec3;

    /// Brute force for eq. 14: integrate over the sphere's visible cap in 2D.
    fn d_brute(alpha: f64) -> Vec<f64> {
        let c = (1.0 - alpha * alpha).sqrt();
        let q = SphereQuadrature::cap(DVec3::Z, c, 200, 8);
        let centre = DVec3::Z;
        let mut y = vec![0.0; 9];
        let mut acc = [0.0; 3];
        let mut total = 0.0;
        for (&s, &w) in q.dirs.iter().zip(&q.weights) {
            let b = s.dot(centre);
            let disc = (b * b - (1.0 - alpha * alpha)).max(0.0);
            let hit = s * (b - disc.sqrt());
            let n = ((hit - centre) / alpha).normalize();
            eval_basis_f64(n, 3, &mut y).unwrap();
            for l in 0..3 {
                acc[l] += w * y[l * l + l];
            }
            total += w;
        }
        acc.iter().map(|a| a / total).collect()
    }

    #[test]
    fn exact_operator_against_2d_quadrature() {
        for &a in &[0.1, 0.4, 0.8, 0.99] {
            let d = averaged_operator_exact(a, 3).unwrap();
            let b = d_brute(a);
            for l in 0..3 {
                assert!(
                    (d[l] - b[l]).abs() < 2e-4,
                    "α={a} l={l}: {} vs {}",
                    d[l],
                    b[l]
                );
            }
        }
    }

    /// Paper 002 Fig. 4: relative squared error of the fits is 0.00016% (D1) and 0.00064% (D2).
    #[test]
    fn eq15_fit_within_paper_error() {
        let (mut e1, mut n1, mut e2, mut n2) = (0.0, 0.0, 0.0, 0.0);
        for i in 1..=200 {
            let a = i as f64 / 200.0;
            let d = averaged_operator_exact(a, 3).unwrap();
            let f = averaged_operator_fit(a as f32);
            assert!((f64::from(f[0]) - d[0]).abs() < 1e-5);
            e1 += (f64::from(f[1]) - d[1]).powi(2);
            n1 += d[1] * d[1];
            e2 += (f64::from(f[2]) - d[2]).powi(2);
            n2 += d[2] * d[2];
        }
        let (r1, r2) = (e1 / n1, e2 / n2);
        println!("eq. 15 fit relative squared error: D1 {r1:e}, D2 {r2:e}");
        // the paper's numbers, with a factor 2 for its 5-digit rounding of the coefficients
        assert!(r1 < 2.0 * 0.00016e-2, "D1 relative squared error {r1:e}");
        assert!(r2 < 2.0 * 0.00064e-2, "D2 relative squared error {r2:e}");
    }

    #[test]
    fn overlap_normalisation_cases() {
        let sqrt_4pi = (4.0 * std::f32::consts::PI).sqrt();
        // one proxy: coverage DC = ω/√4π, so ξ = 1
        let a = 0.5f32;
        let w = solid_angle(a).unwrap();
        let occ_dc = sqrt_4pi - w / sqrt_4pi;
        assert!((overlap_normalisation(occ_dc, w) - 1.0).abs() < 1e-5);
        // two identical, fully overlapping proxies: ξ = 1/2
        assert!((overlap_normalisation(occ_dc, 2.0 * w) - 0.5).abs() < 1e-5);
        assert_eq!(overlap_normalisation(occ_dc, 0.0), 0.0);
        assert!(solid_angle(1.5).is_err());
    }

    #[test]
    fn indirect_vectors() {
        let mut l = vec![0.0f32; 9];
        l[0] = 1.0;
        let dir = Vec3::new(0.0, 0.6, 0.8);
        let i_avg = averaged_indirect(dir, 0.3, &l).unwrap();
        let i_pt = point_sampled_indirect(dir, 0.3, &l).unwrap();
        // constant lighting: both give DC(L̃)·Y00 = 1/√4π radiance times V
        let v = proxy_visibility(dir, 0.3, 3).unwrap();
        for ((a, p), v) in i_avg.iter().zip(&i_pt).zip(&v) {
            assert!((a - 0.28209 * v).abs() < 1e-5);
            assert!((p - 0.282_094_8 * v).abs() < 1e-5);
        }
        assert!(averaged_indirect(dir, 0.3, &[1.0; 4]).is_err());
    }
}
