//! shine-sh: spherical-harmonics arithmetic for shine, the one trusted CPU implementation.
//!
//! # Conventions (docs/architecture.md, "Conventions")
//!
//! * Real orthonormal SH, coefficient index `l*l + l + m`, **with** the Condon–Shortley phase:
//!   `Y(0,0) = 0.2820948`, `Y(1,-1) = -0.4886025·y`, `Y(1,0) = 0.4886025·z`,
//!   `Y(1,1) = -0.4886025·x`.
//! * "Bands" `n` means degrees `l = 0..n`, i.e. `n²` coefficients (paper 002 calls this the
//!   SH *order*). Paper 003 goes to 20 bands; [`MAX_BANDS`] bounds every API.
//! * SH vectors hold plain projections `f_lm = ∫ f(s) Y_lm(s) ds` (no pre-scaling).
//!   Zonal (ZH) vectors hold the `m = 0` coefficients `g_l` of a function circularly symmetric
//!   about +z. Rotating a ZH vector to direction `d` or convolving with it uses the factor
//!   `sqrt(4π/(2l+1))` (paper 003 eq. 15, paper 002 eq. 7–8).
//! * The public API is `f32`; everything that accumulates (recurrences, quadrature, products,
//!   exponentials, eigen-decompositions) runs in `f64` inside.
//!
//! # Modules
//!
//! | module | what |
//! |---|---|
//! | [`basis`] | evaluation of the basis by a stable normalised recurrence, projection |
//! | [`quadrature`] | Gauss–Legendre × uniform-φ product quadrature over the sphere |
//! | [`legendre`] | Legendre polynomials `P_l` and their integrals |
//! | [`zonal`] | spherical-cap ZH (paper 003 eq. 14) and ZH rotation (eq. 15) |
//! | [`rotation`] | general rotation of SH vectors (Ivanic–Ruedenberg recurrence) |
//! | [`kernels`] | clamped cosine, normalised Phong, paper 000 `r_l`, convolution, windowing |
//! | [`hvl`] | paper 003 HVL geometric factor and radius heuristics |
//! | [`brdf_table`] | paper 003 §4.2 isotropic BRDF SH tables (F and F') |
//! | [`product`] | triple-product tensor and SH products |
//! | [`exp_log`] | SH log and the OL / PS / HYB exponentials of Ren et al. 2006 |
//! | [`sphere_blocker`] | canonical log-visibility table of a sphere blocker (paper 002) |
//! | [`proxy_indirect`] | paper 002 indirect operators D(θ), eq. 12 normalisation |
//! | [`aaf`] | paper 004 bandlimits, filter widths and sampling rates |
//! | [`glsl_tables`] | tables embedded in `shaders/include/sh.glsl`, the GLSL twin |
//!
//! # Normalisation decisions
//!
//! * A spherical light / cap ([`zonal::cap_zh`]) is the plain projection of unit radiance over
//!   the cap (paper 003 eq. 9–14): no division by solid angle or `sin²`, unlike DirectXMath's
//!   cone light. A directional or point light is the projection of a delta,
//!   [`basis::eval_basis`], also unscaled.
//! * Kernels are stored as ZH vectors of the function itself; the convolution factor
//!   `sqrt(4π/(2l+1))` is applied by [`kernels::convolve`] and [`zonal::rotate_zh`], never
//!   folded into stored data.
//! * BRDF tables store `F` and `F'` as plain projections ([`brdf_table`]).
//!
//! # SH exponential accuracy
//!
//! Relative L2 error of the exponential of summed sphere-blocker logs against the exact product
//! of the blockers' visibility (4 bands, details and the PS/HYB parameters in [`exp_log`]):
//!
//! | blockers | OL | PS | HYB |
//! |---|---|---|---|
//! | 2 | 0.008 | 0.007 | 0.006 |
//! | 4 | 0.040 | 0.026 | 0.026 |
//! | 8 | 0.140 | 0.066 | 0.062 |

#![deny(missing_docs)]
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub mod aaf;
pub mod basis;
pub mod brdf_table;
pub mod exp_log;
pub mod glsl_tables;
pub mod hvl;
pub mod kernels;
pub mod legendre;
mod linalg;
pub mod product;
pub mod proxy_indirect;
pub mod quadrature;
pub mod rotation;
pub mod sequence;
pub mod sphere_blocker;
pub mod zonal;

