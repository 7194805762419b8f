//! The AAF passes' parameters, their ranges and defaults (paper 004's, and shine's named
//! departures), and what the passes refuse.

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};

use crate::passes::amortise;
use crate::passes::igi::MAX_STORAGE_BUFFER;

/// Ω_h of a Lambertian receiver (paper 004 eq. 18): the default bandlimit.
pub const OMEGA_H: f32 = shine_sh::aaf::OMEGA_H_DIFFUSE;
/// Bandlimits Ω_h the settings take.
pub const OMEGA_H_RANGE: RangeInclusive<f32> = 0.1..=100.0;
/// Filter scales μ the settings take (paper: 0.9; larger μ narrows the filter and samples more).
pub const MU_RANGE: RangeInclusive<f32> = 0.01..=100.0;
/// Samples of the first pass the settings take (paper: 16).
pub const FIRST_SAMPLES: RangeInclusive<u32> = 1..=1024;
/// The lower spp clamps the settings take: never below the paper's 16.
pub const SPP_MIN: RangeInclusive<u32> = 16..=1024;
/// The upper spp clamps (before the factor μ) the settings take (paper: 100).
pub const SPP_MAX: RangeInclusive<u32> = 16..=10_000;
/// Path vertices after the receiver (1: one-bounce indirect light).
pub const BOUNCES: RangeInclusive<u32> = 1..=8;
/// The lower clamps of z_min the settings take, as a fraction of the scene's [`scene_size`](super::scene_size).
pub const Z_MIN_FRACTION: RangeInclusive<f32> = 1e-4..=1.0;
/// How far from the centre's tangent plane a neighbour may lie, in pixel footprints.
pub const PLANE_TOLERANCE: f32 = 2.0;
/// Largest filter radius in pixels (the gaussian is cut at 2β).
pub const MAX_RADIUS: u32 = 32;
/// Largest roughness difference between a pixel and a neighbour whose specular mean its filter
/// takes: the mean of a glossy lobe depends on the lobe's width (the room's glazed tiles, 0.2 to
/// 0.35, and their grout, 0.9, hold different specular means). The diffuse means need no such
/// test.
pub const ROUGHNESS_TOLERANCE: f32 = 0.1;
/// Default [`AafParams::hit_roughness_min`] (not the paper's: its scenes have no mirror-like
/// reflectors). At 0.5 the room's chrome (0.05) and gold (0.15) no longer make caustic
/// fireflies: its 2048-spp study truth went from a relative noise of 3.2 to 0.08. A fixed
/// constant, not tied to the specular pass's limit (that pass traces lobes seen from the camera,
/// never at AAF's hits).
pub const HIT_ROUGHNESS_MIN: f32 = 0.5;
/// The hits' least roughnesses the parameters take (0: no regularisation).
pub const HIT_ROUGHNESS_RANGE: RangeInclusive<f32> = 0.0..=1.0;

/// α of `Ω_x^max = α/d` the settings take (paper: 0.3).
pub const ALPHA_RANGE: RangeInclusive<f32> = 1e-3..=1.0;
/// Importance-sampling factors γ of eq. 21 the settings take (paper, diffuse: 0.4).
pub const GAMMA_RANGE: RangeInclusive<f32> = 0.0..=10.0;
/// Normal thresholds of the filter the settings take, in degrees (paper: 10°).
pub const NORMAL_THRESHOLD_RANGE: RangeInclusive<f32> = 0.0..=180.0;

