//! SH products: the triple-product tensor `Γ_ijk = ∫ Y_i Y_j Y_k ds` and the projected product
//! of two SH vectors, `(a ∗ b)_k = Σ_ij Γ_ijk a_i b_j` (paper 002 §3 "f1 ∗ f2").
//!
//! The tensor is computed by quadrature (exact: the integrand has degree `3(n-1)`), only for
//! `i ≤ j ≤ k` that pass the selection rules (`|l_i - l_j| ≤ l_k ≤ l_i + l_j`, `l_i + l_j + l_k`
//! even), and stored sparse: for each output `k`, the list of `(i, j, Γ_ijk)` over all ordered
//! pairs. Both operands and the result have the same band count (the product is truncated).

use crate::quadrature::SphereQuadrature;
use crate::{Result, ShError, bands_of_len, check_bands, num_coeffs};

/// Largest band count of a triple-product tensor (`8` = the order paper 002 needs, with margin).
pub const MAX_PRODUCT_BANDS: usize = 10;

/// One non-zero of the tensor: `out[k] += value · a[i] · b[j]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TensorEntry {
    /// Index into the first operand.
    pub i: u16,
    /// Index into the second operand.
    pub j: u16,
    /// Index into the result.
    pub k: u16,
    /// `Γ_ijk`.
    pub value: f64,
}

/// The sparse triple-product tensor of a band count.
#[derive(Debug, Clone)]
pub struct TripleProduct {
    bands: usize,
    /// All ordered non-zeros, sorted by `k`, then `i`, then `j`.
    entries: Vec<TensorEntry>,
    /// The non-zeros with `i ≤ j` (half the work of a product), same order.
    pairs: Vec<TensorEntry>,
}

fn band_of(i: usize) -> usize {
    (i as f64).sqrt() as usize
}

impl TripleProduct {
    /// Computes the tensor for `bands` bands (`1..=MAX_PRODUCT_BANDS`).
    pub fn new(bands: usize) -> Result<Self> {
        check_bands(bands)?;
        if bands > MAX_PRODUCT_BANDS {
            return Err(ShError::InvalidBands { bands });
        }
        let n2 = num_coeffs(bands);
        let q = SphereQuadrature::for_degree(3 * (bands - 1));
        let np = q.dirs.len();
        // y[p * n2 + i] * sqrt(w_p) split as: yw = w Y_i, y = Y_j
        let mut y = vec![0.0; np * n2];
        for (p, &d) in q.dirs.iter().enumerate() {
            crate::basis::eval_basis_f64(d, bands, &mut y[p * n2..(p + 1) * n2])?;
        }
        let mut entries = Vec::new();
        for i in 0..n2 {
            let li = band_of(i);
            for j in i..n2 {
                let lj = band_of(j);
                for k in j..n2 {
                    let lk = band_of(k);
                    if lk > li + lj || lk < li.abs_diff(lj) || (li + lj + lk) % 2 == 1 {
                        continue;
                    }
                    let v: f64 = (0..np)
                        .map(|p| q.weights[p] * y[p * n2 + i] * y[p * n2 + j] * y[p * n2 + k])
                        .sum();
                    if v.abs() < 1e-12 {
                        continue;
                    }
                    // every distinct ordered permutation, keyed by the output index
                    let mut perms = [
                        (i, j, k),
                        (j, i, k),
                        (i, k, j),
                        (k, i, j),
                        (j, k, i),
                        (k, j, i),
                    ];
                    perms.sort_unstable();
                    let mut last = None;
                    for p in perms {
                        if Some(p) != last {
                            entries.push(TensorEntry {
                                i: p.0 as u16,
                                j: p.1 as u16,
                                k: p.2 as u16,
                                value: v,
                            });
                            last = Some(p);
                        }
                    }
                }
            }
        }
        entries.sort_by_key(|e| (e.k, e.i, e.j));
        let pairs = entries.iter().filter(|e| e.i <= e.j).copied().collect();
        Ok(Self {
            bands,
            entries,
            pairs,
        })
    }

    /// Band count.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The ordered non-zeros, sorted by output index `k`.
    pub fn entries(&self) -> &[TensorEntry] {
        &self.entries
    }

