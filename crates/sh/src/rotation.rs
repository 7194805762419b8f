//! General rotation of SH vectors, band by band (Ivanic–Ruedenberg recurrence, with the
//! corrections of their 1998 erratum).
//!
//! A rotation `R` maps an SH vector `f` to `g = D(R) f` with `g(s) = f(R⁻¹ s)`: the function is
//! carried along with the rotation, so "rotate then evaluate at `R d`" equals "evaluate at `d`".
//! `D` is block diagonal; band `l` has a `(2l+1)²` orthogonal block. The recurrence builds band
//! `l` from band `l-1` and band 1 in the basis *without* the Condon–Shortley phase; the blocks are
//! then conjugated by `diag((-1)^m)` to our basis (docs/architecture.md, "Conventions"). Cost `O(n³)` to build, `O(n³)` to
//! apply (`Σ (2l+1)²`); meant for bands ≤ 8 per frame, correct (tested) to 20.
//!
//! Zonal vectors never need this: use [`crate::zonal::rotate_zh`] (paper 003 eq. 15).

use glam::{DMat3, Mat3, Quat};

use crate::{Result, ShError, bands_of_len, check_bands};

/// Per-band rotation matrices of SH vectors for one 3D rotation.
#[derive(Debug, Clone)]
pub struct ShRotation {
    bands: usize,
    /// `blocks[l]`: row-major `(2l+1)×(2l+1)`, row/column `m + l`.
    blocks: Vec<Vec<f64>>,
}

fn kron(a: i32, b: i32) -> f64 {
    if a == b { 1.0 } else { 0.0 }
}

impl ShRotation {
    /// Builds the rotation for `bands` bands from a rotation matrix (must be orthonormal, det 1;
    /// it is re-orthonormalised through a quaternion).
    pub fn from_mat3(r: Mat3, bands: usize) -> Result<Self> {
        Self::from_quat(Quat::from_mat3(&r), bands)
    }

    /// Builds the rotation for `bands` bands from a quaternion (normalised first).
    pub fn from_quat(q: Quat, bands: usize) -> Result<Self> {
        check_bands(bands)?;
        let q = q.as_dquat();
        let len = q.length();
        if !len.is_finite() || len == 0.0 {
            return Err(ShError::OutOfRange {
                name: "rotation",
                value: len,
                expected: "a finite non-zero quaternion",
            });
        }
        let r = DMat3::from_quat(q / len);
        let mut blocks = Vec::with_capacity(bands);
        blocks.push(vec![1.0]);
        if bands > 1 {
            // Basis order m = -1, 0, 1  ↔  y, z, x (no Condon–Shortley phase).
            let axis = [1usize, 2, 0];
            let mut b1 = vec![0.0; 9];
            for (i, &ai) in axis.iter().enumerate() {
                for (j, &aj) in axis.iter().enumerate() {
                    b1[i * 3 + j] = r.col(aj)[ai];
                }
            }
            blocks.push(b1);
        }
        for l in 2..bands {
            let next = band_from_previous(&blocks[1], &blocks[l - 1], l);
            blocks.push(next);
        }
        // Conjugate to the Condon–Shortley basis: D_cs[m][n] = (-1)^(m+n) D[m][n].
        for (l, b) in blocks.iter_mut().enumerate() {
            let w = 2 * l + 1;
            for i in 0..w {
                for j in 0..w {
                    if (i + j) % 2 == 1 {
                        b[i * w + j] = -b[i * w + j];
                    }
                }
            }
        }
        Ok(Self { bands, blocks })
    }

    /// Band count this rotation was built for.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The `(2l+1)×(2l+1)` row-major block of band `l` (row/column index `m + l`), if `l < bands`.
    pub fn block(&self, l: usize) -> Option<&[f64]> {
        self.blocks.get(l).map(Vec::as_slice)
    }

    /// Rotates `coeffs` (any band count ≤ [`Self::bands`]) and returns the rotated vector.
    pub fn apply(&self, coeffs: &[f32]) -> Result<Vec<f32>> {
        let n = bands_of_len(coeffs.len())?;
        if n > self.bands {
            return Err(ShError::BandMismatch {
                a: n,
                b: self.bands,
            });
        }
        let mut out = vec![0.0f32; coeffs.len()];
        for (l, block) in self.blocks.iter().take(n).enumerate() {
            let w = 2 * l + 1;
            let base = l * l;
            for i in 0..w {
                let s: f64 = (0..w)
                    .map(|j| block[i * w + j] * f64::from(coeffs[base + j]))
                    .sum();
                out[base + i] = s as f32;
            }
        }
        Ok(out)
    }
}

