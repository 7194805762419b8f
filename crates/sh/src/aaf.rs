//! Paper 004 (axis-aligned filtering for diffuse/glossy indirect light): transfer-function
//! bandlimits, filter widths and per-pixel sampling rates (eq. 15–21, appendix eq. 24 and 26).
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
