//! Paper 003 §4.2: SH projection tables of isotropic BRDFs, `Tab_iso[θ_o] = F_{ω_o}` (eq. 18).
//!
//! For an isotropic BRDF `f(ω_i, ω_o)` in the local shading frame (normal = +z), with the
//! outgoing direction `ω_o = (sin θ_o, 0, cos θ_o)` (φ_o = 0, eq. 17), we store two SH vectors per
//! θ_o sample:
//!
//! * `F`: projection of `cos θ_i · f(ω_i, ω_o)` (the reflectance of eq. 2, for the shading
//!   convolution `L · F`, eq. 19),
//! * `F'`: projection of `f(ω_i, ω_o)` alone (HVL emission, eq. 20).
//!
//! Both are integrated over the upper hemisphere only (the BRDF is zero below).
//!
//! # GPU layout
//!
//! [`BrdfTable::f`] and [`BrdfTable::f_prime`] are plain `f32` arrays of
//! [`THETA_SAMPLES`] rows × `bands²` columns, row-major: coefficient `k` (index `l*l+l+m`) of
//! sample `i` is at `i * bands² + k`. Sample `i` is at `θ_o = (i + 0.5)°`, i.e. at texel centres
//! of a texture of height 90 addressed by `v = θ_o / (π/2)`: upload each array as an R32F image of
//! `bands² × 90` texels (or a storage buffer) and use linear filtering with clamp-to-edge.
//! Because `φ_o = 0` makes `cos θ_i f` even in `φ_i`, all `m < 0` coefficients are zero; they are
//! stored anyway so the GPU indexes with the same `l*l+l+m` everywhere.

use bytemuck::{Pod, Zeroable};
use glam::DVec3;

use crate::quadrature::SphereQuadrature;
use crate::{Result, ShError, check_bands, check_range, num_coeffs};

/// Number of θ_o samples of an isotropic table (one per degree, paper 003 §4.2).
pub const THETA_SAMPLES: usize = 90;

/// θ_o of sample `i`: `(i + 0.5)°` in radians.
pub fn theta_of_sample(i: usize) -> f32 {
    ((i as f64 + 0.5).to_radians()) as f32
}

/// An isotropic BRDF model that can be tabulated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BrdfModel {
    /// Lambertian `albedo / π`.
    Lambert {
        /// Diffuse albedo `k_d` in `[0, 1]`.
        albedo: f32,
    },
    /// Normalised Phong `k_s (n+1)/(2π) max(0, ω_i · r)^n`, `r` the mirror direction of `ω_o`
    /// (paper 000 §3.3.2).
    Phong {
        /// Specular albedo `k_s` in `[0, 1]`.
        ks: f32,
        /// Phong exponent `n ≥ 0`.
        exponent: f32,
    },
    /// GGX microfacet BRDF `D G F / (4 cos θ_i cos θ_o)` with the height-correlated Smith `G` and
    /// the exact (unpolarised, dielectric) Fresnel term, as paper 003 §6 uses.
    Ggx {
        /// GGX width `α` (= perceptual roughness²), in `[1e-3, 1]`.
        alpha: f32,
        /// Index of refraction `η` of the dielectric, in `[1, 4]`.
        ior: f32,
    },
}

