//! Numerical quadrature: Gauss–Legendre on `[-1, 1]` and a product rule over the sphere.
//!
//! The sphere rule uses Gauss–Legendre nodes in `z = cos θ` and uniform nodes in `φ`. With
//! `n_z` nodes and `n_φ` angles it integrates every spherical polynomial of degree
//! `≤ min(2 n_z - 1, n_φ - 1)` exactly, so it is the reference all closed forms are tested
//! against, and the projection routine for smooth functions.

use glam::DVec3;

use crate::{Result, basis, check_bands, num_coeffs};

/// Gauss–Legendre nodes and weights on `[-1, 1]` (`n ≥ 1`), by Newton iteration on `P_n`.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let n = n.max(1);
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    let nf = n as f64;
    for i in 0..n.div_ceil(2) {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (nf + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 1..n {
                let kf = k as f64;
                let p2 = ((2.0 * kf + 1.0) * x * p1 - kf * p0) / (kf + 1.0);
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 1 { x } else { p1 };
            let pm1 = if n == 1 { 1.0 } else { p0 };
            dp = nf * (x * p - pm1) / (x * x - 1.0);
            let dx = p / dp;
            x -= dx;
            if dx.abs() < 1e-15 {
                break;
            }
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = x;
        weights[i] = w;
        nodes[n - 1 - i] = -x;
        weights[n - 1 - i] = w;
    }
    (nodes, weights)
}

/// A product quadrature rule over the unit sphere: directions and solid-angle weights.
#[derive(Debug, Clone)]
pub struct SphereQuadrature {
    /// Unit directions.
    pub dirs: Vec<DVec3>,
    /// Weights in steradians; they sum to `4π`.
    pub weights: Vec<f64>,
}

impl SphereQuadrature {
    /// Rule with `n_z` Gauss–Legendre nodes in `cos θ` and `n_phi` uniform angles in `φ`.
    pub fn new(n_z: usize, n_phi: usize) -> Self {
        let (zs, wz) = gauss_legendre(n_z);
        let n_phi = n_phi.max(1);
        let dphi = std::f64::consts::TAU / n_phi as f64;
        let mut dirs = Vec::with_capacity(zs.len() * n_phi);
        let mut weights = Vec::with_capacity(zs.len() * n_phi);
        for (&z, &w) in zs.iter().zip(&wz) {
            let s = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) * dphi;
                dirs.push(DVec3::new(s * phi.cos(), s * phi.sin(), z));
                weights.push(w * dphi);
            }
        }
        Self { dirs, weights }
    }

    /// Rule over the spherical cap `{s : s·axis ≥ cos_a}` (weights sum to `2π(1 - cos_a)`), with
    /// `n_z` Gauss–Legendre nodes in `s·axis ∈ [cos_a, 1]` and `n_phi` angles; `axis` must be unit.
    ///
    /// Integrals of smooth functions over a cap or a hemisphere (`cos_a = 0`) are then exact to
    /// high degree, instead of suffering the discontinuity of an indicator on the full sphere.
    pub fn cap(axis: DVec3, cos_a: f64, n_z: usize, n_phi: usize) -> Self {
        let cos_a = cos_a.clamp(-1.0, 1.0);
        let (ts, wt) = gauss_legendre(n_z);
        let n_phi = n_phi.max(1);
        let dphi = std::f64::consts::TAU / n_phi as f64;
        let (t1, t2) = axis.any_orthonormal_pair();
        let half = 0.5 * (1.0 - cos_a);
        let mut dirs = Vec::with_capacity(ts.len() * n_phi);
        let mut weights = Vec::with_capacity(ts.len() * n_phi);
        for (&t, &w) in ts.iter().zip(&wt) {
            let z = cos_a + half * (t + 1.0);
            let s = (1.0 - z * z).max(0.0).sqrt();
            for j in 0..n_phi {
                let phi = (j as f64 + 0.5) * dphi;
                dirs.push(t1 * (s * phi.cos()) + t2 * (s * phi.sin()) + axis * z);
                weights.push(w * half * dphi);
            }
        }
        Self { dirs, weights }
    }

    /// Rule exact for spherical polynomials up to degree `degree`.
    pub fn for_degree(degree: usize) -> Self {
        Self::new(degree / 2 + 1, degree + 1)
    }

    /// `∫ f(s) ds` over the sphere.
    pub fn integrate(&self, mut f: impl FnMut(DVec3) -> f64) -> f64 {
        self.dirs
            .iter()
            .zip(&self.weights)
            .map(|(&d, &w)| w * f(d))
            .sum()
    }

    /// Projection `f_lm = ∫ f(s) Y_lm(s) ds` of `f` onto `bands` bands, in `f64`.
    pub fn project_f64(&self, bands: usize, mut f: impl FnMut(DVec3) -> f64) -> Result<Vec<f64>> {
        check_bands(bands)?;
        let mut out = vec![0.0; num_coeffs(bands)];
        let mut y = vec![0.0; num_coeffs(bands)];
        for (&d, &w) in self.dirs.iter().zip(&self.weights) {
            let v = f(d);
            if v == 0.0 {
                continue;
            }
            basis::eval_basis_f64(d, bands, &mut y)?;
            for (o, &yi) in out.iter_mut().zip(&y) {
                *o += w * v * yi;
            }
        }
        Ok(out)
    }

    /// Projection of `f` onto `bands` bands as an `f32` SH vector.
    pub fn project(&self, bands: usize, f: impl FnMut(DVec3) -> f64) -> Result<Vec<f32>> {
        Ok(self
            .project_f64(bands, f)?
            .into_iter()
            .map(|c| c as f32)
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_and_moments() {
        let (x, w) = gauss_legendre(7);
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14);
        // exact for degree 13
        let m: f64 = x.iter().zip(&w).map(|(&x, &w)| w * x.powi(12)).sum();
        assert!((m - 2.0 / 13.0).abs() < 1e-14);
        let q = SphereQuadrature::new(8, 16);
        assert!((q.integrate(|_| 1.0) - 4.0 * std::f64::consts::PI).abs() < 1e-12);
        // ∫ z² = 4π/3
        assert!((q.integrate(|d| d.z * d.z) - 4.0 * std::f64::consts::PI / 3.0).abs() < 1e-12);
        assert!(q.integrate(|d| d.x * d.y).abs() < 1e-12);
    }

    /// `z² = 1/3 + (2/3) P_2(z)`: projection has `f_00 = sqrt(4π)/3`,
    /// `f_20 = (2/3) sqrt(4π/5)`, all else 0.
    #[test]
    fn projection_of_a_polynomial() {
        let q = SphereQuadrature::for_degree(8);
        let f = q.project_f64(4, |d| d.z * d.z).unwrap();
        let pi4 = 4.0 * std::f64::consts::PI;
        assert!((f[0] - pi4.sqrt() / 3.0).abs() < 1e-12);
        assert!((f[6] - 2.0 / 3.0 * (pi4 / 5.0).sqrt()).abs() < 1e-12);
        for (i, c) in f.iter().enumerate() {
            if i != 0 && i != 6 {
                assert!(c.abs() < 1e-12, "coefficient {i} = {c}");
            }
        }
        assert!(q.project(0, |_| 1.0).is_err());
    }
}