/// One Ivanic–Ruedenberg step: band `l` from band 1 (`r1`) and band `l-1` (`prev`).
fn band_from_previous(r1: &[f64], prev: &[f64], l: usize) -> Vec<f64> {
    let li = l as i32;
    let w = 2 * l + 1;
    let wp = 2 * l - 1;
    let r = |i: i32, j: i32| r1[((i + 1) * 3 + (j + 1)) as usize];
    let mp = |a: i32, b: i32| prev[((a + li - 1) as usize) * wp + (b + li - 1) as usize];
    let p = |i: i32, a: i32, b: i32| -> f64 {
        if b == li {
            r(i, 1) * mp(a, li - 1) - r(i, -1) * mp(a, -li + 1)
        } else if b == -li {
            r(i, 1) * mp(a, -li + 1) + r(i, -1) * mp(a, li - 1)
        } else {
            r(i, 0) * mp(a, b)
        }
    };
    let mut out = vec![0.0; w * w];
    for m in -li..=li {
        for n in -li..=li {
            let lf = f64::from(li);
            let am = f64::from(m.abs());
            let d = if n.abs() < li {
                f64::from((li + n) * (li - n))
            } else {
                f64::from(2 * li * (2 * li - 1))
            };
            let u = (f64::from((li + m) * (li - m)) / d).sqrt();
            let v = 0.5
                * ((1.0 + kron(m, 0)) * (lf + am - 1.0) * (lf + am) / d).sqrt()
                * (1.0 - 2.0 * kron(m, 0));
            let wc = -0.5 * ((lf - am - 1.0) * (lf - am) / d).max(0.0).sqrt() * (1.0 - kron(m, 0));
            let mut val = 0.0;
            if u != 0.0 {
                val += u * p(0, m, n);
            }
            if v != 0.0 {
                let vv = if m == 0 {
                    p(1, 1, n) + p(-1, -1, n)
                } else if m > 0 {
                    p(1, m - 1, n) * (1.0 + kron(m, 1)).sqrt()
                        - p(-1, -m + 1, n) * (1.0 - kron(m, 1))
                } else {
                    p(1, m + 1, n) * (1.0 - kron(m, -1))
                        + p(-1, -m - 1, n) * (1.0 + kron(m, -1)).sqrt()
                };
                val += v * vv;
            }
            if wc != 0.0 {
                let ww = if m > 0 {
                    p(1, m + 1, n) + p(-1, -m - 1, n)
                } else {
                    p(1, m - 1, n) - p(-1, -m + 1, n)
                };
                val += wc * ww;
            }
            out[((m + li) as usize) * w + (n + li) as usize] = val;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::{eval_basis, evaluate};
    use glam::Vec3;

    fn pseudo_random_vec(n2: usize, seed: u32) -> Vec<f32> {
        let mut s = seed;
        (0..n2)
            .map(|_| {
                s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                (s >> 8) as f32 / (1u32 << 24) as f32 - 0.5
            })
            .collect()
    }

    #[test]
    fn rotate_then_evaluate_matches_evaluate_at_rotated_direction() {
        let q = Quat::from_axis_angle(Vec3::new(0.3, -0.8, 0.5).normalize(), 1.1)
            * Quat::from_rotation_z(0.4);
        for &bands in &[2usize, 3, 5, 9, 20] {
            let f = pseudo_random_vec(bands * bands, bands as u32);
            let rot = ShRotation::from_quat(q, bands).unwrap();
            let g = rot.apply(&f).unwrap();
            for d in [
                Vec3::new(0.2, 0.9, -0.3),
                Vec3::new(-0.7, 0.1, 0.6),
                Vec3::Z,
                Vec3::new(0.0, -1.0, 0.01),
            ] {
                let d = d.normalize();
                let a = evaluate(&g, q * d).unwrap();
                let b = evaluate(&f, d).unwrap();
                assert!(
                    (a - b).abs() < 2e-4 * (bands as f32),
                    "bands {bands}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn rotating_a_delta_moves_it() {
        let bands = 8;
        let q = Quat::from_rotation_y(0.7) * Quat::from_rotation_x(-1.3);
        let d = Vec3::new(0.1, 0.4, 0.9).normalize();
        let rot = ShRotation::from_quat(q, bands).unwrap();
        let moved = rot.apply(&eval_basis(d, bands).unwrap()).unwrap();
        let expect = eval_basis(q * d, bands).unwrap();
        for (a, b) in moved.iter().zip(&expect) {
            assert!((a - b).abs() < 1e-5);
        }
        assert!(rot.apply(&vec![0.0; 81]).is_err());
        assert!(ShRotation::from_quat(Quat::from_xyzw(0.0, 0.0, 0.0, 0.0), 3).is_err());
    }
}
