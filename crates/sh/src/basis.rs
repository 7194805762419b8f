//! The real SH basis `Y_lm` to any band count, by a normalised recurrence.
//!
//! We run the recurrence on `Q_l^m = P̄_l^m(z) / sin^m θ`, where `P̄_l^m` is the associated
//! Legendre function already multiplied by its normalisation `K_l^m` (Condon–Shortley phase
//! included), and combine it with `(x + i y)^m = sin^m θ · e^{i m φ}`:
//!
//! * `Q_0^0 = 1/sqrt(4π)`, `Q_m^m = -sqrt((2m+1)/(2m)) Q_{m-1}^{m-1}`,
//! * `Q_{m+1}^m = sqrt(2m+3) z Q_m^m`,
//! * `Q_l^m = a_lm (z Q_{l-1}^m - b_lm Q_{l-2}^m)`, `a_lm = sqrt((4l²-1)/(l²-m²))`,
//!   `b_lm = sqrt(((l-1)²-m²)/(4(l-1)²-1))`,
//! * `Y_l0 = Q_l^0`, `Y_lm = √2 Q_l^m Re (x+iy)^m`, `Y_l,-m = √2 Q_l^m Im (x+iy)^m` (`m > 0`).
//!
//! No factorial appears and the recurrence is polynomial in `x, y, z` (no `atan2`, no pole
//! special case), so it is stable to high degree; the tests check orthonormality to 20 bands.

use glam::{DVec3, Vec3};

use crate::{Result, ShError, bands_of_len, check_bands, num_coeffs};

/// Writes `Y_lm(d)` for all `l < bands` into `out[..bands²]` (`f64`, `d` must be unit length).
pub fn eval_basis_f64(d: DVec3, bands: usize, out: &mut [f64]) -> Result<()> {
    check_bands(bands)?;
    let n2 = num_coeffs(bands);
    if out.len() < n2 {
        return Err(ShError::NotSquare { len: out.len() });
    }
    recurrence(d, bands, |_, i, v| out[i] = v);
    Ok(())
}

/// The recurrence of the module docs; hands each `(l, index, Y_lm(d))` to `put` (`bands` checked
/// by the caller, `d` unit length).
pub(crate) fn recurrence(d: DVec3, bands: usize, mut put: impl FnMut(usize, usize, f64)) {
    let (x, y, z) = (d.x, d.y, d.z);
    let sqrt2 = std::f64::consts::SQRT_2;
    // (x + iy)^m
    let (mut cm, mut sm) = (1.0f64, 0.0f64);
    let mut qmm = 0.5 / std::f64::consts::PI.sqrt();
    for m in 0..bands {
        if m > 0 {
            let mf = m as f64;
            qmm *= -((2.0 * mf + 1.0) / (2.0 * mf)).sqrt();
            let c = cm * x - sm * y;
            sm = cm * y + sm * x;
            cm = c;
        }
        let mf = m as f64;
        let mut q_prev2 = 0.0;
        let mut q_prev = qmm;
        for l in m..bands {
            let q = if l == m {
                qmm
            } else if l == m + 1 {
                (2.0 * mf + 3.0).sqrt() * z * qmm
            } else {
                let lf = l as f64;
                let a = ((4.0 * lf * lf - 1.0) / (lf * lf - mf * mf)).sqrt();
                let b = (((lf - 1.0) * (lf - 1.0) - mf * mf)
                    / (4.0 * (lf - 1.0) * (lf - 1.0) - 1.0))
                    .sqrt();
                a * (z * q_prev - b * q_prev2)
            };
            if l > m {
                q_prev2 = q_prev;
                q_prev = q;
            }
            let base = l * l + l;
            if m == 0 {
                put(l, base, q);
            } else {
                put(l, base + m, sqrt2 * q * cm);
                put(l, base - m, sqrt2 * q * sm);
            }
        }
    }
}

/// Normalises a direction, rejecting zero, infinite and NaN vectors.
pub(crate) fn unit_dir(d: Vec3) -> Result<DVec3> {
    let d = d.as_dvec3();
    let len = d.length();
    if len.is_finite() && len > 0.0 {
        Ok(d / len)
    } else {
        Err(ShError::OutOfRange {
            name: "direction",
            value: len,
            expected: "a finite non-zero vector",
        })
    }
}

