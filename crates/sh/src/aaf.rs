//! Paper 004 (axis-aligned filtering for diffuse/glossy indirect light): transfer-function
//! bandlimits, filter widths and per-pixel sampling rates (eq. 15–21, appendix eq. 24 and 26),
//! and the filter's local polynomial fit with the paper's gaussian weights ([`LocalFit`]).
//!
//! Units: frequencies in cycles per unit of the `v` parameterisation (bandlimits) or per world
//! unit (spatial); `z_min`/`z_max` are world-space distances to the nearest/farthest reflector;
//! `d` is the world-space size of a pixel at the receiver (`A_p = d²`).

use crate::{Result, check_range};

/// Ω_h^max of the Lambertian transfer function in 3D, 95% energy (paper 004 §4.2, eq. 18).
pub const OMEGA_H_DIFFUSE: f32 = 2.8;
/// Ω_h^max of the flatland Lambertian transfer function (paper 004 §4.2).
pub const OMEGA_H_DIFFUSE_FLATLAND: f32 = 2.0;
/// Default `α` of `Ω_x^max = α / d` (paper 004 §4.1: "α = 0.3 in most of our renderings").
pub const DEFAULT_ALPHA: f32 = 0.3;
/// Default filter scale `µ` (paper 004 §4.3: "µ = 0.9 adequate in most cases").
pub const DEFAULT_MU: f32 = 0.9;
/// Default importance-sampling factor `γ` for diffuse receivers (paper 004 §4.3).
pub const DEFAULT_GAMMA: f32 = 0.4;

/// Receiver BRDF class, for the transfer-function bandlimit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Transfer {
    /// Lambertian: Ω_h = 2.8 (eq. 18).
    Diffuse,
    /// Blinn-Phong of exponent `m`: Ω_h = 3.6 + 0.084 m (eq. 18 / appendix eq. 24; fitted for
    /// 4 < m < 50).
    BlinnPhong {
        /// Exponent `m`.
        exponent: f32,
    },
    /// Phong of exponent `m`: Ω_h = 4.27 + 0.15 m (appendix eq. 26).
    Phong {
        /// Exponent `m`.
        exponent: f32,
    },
}

/// Ω_h^max of a transfer function (eq. 18, 24, 26). Exponents are clamped to `≥ 0`.
pub fn transfer_bandlimit(t: Transfer) -> f32 {
    match t {
        Transfer::Diffuse => OMEGA_H_DIFFUSE,
        Transfer::BlinnPhong { exponent } => 3.6 + 0.084 * exponent.max(0.0), // eq. 24, paper 004
        Transfer::Phong { exponent } => 4.27 + 0.15 * exponent.max(0.0),      // eq. 26, paper 004
    }
}

/// Largest Blinn-Phong exponent of the appendix's fit (eq. 24 is fitted for 4 < m < 50).
pub const BLINN_PHONG_EXPONENT_MAX: f32 = 50.0;

/// The Blinn-Phong exponent with the same lobe width as GGX of perceptual `roughness`
/// (α = roughness²): `m = 2/α² − 2` (Walter et al. 2007, §5.2), clamped to
/// `[0, BLINN_PHONG_EXPONENT_MAX]`.
pub fn blinn_phong_exponent(roughness: f32) -> f32 {
    let alpha = (roughness * roughness).max(1e-3);
    (2.0 / (alpha * alpha) - 2.0).clamp(0.0, BLINN_PHONG_EXPONENT_MAX)
}

/// Ω_h of a metallic-roughness receiver: the diffuse bandlimit `omega_h` blended by `metallic`
/// towards the Blinn-Phong bandlimit (eq. 24) of its GGX lobe ([`blinn_phong_exponent`]),
/// never below `omega_h`. Dielectrics keep the diffuse bandlimit (their specular lobe carries a
/// few percent of the energy); metals take the glossy one.
pub fn receiver_bandlimit(omega_h: f32, roughness: f32, metallic: f32) -> f32 {
    let glossy = transfer_bandlimit(Transfer::BlinnPhong {
        exponent: blinn_phong_exponent(roughness),
    });
    let m = metallic.clamp(0.0, 1.0);
    omega_h + (glossy.max(omega_h) - omega_h) * m
}