/// Exact Fresnel reflectance of an unpolarised dielectric interface, `c = |cos|` to the normal.
pub fn fresnel_dielectric(cos_theta: f64, ior: f64) -> f64 {
    let c = cos_theta.abs();
    let g2 = ior * ior - 1.0 + c * c;
    if g2 < 0.0 {
        return 1.0;
    }
    let g = g2.sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

impl BrdfModel {
    fn validate(self) -> Result<Self> {
        match self {
            BrdfModel::Lambert { albedo } => {
                check_range("albedo", f64::from(albedo), 0.0, 1.0, "0..=1")?;
            }
            BrdfModel::Phong { ks, exponent } => {
                check_range("k_s", f64::from(ks), 0.0, 1.0, "0..=1")?;
                check_range("Phong exponent", f64::from(exponent), 0.0, 1e4, "0..=1e4")?;
            }
            BrdfModel::Ggx { alpha, ior } => {
                check_range("GGX alpha", f64::from(alpha), 1e-3, 1.0, "1e-3..=1")?;
                check_range("ior", f64::from(ior), 1.0, 4.0, "1..=4")?;
            }
        }
        Ok(self)
    }

    /// `f(ω_i, ω_o)` in the local frame (normal +z); zero when either direction is below.
    pub fn eval(self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        match self {
            BrdfModel::Lambert { albedo } => f64::from(albedo) / std::f64::consts::PI,
            BrdfModel::Phong { ks, exponent } => {
                let r = DVec3::new(-wo.x, -wo.y, wo.z);
                let n = f64::from(exponent);
                f64::from(ks) * (n + 1.0) / std::f64::consts::TAU * wi.dot(r).max(0.0).powf(n)
            }
            BrdfModel::Ggx { alpha, ior } => {
                let a2 = f64::from(alpha) * f64::from(alpha);
                let h = (wi + wo).normalize();
                let nh = h.z;
                let t = nh * nh * (a2 - 1.0) + 1.0;
                let d = a2 / (std::f64::consts::PI * t * t);
                let lambda = |c: f64| {
                    let tan2 = (1.0 - c * c).max(0.0) / (c * c);
                    0.5 * (-1.0 + (1.0 + a2 * tan2).sqrt())
                };
                let g = 1.0 / (1.0 + lambda(wi.z) + lambda(wo.z));
                let f = fresnel_dielectric(wi.dot(h), f64::from(ior));
                d * g * f / (4.0 * wi.z * wo.z)
            }
        }
    }
}

/// Hemisphere quadrature resolution used to build a table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HemisphereSampling {
    /// Gauss–Legendre nodes in `cos θ_i` over `[0, 1]`.
    pub n_theta: usize,
    /// Uniform nodes in `φ_i`.
    pub n_phi: usize,
}

impl Default for HemisphereSampling {
    /// 128 × 256: enough for Phong up to `n ≈ 500` and GGX down to `α ≈ 0.1` at 10 bands
    /// (sharper lobes need more).
    fn default() -> Self {
        Self {
            n_theta: 128,
            n_phi: 256,
        }
    }
}

/// Plain-old-data header describing a table for the GPU (`#[repr(C)]`, 16 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Pod, Zeroable)]
pub struct BrdfTableInfo {
    /// Band count `n`.
    pub bands: u32,
    /// Row stride in floats: `n²`.
    pub stride: u32,
    /// Rows: [`THETA_SAMPLES`].
    pub theta_samples: u32,
    /// Padding to 16 bytes.
    pub pad: u32,
}

/// An isotropic BRDF's SH tables `F` and `F'` over 90 θ_o samples (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfTable {
    bands: usize,
    f: Vec<f32>,
    f_prime: Vec<f32>,
}

impl BrdfTable {
    /// Tabulates `model` to `bands` bands with the default hemisphere sampling.
    pub fn build(model: BrdfModel, bands: usize) -> Result<Self> {
        Self::build_with(model, bands, HemisphereSampling::default())
    }