/// `[aaf]`: the parameters of the AAF passes (paper 004, `src/passes/aaf/`), each declared
/// once: the settings' keys, ranges and defaults are these fields'. Defaults are paper 004's
/// (§4.3, §6), except two that are shine's: the filter's quadratic fit
/// ([`shine_sh::aaf::FILTER_DEGREE`]; 0 is the paper's) and the hits' least roughness
/// ([`HIT_ROUGHNESS_MIN`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct AafParams {
    /// Stratified samples per pixel of the first pass (paper: 16).
    #[serde(rename = "samples")]
    #[setting(default = 16, range = FIRST_SAMPLES, lab = 4..=64, affects = both)]
    pub first_samples: u32,
    /// Filter scale μ (eq. 15, 21): larger narrows the filter and samples more.
    #[setting(default = shine_sh::aaf::DEFAULT_MU, range = MU_RANGE, lab = 0.3..=3.0, affects = both)]
    pub mu: f32,
    /// Bandlimit Ω_h of the receiver's transfer function (eq. 18; Lambert: 2.8).
    #[setting(default = OMEGA_H, range = OMEGA_H_RANGE, lab = 1.0..=8.0, affects = both)]
    pub omega_h: f32,
    /// α of `Ω_x^max = α/d` (paper 004 §4.1: 0.3).
    #[setting(default = shine_sh::aaf::DEFAULT_ALPHA, range = ALPHA_RANGE, lab = 0.1..=1.0, affects = both)]
    pub alpha: f32,
    /// Importance-sampling factor γ of eq. 21.
    #[setting(default = shine_sh::aaf::DEFAULT_GAMMA, range = GAMMA_RANGE, lab = 0.0..=2.0, affects = both)]
    pub gamma: f32,
    /// Lower clamp of the samples per pixel.
    #[setting(default = 16, range = SPP_MIN, lab = 16..=64, affects = both)]
    pub spp_min: u32,
    /// Upper clamp of the samples per pixel before the factor μ (the paper's 100μ).
    #[setting(default = 100, range = SPP_MAX, lab = 16..=400, affects = both)]
    pub spp_max: u32,
    /// Path vertices after the receiver (1: one-bounce indirect).
    #[setting(default = 1, range = BOUNCES, lab = 1..=2, affects = both)]
    pub bounces: u32,
    /// Lower clamp of z_min as a fraction of the scene's [`scene_size`](super::scene_size)
    /// (paper: about 2%).
    #[setting(default = 0.02, range = Z_MIN_FRACTION, lab = 0.005..=0.1, affects = both)]
    pub z_min_fraction: f32,
    /// Normal threshold of the filter in degrees (paper: 10°).
    #[setting(default = 10.0, range = NORMAL_THRESHOLD_RANGE, lab = 5.0..=30.0, affects = quality)]
    pub normal_threshold_degrees: f32,
    /// The adaptive second pass (eq. 21); off: uniform sampling at `samples`.
    #[setting(default = true, affects = both)]
    pub adaptive: bool,
    /// The screen-space filter; off: the unfiltered Monte-Carlo mean.
    #[setting(default = true, affects = both)]
    pub filter: bool,
    /// Seed of the samples' random numbers (set by the frame).
    #[serde(skip)]
    #[setting(default = 0)]
    pub seed: u32,
    /// Roughness limit of the frame's traced specular pass (0: none; set by the frame): the
    /// samples' specular BRDF term is scaled by `1 −` [`crate::passes::specular::trace_weight`].
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub specular_limit: f32,
    /// Degree of the filter's local polynomial fit with the paper's gaussian weights
    /// ([`shine_sh::aaf::LocalFit`]): 0 is paper 004's gaussian, 1 linear, 2 quadratic (keeps
    /// the light's peaks, valleys and edges the gaussian flattens and tilts, but removes less
    /// noise where the filter has few neighbours; docs/quality.md).
    #[setting(default = shine_sh::aaf::FILTER_DEGREE, range = shine_sh::aaf::FILTER_DEGREES, affects = quality)]
    pub filter_degree: u32,
    /// Filter the diffuse light as an irradiance vector (shine's; false is the paper's scalar
    /// filter, shading normals tested): each pixel's `V = M₀ n + (8/3) E[L ω_t]`
    /// ([`shine_sh::aaf::TANGENT_SCALE`]), neighbours tested by their geometric normals, the
    /// result evaluated at each pixel's shading normal, so that a normal map does not cut the
    /// filter (docs/quality.md: the room's samples saved at equal error rose from 2.6× to 5.7×).
    #[setting(default = true, affects = quality)]
    pub irradiance_vector: bool,
    /// Least roughness of the BRDF at the samples' hits (path regularisation, Kaplanyan and
    /// Dachsbacher 2013): a point light's highlight on a mirror-like reflector, seen by a
    /// cosine-weighted ray, is a caustic that Monte Carlo gathering cannot sample; rougher,
    /// the same energy spreads into a lobe the rays find.
    #[setting(default = HIT_ROUGHNESS_MIN, range = HIT_ROUGHNESS_RANGE, affects = quality)]
    pub hit_roughness_min: f32,
    /// Pixels per refresh (paper 001): 1 samples every pixel every frame; 4 samples one pixel
    /// per 2×2 cell per frame and reprojects the others' sums from the previous frames
    /// (`aaf_reproject`, [`AafSlice`](super::AafSlice)).
    #[setting(default = 1, one_of = amortise::SLICE_CHOICES, affects = both)]
    pub slices: u32,
    /// Bytes one storage buffer may hold on the device (`maxStorageBufferRange`; lavapipe's is
    /// [`MAX_STORAGE_BUFFER`], NVIDIA's 4 GiB; set by the frame): bounds the per-pixel sums
    /// and filter rows ([`AafParams::check_extent`]).
    #[serde(skip)]
    #[setting(default = MAX_STORAGE_BUFFER)]
    pub storage_limit: u64,
}