/// Largest band count any function of this crate accepts (degrees `0..MAX_BANDS`).
///
/// Paper 003 renders with up to 20 bands; 32 leaves headroom while keeping every table small.
pub const MAX_BANDS: usize = 32;

/// Errors for invalid input: band counts, vector lengths and parameter ranges.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShError {
    /// A band count outside `1..=MAX_BANDS`.
    #[error("invalid SH band count {bands}: must be 1..={max}", max = MAX_BANDS)]
    InvalidBands {
        /// The band count that was asked for.
        bands: usize,
    },
    /// A coefficient slice whose length is not a perfect square `n²` with `1 ≤ n ≤ MAX_BANDS`.
    #[error("SH vector of length {len} is not n² for a band count n in 1..={max}", max = MAX_BANDS)]
    NotSquare {
        /// The offending length.
        len: usize,
    },
    /// Two SH vectors that must have the same band count do not.
    #[error("SH band counts differ: {a} vs {b}")]
    BandMismatch {
        /// Band count of the first operand.
        a: usize,
        /// Band count of the second operand.
        b: usize,
    },
    /// A scalar parameter outside its documented range.
    #[error("parameter `{name}` = {value} is out of range: {expected}")]
    OutOfRange {
        /// Parameter name as documented.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range expected, in words.
        expected: &'static str,
    },
}

/// Result alias of this crate.
pub type Result<T> = std::result::Result<T, ShError>;

/// Number of coefficients for `bands` bands: `bands²`.
#[inline]
pub const fn num_coeffs(bands: usize) -> usize {
    bands * bands
}

/// Coefficient index of `(l, m)`, `-l ≤ m ≤ l`: `l*l + l + m` (docs/architecture.md, "Conventions").
#[inline]
pub const fn index(l: usize, m: i32) -> usize {
    (l * l + l).wrapping_add_signed(m as isize)
}

/// Checks a band count against `1..=MAX_BANDS`.
pub fn check_bands(bands: usize) -> Result<usize> {
    if (1..=MAX_BANDS).contains(&bands) {
        Ok(bands)
    } else {
        Err(ShError::InvalidBands { bands })
    }
}

/// Band count of a coefficient slice of length `len` (must be `n²`, `1 ≤ n ≤ MAX_BANDS`).
pub fn bands_of_len(len: usize) -> Result<usize> {
    let n = (len as f64).sqrt().round() as usize;
    if n * n == len && (1..=MAX_BANDS).contains(&n) {
        Ok(n)
    } else {
        Err(ShError::NotSquare { len })
    }
}

/// Checks that a scalar lies in `[lo, hi]` (and is not NaN).
pub(crate) fn check_range(
    name: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    expected: &'static str,
) -> Result<f64> {
    if value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(ShError::OutOfRange {
            name,
            value,
            expected,
        })
    }
}

/// Dot product of two SH vectors of equal length, accumulated in `f64`.
///
/// For projections `f`, `g` this is `∫ f g ds` (Parseval), the core of every SH shading step.
pub fn dot(a: &[f32], b: &[f32]) -> Result<f32> {
    let na = bands_of_len(a.len())?;
    let nb = bands_of_len(b.len())?;
    if na != nb {
        return Err(ShError::BandMismatch { a: na, b: nb });
    }
    Ok(a.iter()
        .zip(b)
        .map(|(&x, &y)| f64::from(x) * f64::from(y))
        .sum::<f64>() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn index_layout() {
        assert_eq!(index(0, 0), 0);
        assert_eq!(index(1, -1), 1);
        assert_eq!(index(1, 1), 3);
        assert_eq!(index(2, -2), 4);
        assert_eq!(index(19, 19), 399);
    }

    #[test]
    fn lengths_and_bands() {
        assert_eq!(bands_of_len(16), Ok(4));
        assert!(bands_of_len(15).is_err());
        assert!(bands_of_len(0).is_err());
        assert!(check_bands(0).is_err());
        assert!(check_bands(MAX_BANDS + 1).is_err());
        assert!(dot(&[1.0; 4], &[1.0; 9]).is_err());
        assert_eq!(dot(&[1.0, 2.0, 0.0, 1.0], &[1.0; 4]), Ok(4.0));
    }
}