    /// Tabulates `model` to `bands` bands with an explicit hemisphere quadrature.
    pub fn build_with(
        model: BrdfModel,
        bands: usize,
        sampling: HemisphereSampling,
    ) -> Result<Self> {
        let model = model.validate()?;
        check_bands(bands)?;
        if sampling.n_theta == 0 || sampling.n_phi == 0 {
            return Err(ShError::OutOfRange {
                name: "hemisphere sampling",
                value: 0.0,
                expected: "n_theta and n_phi ≥ 1",
            });
        }
        let n2 = num_coeffs(bands);
        let q = SphereQuadrature::cap(DVec3::Z, 0.0, sampling.n_theta, sampling.n_phi);
        // Basis values at the quadrature nodes, shared by all θ_o.
        let mut ys = vec![0.0f64; q.dirs.len() * n2];
        for (k, &d) in q.dirs.iter().enumerate() {
            crate::basis::eval_basis_f64(d, bands, &mut ys[k * n2..(k + 1) * n2])?;
        }
        let mut f = vec![0.0f32; THETA_SAMPLES * n2];
        let mut f_prime = vec![0.0f32; THETA_SAMPLES * n2];
        let mut acc = vec![0.0f64; n2];
        let mut acc_p = vec![0.0f64; n2];
        for i in 0..THETA_SAMPLES {
            let th = f64::from(theta_of_sample(i));
            let wo = DVec3::new(th.sin(), 0.0, th.cos());
            acc.iter_mut().for_each(|a| *a = 0.0);
            acc_p.iter_mut().for_each(|a| *a = 0.0);
            for (k, (&wi, &w)) in q.dirs.iter().zip(&q.weights).enumerate() {
                let v = model.eval(wi, wo) * w;
                if v == 0.0 {
                    continue;
                }
                let y = &ys[k * n2..(k + 1) * n2];
                let vc = v * wi.z;
                for j in 0..n2 {
                    acc[j] += vc * y[j];
                    acc_p[j] += v * y[j];
                }
            }
            for j in 0..n2 {
                f[i * n2 + j] = acc[j] as f32;
                f_prime[i * n2 + j] = acc_p[j] as f32;
            }
        }
        Ok(Self { bands, f, f_prime })
    }

    /// Band count.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// `F` (with cos θ_i): [`THETA_SAMPLES`] × `bands²` floats, row-major (module docs).
    pub fn f(&self) -> &[f32] {
        &self.f
    }

    /// `F'` (without cos θ_i): same layout as [`Self::f`].
    pub fn f_prime(&self) -> &[f32] {
        &self.f_prime
    }

    /// The GPU header of this table.
    pub fn info(&self) -> BrdfTableInfo {
        BrdfTableInfo {
            bands: self.bands as u32,
            stride: num_coeffs(self.bands) as u32,
            theta_samples: THETA_SAMPLES as u32,
            pad: 0,
        }
    }

    /// `F` at `θ_o` (radians, clamped to `[0, π/2]`), linearly interpolated between samples with
    /// clamp-to-edge, exactly as a GPU linear lookup of the layout would.
    pub fn lookup_f(&self, theta_o: f32) -> Vec<f32> {
        Self::lerp_rows(&self.f, num_coeffs(self.bands), theta_o)
    }

    /// `F'` at `θ_o`, interpolated like [`Self::lookup_f`].
    pub fn lookup_f_prime(&self, theta_o: f32) -> Vec<f32> {
        Self::lerp_rows(&self.f_prime, num_coeffs(self.bands), theta_o)
    }

    fn lerp_rows(data: &[f32], n2: usize, theta_o: f32) -> Vec<f32> {
        let deg = f64::from(theta_o).to_degrees();
        let x = if deg.is_finite() {
            (deg - 0.5).clamp(0.0, (THETA_SAMPLES - 1) as f64)
        } else {
            0.0
        };
        let i0 = x.floor() as usize;
        let i1 = (i0 + 1).min(THETA_SAMPLES - 1);
        let t = (x - i0 as f64) as f32;
        (0..n2)
            .map(|j| data[i0 * n2 + j] * (1.0 - t) + data[i1 * n2 + j] * t)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::basis::eval_basis_f64;
    use crate::kernels::clamped_cosine_zh;

    /// Brute force: midpoint rule in (θ_i, φ_i) with `sin θ` weights, independent of the GL rule.
    fn brute_force(model: BrdfModel, bands: usize, theta_o: f64) -> (Vec<f64>, Vec<f64>) {
        let n2 = bands * bands;
        let (nt, np) = (300, 600);
        let wo = DVec3::new(theta_o.sin(), 0.0, theta_o.cos());
        let mut out = vec![0.0; n2];
        let mut out_p = vec![0.0; n2];
        let mut y = vec![0.0; n2];
        let dt = std::f64::consts::FRAC_PI_2 / nt as f64;
        let dp = std::f64::consts::TAU / np as f64;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            for j in 0..np {
                let p = (j as f64 + 0.5) * dp;
                let wi = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
                let v = model.eval(wi, wo) * t.sin() * dt * dp;
                eval_basis_f64(wi, bands, &mut y).unwrap();
                for k in 0..n2 {
                    out[k] += v * wi.z * y[k];
                    out_p[k] += v * y[k];
                }
            }
        }
        (out, out_p)
    }