/// What the AAF passes refuse.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AafError {
    /// A parameter out of its range.
    #[error("AAF {0}")]
    OutOfRange(#[from] crate::passes::OutOfRange),
    /// A setting outside its declared domain.
    #[error("AAF: {0}")]
    Setting(#[from] crate::declare::OutOfRange),
    /// An amortised dispatch's slice without its marks, or out of range.
    #[error(transparent)]
    Slice(#[from] amortise::AmortiseError),
    /// The per-pixel sums would exceed one storage buffer.
    #[error(
        "AAF per-pixel sums of {width}×{height} pixels need {bytes} bytes, more than the {limit} bytes of one storage buffer on this device: lower the resolution"
    )]
    TooLarge {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// Bytes needed.
        bytes: u64,
        /// Bytes one storage buffer may hold ([`AafParams::storage_limit`]).
        limit: u64,
    },
}

impl AafParams {
    /// Checks every parameter against its declared range, and the frame's specular limit.
    pub fn validate(&self) -> Result<(), AafError> {
        self.check_in("aaf.")?;
        crate::passes::check_range(
            "specular_limit",
            self.specular_limit,
            &crate::passes::specular::LIMIT_RANGE,
        )?;
        Ok(())
    }

    /// Checks that the per-pixel sums of an image of `extent` ([`SUMS_BYTES`](super::SUMS_BYTES)
    /// a pixel, the largest of AAF's buffers) fit one storage buffer of the device.
    pub fn check_extent(&self, extent: [u32; 2]) -> Result<(), AafError> {
        let bytes = u64::from(extent[0]) * u64::from(extent[1]) * super::SUMS_BYTES;
        if bytes > self.storage_limit {
            return Err(AafError::TooLarge {
                width: extent[0],
                height: extent[1],
                bytes,
                limit: self.storage_limit,
            });
        }
        Ok(())
    }

    /// The upper clamp of the sample count, `spp_max · μ`, never below `spp_min`.
    pub fn spp_upper(&self) -> f32 {
        (self.spp_max as f32 * self.mu).max(self.spp_min as f32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_too_large_for_one_storage_buffer_is_refused() {
        let lavapipe = AafParams::default();
        assert!(lavapipe.check_extent([1280, 720]).is_ok());
        let message = lavapipe.check_extent([1920, 1080]).unwrap_err().to_string();
        assert!(
            message.contains("1920×1080") && message.contains("lower the resolution"),
            "{message}"
        );
        let nvidia = AafParams {
            storage_limit: 4 << 30,
            ..AafParams::default()
        };
        assert!(nvidia.check_extent([3840, 2160]).is_ok());
    }
}