/// Per-pixel inputs of the AAF formulas.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PixelFootprint {
    /// `z_min > 0`: distance to the nearest reflector seen from the pixel.
    pub z_min: f32,
    /// `z_max ≥ z_min`: distance to the farthest reflector.
    pub z_max: f32,
    /// `d > 0`: projected world-space size of the pixel (`A_p = d²`, `Ω_pix^max = 1/d`).
    pub pixel_size: f32,
}

impl PixelFootprint {
    fn validate(self) -> Result<Self> {
        check_range("z_min", f64::from(self.z_min), 1e-30, f64::MAX, "> 0")?;
        check_range(
            "z_max",
            f64::from(self.z_max),
            f64::from(self.z_min),
            f64::MAX,
            "≥ z_min",
        )?;
        check_range(
            "pixel size",
            f64::from(self.pixel_size),
            1e-30,
            f64::MAX,
            "> 0",
        )?;
        Ok(self)
    }
}

/// Eq. 15: `Ω_x^r = µ · min(Ω_h^max / z_min, Ω_x^max)`, `Ω_x^max = α / d` (`0 < α < 1`).
pub fn filter_bandwidth(omega_h: f32, px: PixelFootprint, alpha: f32, mu: f32) -> Result<f32> {
    let px = px.validate()?;
    check_range("α", f64::from(alpha), 1e-6, 1.0, "0 < α ≤ 1")?;
    check_range("µ", f64::from(mu), 1e-6, 1e6, "> 0")?;
    let omega_x_max = f64::from(alpha) / f64::from(px.pixel_size);
    Ok((f64::from(mu) * (f64::from(omega_h) / f64::from(px.z_min)).min(omega_x_max)) as f32)
}

/// Eq. 16: world-space standard deviation of the gaussian screen filter, `β = 2 / Ω_x^r`
/// (the Fourier-space standard deviation is `Ω_x^r / 2`). Divide by the pixel size for pixels.
pub fn filter_width(omega_r_x: f32) -> Result<f32> {
    let w = check_range("Ω_x^r", f64::from(omega_r_x), 1e-30, f64::MAX, "> 0")?;
    Ok((2.0 / w) as f32)
}

/// Eq. 19: minimum sampling rates `(Ω_x^*, Ω_v^*)`:
/// `Ω_x^* = Ω_h/z_min + α Ω_pix^max`, `Ω_v^* = Ω_h (1 + z_max/z_min)`.
pub fn min_sampling_rates(omega_h: f32, px: PixelFootprint, alpha: f32) -> Result<(f32, f32)> {
    let px = px.validate()?;
    let (h, zmin, zmax) = (f64::from(omega_h), f64::from(px.z_min), f64::from(px.z_max));
    let x = h / zmin + f64::from(alpha) / f64::from(px.pixel_size);
    let v = h * (1.0 + zmax / zmin);
    Ok((x as f32, v as f32))
}

/// Eq. 21 (eq. 20 for `µ = γ = 1`): samples per pixel
/// `n(µ) = γ (µ Ω_h sqrt(A_p)/z_min + α)² Ω_h² (1 + µ z_max/z_min)²`, `sqrt(A_p) = d`.
pub fn samples_per_pixel(
    omega_h: f32,
    px: PixelFootprint,
    alpha: f32,
    mu: f32,
    gamma: f32,
) -> Result<f32> {
    let px = px.validate()?;
    check_range("µ", f64::from(mu), 1e-6, 1e6, "> 0")?;
    check_range("γ", f64::from(gamma), 0.0, 1e6, "≥ 0")?;
    let (h, zmin, zmax, d) = (
        f64::from(omega_h),
        f64::from(px.z_min),
        f64::from(px.z_max),
        f64::from(px.pixel_size),
    );
    let mu = f64::from(mu);
    let a = mu * h * d / zmin + f64::from(alpha);
    let b = 1.0 + mu * zmax / zmin;
    Ok((f64::from(gamma) * a * a * h * h * b * b) as f32)
}