    fn check(&self, len: usize) -> Result<()> {
        let n = bands_of_len(len)?;
        if n != self.bands {
            return Err(ShError::BandMismatch {
                a: n,
                b: self.bands,
            });
        }
        Ok(())
    }

    /// `(a ∗ b)` in `f64` (both of this tensor's band count; unchecked lengths are a bug).
    pub(crate) fn product_f64(&self, a: &[f64], b: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; a.len()];
        for e in &self.pairs {
            let (i, j) = (e.i as usize, e.j as usize);
            out[e.k as usize] += if i == j {
                e.value * a[i] * b[i]
            } else {
                e.value * (a[i] * b[j] + a[j] * b[i])
            };
        }
        out
    }

    /// The projected product `a ∗ b` of two SH vectors of this tensor's band count.
    pub fn product(&self, a: &[f32], b: &[f32]) -> Result<Vec<f32>> {
        self.check(a.len())?;
        self.check(b.len())?;
        let a: Vec<f64> = a.iter().map(|&x| f64::from(x)).collect();
        let b: Vec<f64> = b.iter().map(|&x| f64::from(x)).collect();
        Ok(self
            .product_f64(&a, &b)
            .into_iter()
            .map(|x| x as f32)
            .collect())
    }

    /// Product matrix `M_a` (row-major `n²×n²`, symmetric) with `M_a b = a ∗ b`, in `f64`.
    pub(crate) fn product_matrix_f64(&self, a: &[f64]) -> Vec<f64> {
        let n2 = a.len();
        let mut m = vec![0.0; n2 * n2];
        for e in &self.entries {
            m[e.k as usize * n2 + e.j as usize] += e.value * a[e.i as usize];
        }
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::eval_basis_f64;
    use crate::quadrature::SphereQuadrature;

    #[test]
    fn product_against_quadrature_of_pointwise_product() {
        let bands = 4;
        let t = TripleProduct::new(bands).unwrap();
        let a: Vec<f32> = (0..16).map(|i| ((i * 5 % 7) as f32 - 3.0) * 0.2).collect();
        let b: Vec<f32> = (0..16).map(|i| ((i * 3 % 5) as f32 - 2.0) * 0.3).collect();
        let c = t.product(&a, &b).unwrap();
        let q = SphereQuadrature::for_degree(12);
        let mut y = vec![0.0; 16];
        let reference = q
            .project_f64(bands, |s| {
                eval_basis_f64(s, bands, &mut y).unwrap();
                let fa: f64 = y.iter().zip(&a).map(|(y, &a)| y * f64::from(a)).sum();
                let fb: f64 = y.iter().zip(&b).map(|(y, &b)| y * f64::from(b)).sum();
                fa * fb
            })
            .unwrap();
        for (x, r) in c.iter().zip(&reference) {
            assert!((f64::from(*x) - r).abs() < 1e-5);
        }
        // known constant: Γ_000 = 1/sqrt(4π)
        let e0 = t
            .entries()
            .iter()
            .find(|e| e.i == 0 && e.j == 0 && e.k == 0)
            .unwrap();
        assert!((e0.value - 0.282_094_791_773_878_14).abs() < 1e-12);
        assert!(t.product(&a, &[0.0; 9]).is_err());
        assert!(TripleProduct::new(MAX_PRODUCT_BANDS + 1).is_err());
    }

    #[test]
    fn product_matrix_is_symmetric_and_consistent() {
        let t = TripleProduct::new(3).unwrap();
        let a: Vec<f64> = (0..9).map(|i| (i as f64 * 0.37).sin()).collect();
        let b: Vec<f64> = (0..9).map(|i| (i as f64 * 0.91).cos()).collect();
        let m = t.product_matrix_f64(&a);
        for i in 0..9 {
            for j in 0..9 {
                assert!((m[i * 9 + j] - m[j * 9 + i]).abs() < 1e-12);
            }
        }
        let direct = t.product_f64(&a, &b);
        for k in 0..9 {
            let mv: f64 = (0..9).map(|j| m[k * 9 + j] * b[j]).sum();
            assert!((mv - direct[k]).abs() < 1e-12);
        }
    }
}