/// Writes `Y_lm(d)` for `l < bands` into `out[..bands²]`; `d` is normalised first.
pub fn eval_basis_into(d: Vec3, bands: usize, out: &mut [f32]) -> Result<()> {
    let d = unit_dir(d)?;
    check_bands(bands)?;
    let n2 = num_coeffs(bands);
    if out.len() < n2 {
        return Err(ShError::NotSquare { len: out.len() });
    }
    recurrence(d, bands, |_, i, v| out[i] = v as f32);
    Ok(())
}

/// The basis vector `[Y_lm(d)]` for `l < bands`, `bands²` values; `d` is normalised first.
///
/// This is also the projection of a unit delta (Dirac) at `d`: SH of a point or directional light.
pub fn eval_basis(d: Vec3, bands: usize) -> Result<Vec<f32>> {
    let mut out = vec![0.0; num_coeffs(check_bands(bands)?)];
    eval_basis_into(d, bands, &mut out)?;
    Ok(out)
}

/// Reconstructs `f(d) = Σ f_lm Y_lm(d)` from the SH vector `coeffs` (band count from its length).
pub fn evaluate(coeffs: &[f32], d: Vec3) -> Result<f32> {
    let bands = bands_of_len(coeffs.len())?;
    let mut sum = 0.0f64;
    recurrence(unit_dir(d)?, bands, |_, i, y| {
        sum += f64::from(coeffs[i]) * y
    });
    Ok(sum as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrature::SphereQuadrature;
    use crate::{index, num_coeffs};

    const C1: f64 = 0.488_602_511_902_919_9;

    #[test]
    fn low_bands_match_closed_forms() {
        let d = DVec3::new(0.3, -0.5, 0.7).normalize();
        let mut y = vec![0.0; 9];
        eval_basis_f64(d, 3, &mut y).unwrap();
        assert!((y[0] - 0.282_094_791_773_878_14).abs() < 1e-15);
        assert!((y[1] + C1 * d.y).abs() < 1e-15);
        assert!((y[2] - C1 * d.z).abs() < 1e-15);
        assert!((y[3] + C1 * d.x).abs() < 1e-15);
        let c2 = 1.092_548_430_592_079_2;
        assert!((y[4] - c2 * d.x * d.y).abs() < 1e-14);
        assert!((y[5] + c2 * d.y * d.z).abs() < 1e-14);
        assert!((y[6] - 0.315_391_565_252_520_05 * (3.0 * d.z * d.z - 1.0)).abs() < 1e-14);
        assert!((y[7] + c2 * d.x * d.z).abs() < 1e-14);
        assert!((y[8] - 0.546_274_215_296_039_6 * (d.x * d.x - d.y * d.y)).abs() < 1e-14);
    }

    /// ANCHORS pitfall: a delta at +x has a negative coefficient 3 (Condon–Shortley phase).
    #[test]
    fn delta_at_plus_x_has_negative_coefficient_3() {
        let v = eval_basis(Vec3::X, 2).unwrap();
        assert!(v[3] < -0.48 && v[3] > -0.49);
        assert!(v[1].abs() < 1e-7 && v[2].abs() < 1e-7);
    }

    #[test]
    fn orthonormal_to_20_bands() {
        let bands = 20;
        let n2 = num_coeffs(bands);
        let q = SphereQuadrature::for_degree(2 * bands);
        let mut gram = vec![0.0f64; n2 * n2];
        let mut y = vec![0.0; n2];
        for (&d, &w) in q.dirs.iter().zip(&q.weights) {
            eval_basis_f64(d, bands, &mut y).unwrap();
            for i in 0..n2 {
                let wy = w * y[i];
                for j in i..n2 {
                    gram[i * n2 + j] += wy * y[j];
                }
            }
        }
        let mut worst = 0.0f64;
        for i in 0..n2 {
            for j in i..n2 {
                let expect = if i == j { 1.0 } else { 0.0 };
                worst = worst.max((gram[i * n2 + j] - expect).abs());
            }
        }
        assert!(worst < 1e-11, "worst Gram deviation {worst}");
    }

    #[test]
    fn evaluate_and_errors() {
        let mut c = vec![0.0f32; 16];
        c[index(2, 0)] = 1.0;
        let v = evaluate(&c, Vec3::Z).unwrap();
        assert!((v - 0.630_783_1).abs() < 1e-6);
        assert!(evaluate(&c, Vec3::ZERO).is_err());
        assert!(evaluate(&c[..15], Vec3::Z).is_err());
        assert!(eval_basis(Vec3::Z, 0).is_err());
        assert!(eval_basis(Vec3::new(f32::NAN, 0.0, 1.0), 3).is_err());
    }
}