/// Degree of the filter's local polynomial fit by default: 2, a weighted quadratic about the
/// centre pixel. Degree 0 is paper 004's filter (eq. 16, a normalised gaussian: the fit of a
/// constant). See [`LocalFit`].
pub const FILTER_DEGREE: u32 = 2;
/// The fit degrees the filter takes: 0 (paper), 1 (linear), 2 (quadratic).
pub const FILTER_DEGREES: std::ops::RangeInclusive<u32> = 0..=2;
/// A fit is used only when its moment matrix's determinant is at least this share of the
/// product of its diagonal; below it the fit drops a degree (too few or too clustered
/// neighbours to pin a slope or a curvature).
pub const FIT_CONDITION_MIN: f32 = 1e-4;

/// The tangent part of the irradiance vector from cosine-weighted samples (shine's, not the
/// paper's; GLSL `AAF_TANGENT_SCALE`). For radiance linear in the direction, `L(ω) = l₀ + l₁·ω`,
/// cosine-weighted samples about `n` have `E[L ω_t] = l₁ₜ / 4` (the tangent second moment of the
/// cosine lobe is `1/4`), and the cosine-weighted mean at a normal tilted from `n` by `δ` changes
/// by `(2/3) l₁·δ`: so `8/3` times the mean of `L ω_t` is the gradient of the mean with respect
/// to the normal. With the mean `M₀` along `n`, `V = M₀ n + (8/3) E[L ω_t]` is the irradiance
/// vector (over π): the mean at a nearby normal `m` is `V·m` to first order in the tilt (the
/// constant part is off by `l₀ (1 − n·m)`: 14% of it at the room's 31° bevels), which the
/// filter evaluates at each pixel's shading normal after smoothing `V` across a normal-mapped
/// surface.
pub const TANGENT_SCALE: f32 = 8.0 / 3.0;

/// One separable pass of the filter at one pixel, as a weighted least-squares fit of a
/// polynomial in `u` (the signed world distance from the centre along the pass's axis, in units
/// of β) to the neighbours' values (`N` channels), with the paper's gaussian weights
/// `exp(−u²/2)`: the filtered value is the fit at `u = 0`. Degree 0 is the paper's normalised
/// gaussian. A gaussian flattens every peak and valley of the light by `O(β²)` (its bias) and,
/// where the normal and plane tests or the image's border cut its support to one side, tilts it
/// by `O(β)`; the quadratic fit is exact for light that varies quadratically along the axis, on
/// either side.
///
/// Each neighbour also carries a precision `p` (the inverse of its value's noise variance, in
/// units of one pixel's mean): its weight is `p exp(−u²/2)`, the weighted least squares of
/// values of unequal noise, and [`Self::precision`] is the fitted value's own. The first pass
/// gives every pixel's mean precision 1; above degree 0, the second weights each row by the
/// precision of the first pass's fit there, so a row fitted from few neighbours (at the image's
/// border, beside an edge, or a quadratic extrapolated from one side) counts less than one
/// fitted from many.
/// GLSL twin: `AafFit` in `shaders/include/aaf.glsl` (nine channels, a mat3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFit<const N: usize = 3> {
    /// `Σ w u^k`, k = 0..4, with `w = p g` and `g` the gaussian.
    s: [f32; 5],
    /// `Σ w u^k y`, k = 0..2, per channel.
    t: [[f32; N]; 3],
    /// `Σ g w u^k = Σ w² u^k / p`, k = 0..4: the moments `V` of the fitted value's noise
    /// variance `cᵀ V c` ([`Self::precision`]).
    v: [f32; 5],
}

impl<const N: usize> Default for LocalFit<N> {
    fn default() -> Self {
        Self {
            s: [0.0; 5],
            t: [[0.0; N]; 3],
            v: [0.0; 5],
        }
    }
}

impl<const N: usize> LocalFit<N> {
    /// Whether any neighbour was added.
    pub fn has_neighbours(&self) -> bool {
        self.s[0] > 0.0
    }

    /// Adds a neighbour at `u` (in units of β) with value `y` of precision `precision`, weighted
    /// by `precision` times the gaussian of `u`.
    pub fn add(&mut self, u: f32, y: [f32; N], precision: f32) {
        let g = (-0.5 * u * u).exp();
        let w = g * precision;
        let mut power = 1.0;
        for k in 0..5 {
            self.s[k] += w * power;
            self.v[k] += g * w * power;
            if k < 3 {
                for (t, y) in self.t[k].iter_mut().zip(y) {
                    *t += w * power * y;
                }
            }
            power *= u;
        }
    }