    #[test]
    fn tables_against_brute_force_hemisphere_integral() {
        let bands = 4;
        for model in [
            BrdfModel::Lambert { albedo: 0.8 },
            BrdfModel::Phong {
                ks: 0.9,
                exponent: 20.0,
            },
            BrdfModel::Ggx {
                alpha: 0.3,
                ior: 1.5,
            },
        ] {
            let table = BrdfTable::build(model, bands).unwrap();
            for &i in &[0usize, 45, 85] {
                let th = f64::from(theta_of_sample(i));
                let (r_f, r_fp) = brute_force(model, bands, th);
                // The grazing GGX lobe converges slowest (3% error at 85.5° with a 64×128 rule,
                // < 1e-3 with the default 128×256).
                let tol = if i == 85 { 4e-3 } else { 2e-3 };
                for (data, reference, with_cos) in
                    [(table.f(), r_f, true), (table.f_prime(), r_fp, false)]
                {
                    let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                    for (k, r) in reference.iter().enumerate() {
                        let v = f64::from(data[i * 16 + k]);
                        assert!(
                            (v - r).abs() < tol * scale + 1e-6,
                            "{model:?} θ_o #{i} k={k} cos={with_cos}: {v} vs {r}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn lambert_table_is_the_clamped_cosine() {
        let table = BrdfTable::build_with(
            BrdfModel::Lambert { albedo: 1.0 },
            5,
            HemisphereSampling {
                n_theta: 16,
                n_phi: 16,
            },
        )
        .unwrap();
        let cc = clamped_cosine_zh(5).unwrap();
        let f = table.lookup_f(0.7);
        for l in 0..5 {
            for m in -(l as i32)..=(l as i32) {
                let expect = if m == 0 {
                    cc[l] / std::f32::consts::PI
                } else {
                    0.0
                };
                assert!((f[crate::index(l, m)] - expect).abs() < 1e-5);
            }
        }
        assert_eq!(table.info().stride, 25);
        assert_eq!(bytemuck::bytes_of(&table.info()).len(), 16);
        assert!(
            BrdfTable::build(
                BrdfModel::Ggx {
                    alpha: 0.0,
                    ior: 1.5
                },
                3
            )
            .is_err()
        );
    }

    /// With ω_o in the xz half-plane every isotropic lobe is even in φ (symmetric under
    /// y → −y), and the φ nodes of the quadrature are too: the coefficients with m < 0 vanish
    /// at every θ_o. The HVL gather keeps only m ≥ 0 of the glossy rows (hvl_gather.comp).
    #[test]
    fn isotropic_tables_have_no_odd_part_in_phi() {
        for sampling in [
            HemisphereSampling::default(),
            HemisphereSampling {
                n_theta: 12,
                n_phi: 24,
            },
        ] {
            for model in [
                BrdfModel::Ggx {
                    alpha: 0.3,
                    ior: 1.5,
                },
                BrdfModel::Phong {
                    ks: 1.0,
                    exponent: 20.0,
                },
            ] {
                let table = BrdfTable::build_with(model, 5, sampling).unwrap();
                let peak = table.f().iter().fold(0.0f32, |m, v| m.max(v.abs()));
                for row in table.f().chunks(25) {
                    for l in 1..5 {
                        for m in 1..=(l as i32) {
                            let odd = row[crate::index(l, -m)].abs();
                            assert!(odd <= 1e-6 * peak, "{model:?} l {l} m -{m}: {odd}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn fresnel_limits() {
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-12);
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-12);
    }
}