    /// The coefficients `c` of the fitted value at `u = 0`, `Σ_k c_k Σ w u^k y`, of the highest
    /// degree up to `degree` whose fit is well conditioned ([`FIT_CONDITION_MIN`]); `None`
    /// without neighbours.
    pub fn coefficients(&self, degree: u32) -> Option<[f32; 3]> {
        let [s0, s1, s2, s3, s4] = self.s;
        if s0 <= 0.0 {
            return None;
        }
        let det2 = s0 * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s2 * s3) + s2 * (s1 * s3 - s2 * s2);
        if degree >= 2 && det2 > FIT_CONDITION_MIN * s0 * s2 * s4 {
            return Some(
                [s2 * s4 - s3 * s3, s2 * s3 - s1 * s4, s1 * s3 - s2 * s2].map(|c| c / det2),
            );
        }
        let det1 = s0 * s2 - s1 * s1;
        if degree >= 1 && det1 > FIT_CONDITION_MIN * s0 * s2 {
            return Some([s2 / det1, -s1 / det1, 0.0]);
        }
        Some([1.0 / s0, 0.0, 0.0])
    }

    /// The fitted value at `u = 0` ([`Self::coefficients`]); `None` without neighbours. Not
    /// clamped: a channel may be a signed component (the irradiance vector's); the caller
    /// clamps the light it evaluates at zero.
    pub fn value(&self, degree: u32) -> Option<[f32; N]> {
        let c = self.coefficients(degree)?;
        let [t0, t1, t2] = &self.t;
        Some(std::array::from_fn(|i| {
            c[0] * t0[i] + c[1] * t1[i] + c[2] * t2[i]
        }))
    }

    /// The precision of the fitted value at `u = 0` ([`Self::coefficients`]): the inverse of
    /// `Σ (l² / p)` over the neighbours, `l` the weight the fit gives each value; `None`
    /// without neighbours (or if the inverse is not finite). A gaussian average of `K` values
    /// of precision 1 at `u = 0` has precision `K`; a fit extrapolated from one side may have
    /// less than one value's.
    pub fn precision(&self, degree: u32) -> Option<f32> {
        let c = self.coefficients(degree)?;
        let v = &self.v;
        let variance = c[0] * c[0] * v[0]
            + 2.0 * c[0] * c[1] * v[1]
            + (c[1] * c[1] + 2.0 * c[0] * c[2]) * v[2]
            + 2.0 * c[1] * c[2] * v[3]
            + c[2] * c[2] * v[4];
        let precision = 1.0 / variance;
        (variance > 0.0 && precision.is_finite()).then_some(precision)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn bandlimits() {
        assert_eq!(transfer_bandlimit(Transfer::Diffuse), 2.8);
        assert!((transfer_bandlimit(Transfer::BlinnPhong { exponent: 10.0 }) - 4.44).abs() < 1e-5);
        assert!((transfer_bandlimit(Transfer::Phong { exponent: 10.0 }) - 5.77).abs() < 1e-5);
    }

    #[test]
    fn receiver_bandlimits_blend_from_diffuse_to_glossy() {
        // GGX roughness 1 is a Blinn-Phong exponent 0; sharp lobes clamp at the fit's 50.
        assert_eq!(blinn_phong_exponent(1.0), 0.0);
        assert_eq!(blinn_phong_exponent(0.1), BLINN_PHONG_EXPONENT_MAX);
        let alpha: f32 = 0.5 * 0.5;
        assert!((blinn_phong_exponent(0.5) - (2.0 / (alpha * alpha) - 2.0)).abs() < 1e-4);
        // Dielectrics keep Ω_h; metals take 3.6 + 0.084 m; half-metals lie between.
        assert_eq!(receiver_bandlimit(2.8, 0.3, 0.0), 2.8);
        let glossy = 3.6 + 0.084 * blinn_phong_exponent(0.3);
        assert!((receiver_bandlimit(2.8, 0.3, 1.0) - glossy).abs() < 1e-5);
        assert!((receiver_bandlimit(2.8, 0.3, 0.5) - 0.5 * (2.8 + glossy)).abs() < 1e-5);
        // A rough metal's Blinn-Phong bandlimit (3.6) is above the diffuse one: never below.
        assert!(receiver_bandlimit(2.8, 1.0, 1.0) >= 2.8);
    }

    #[test]
    fn filter_and_rates() {
        let px = PixelFootprint {
            z_min: 0.5,
            z_max: 2.0,
            pixel_size: 0.01,
        };
        // Ω_h/z_min = 5.6 < α/d = 30 → Ω_x^r = µ 5.6
        let w = filter_bandwidth(2.8, px, 0.3, 1.0).unwrap();
        assert!((w - 5.6).abs() < 1e-5);
        assert!((filter_width(w).unwrap() - 2.0 / 5.6).abs() < 1e-6);
        // very close reflector: clamped by the pixel frequency
        let close = PixelFootprint { z_min: 0.01, ..px };
        assert!((filter_bandwidth(2.8, close, 0.3, 1.0).unwrap() - 30.0).abs() < 1e-4);
        let (x, v) = min_sampling_rates(2.8, px, 0.3).unwrap();
        assert!((x - (5.6 + 30.0)).abs() < 1e-4 && (v - 2.8 * 5.0).abs() < 1e-5);
        // eq. 20 = eq. 21 with µ = γ = 1: (2.8·0.01/0.5 + 0.3)² · 2.8² · 5²
        let n = samples_per_pixel(2.8, px, 0.3, 1.0, 1.0).unwrap();
        let expect = (0.056f32 + 0.3).powi(2) * 7.84 * 25.0;
        assert!((n - expect).abs() < 1e-3);
        // more filter scale → more samples
        assert!(samples_per_pixel(2.8, px, 0.3, 2.0, 1.0).unwrap() > n);
        let bad = PixelFootprint { z_max: 0.1, ..px };
        assert!(samples_per_pixel(2.8, bad, 0.3, 1.0, 1.0).is_err());
    }

    #[test]
    fn the_quadratic_fit_is_exact_for_quadratic_light_even_one_sided() {
        let light = |u: f32| 2.0 + 0.5 * u - 0.3 * u * u;
        for side in [-3..=3, 0..=4] {
            let mut fit = LocalFit::<3>::default();
            for k in side {
                let u = 0.7 * k as f32;
                fit.add(u, [light(u), 2.0 * light(u), 0.0], 1.0);
            }
            let v: [f32; 3] = fit.value(2).unwrap();
            assert!(
                (v[0] - 2.0).abs() < 1e-4 && (v[1] - 4.0).abs() < 1e-4,
                "{v:?}"
            );
            assert_eq!(v[2], 0.0);
            // The paper's gaussian (degree 0) is biased: by the curvature, or by the slope
            // where the neighbours lie on one side.
            let g = fit.value(0).unwrap();
            assert!((g[0] - 2.0).abs() > 0.05, "{g:?}");
        }
    }

    #[test]
    fn an_ill_conditioned_fit_drops_a_degree() {
        let mut none = LocalFit::<3>::default();
        assert_eq!(none.value(2), None);
        none.add(0.0, [1.0; 3], 1.0);
        assert_eq!(none.value(2), Some([1.0; 3]));
        // Two neighbours pin a line, not a parabola: the linear fit through them.
        let mut two = LocalFit::<3>::default();
        two.add(0.5, [3.0; 3], 1.0);
        two.add(1.0, [4.0; 3], 1.0);
        let v = two.value(2).unwrap();
        assert!((v[0] - 2.0).abs() < 1e-4, "{v:?}");
        // A fit extrapolated below zero is not clamped (a channel may be a signed component).
        let mut down = LocalFit::<3>::default();
        down.add(0.5, [1.0; 3], 1.0);
        down.add(1.0, [3.0; 3], 1.0);
        let v = down.value(1).unwrap();
        assert!((v[0] + 1.0).abs() < 1e-4, "{v:?}");
    }

    #[test]
    fn precision_is_the_inverse_of_the_fitted_values_noise_variance() {
        // Values of unequal precision at one place: the inverse-variance mean, whose precision
        // is the sum.
        let mut same = LocalFit::<1>::default();
        same.add(0.0, [1.0], 4.0);
        same.add(0.0, [6.0], 1.0);
        assert!((same.value(0).unwrap()[0] - 2.0).abs() < 1e-6);
        assert!((same.precision(0).unwrap() - 5.0).abs() < 1e-5);
        assert_eq!(LocalFit::<1>::default().precision(2), None);
        // Any degree, any layout: Σ l² / p, with l the weight the fit gives each value (the
        // fit of a value of 1 there and 0 elsewhere).
        let neighbours = [(-1.3, 0.5), (-0.4, 2.0), (0.2, 1.0), (0.9, 3.0), (1.7, 0.8)];
        let fit_of = |one: Option<usize>| {
            let mut fit = LocalFit::<1>::default();
            for (i, &(u, p)) in neighbours.iter().enumerate() {
                fit.add(u, [f32::from(one == Some(i))], p);
            }
            fit
        };
        for degree in 0..=2 {
            let variance: f32 = (0..neighbours.len())
                .map(|i| fit_of(Some(i)).value(degree).unwrap()[0].powi(2) / neighbours[i].1)
                .sum();
            let precision = fit_of(None).precision(degree).unwrap();
            assert!(
                (precision * variance - 1.0).abs() < 1e-4,
                "degree {degree}: {precision} against 1 / {variance}"
            );
        }
        // A quadratic extrapolated from one side is noisier than one value.
        let mut one_sided = LocalFit::<1>::default();
        for k in 1..=4 {
            one_sided.add(0.5 * k as f32, [0.0], 1.0);
        }
        assert!(one_sided.precision(2).unwrap() < 1.0);
        assert!(one_sided.precision(0).unwrap() > 1.0);
    }

    /// The cosine-weighted mean of `radiance` over the hemisphere about the unit normal `n`
    /// (midpoint quadrature), and the mean of the radiance times the direction's part tangent
    /// to `n`.
    fn cosine_moments(radiance: impl Fn(DVec3) -> f64, n: DVec3) -> (f64, DVec3) {
        let (t, b) = n.any_orthonormal_pair();
        let steps = 400;
        let (mut m0, mut m1, mut weight) = (0.0, DVec3::ZERO, 0.0);
        for i in 0..steps {
            let theta = (i as f64 + 0.5) / steps as f64 * std::f64::consts::FRAC_PI_2;
            let (st, ct) = theta.sin_cos();
            for j in 0..steps {
                let phi = (j as f64 + 0.5) / steps as f64 * std::f64::consts::TAU;
                let (sp, cp) = phi.sin_cos();
                let w = st * cp * t + st * sp * b + ct * n;
                let dw = ct * st; // cosine × the solid angle's sin θ
                let l = radiance(w);
                m0 += l * dw;
                m1 += l * (w - ct * n) * dw;
                weight += dw;
            }
        }
        (m0 / weight, m1 / weight)
    }

    #[test]
    fn the_irradiance_vector_follows_a_tilted_normal() {
        // Radiance linear in the direction, brighter from one side and from above.
        let radiance = |w: DVec3| 1.0 + 0.6 * w.x + 0.3 * w.z;
        let n = DVec3::Z;
        let (m0, m1t) = cosine_moments(radiance, n);
        let v = m0 * n + f64::from(TANGENT_SCALE) * m1t;
        for tilt in [0.02f64, 0.05, 0.1] {
            let m = DVec3::new(tilt.sin(), 0.0, tilt.cos());
            let truth = cosine_moments(radiance, m).0;
            let estimate = v.dot(m);
            // The first-order change in the tilt is exact; what is left is O(tilt²): the
            // constant part l₀ (1 − cos tilt), tilt² / 2 here. A scale of 2 instead of 8/3
            // misses 0.1 × tilt and fails.
            let first_order = m0 + 0.4 * tilt;
            assert!(
                (truth - first_order).abs() < tilt * tilt,
                "tilt {tilt}: {truth} {first_order}"
            );
            assert!(
                (estimate - truth).abs() < 0.7 * tilt * tilt,
                "tilt {tilt}: V.m {estimate}, the mean at m {truth}"
            );
        }
    }
}
