//! Automatic exposure (issue 21, item 5): the `exposure_reduce` and `exposure_resolve` passes
//! (`shaders/exposure.comp`) and their CPU twin.
//!
//! The exposure maps the frame's log-average luminance `L̄ = exp(mean log(δ + L))` (Reinhard et
//! al. 2002, eq. 1, over every rendered pixel of direct plus indirect light, Rec. 709
//! luminance) to the key `a` (eq. 2: middle grey, [`KEY`] = 0.18): `e = a / L̄`, clamped to
//! [`EXPOSURE_RANGE`]. In a sequence it moves towards that target by a fraction
//! [`ExposureParams::adaptation`] of the way per frame, in log space (eye adaptation), starting
//! at the target on a frame without history. The composite multiplies the tonemapped frame's
//! radiance by `e` on top of the manual exposure (`output.exposure`, then a compensation
//! factor); the HDR frame keeps the manual exposure only.

use std::ops::RangeInclusive;

use glam::Vec3;

use crate::capture::tonemap::luminance;
use crate::graph::{Buffer, BufferDesc, Handle, History, Image, RenderGraph};
use crate::shaders;

/// The key `a` of Reinhard et al. 2002 (eq. 2): the log-average maps to middle grey.
pub const KEY: f32 = 0.18;
/// δ of the log average (eq. 1): keeps black pixels finite (GLSL `EXPOSURE_LUMINANCE_FLOOR`).
pub const LUMINANCE_FLOOR: f32 = 1e-4;
/// The exposures automatic exposure may choose.
pub const EXPOSURE_RANGE: RangeInclusive<f32> = 1e-3..=1e3;
/// Default fraction of the way (in log exposure) a frame moves towards its target.
pub const ADAPTATION: f32 = 0.1;
/// Adaptation rates the settings take (1: no smoothing).
pub const ADAPTATION_RANGE: RangeInclusive<f32> = 0.001..=1.0;
/// Pixels of one workgroup of the reduce pass (16 × 16).
const TILE: u32 = 16;

/// Parameters of automatic exposure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExposureParams {
    /// The key `a` the log-average luminance is mapped to.
    pub key: f32,
    /// Fraction of the way in log exposure a frame moves towards its target (1: at once).
    pub adaptation: f32,
}

impl Default for ExposureParams {
    fn default() -> Self {
        Self {
            key: KEY,
            adaptation: ADAPTATION,
        }
    }
}

/// Push constants of `shaders/exposure.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ExposurePush {
    /// Rendered size (reduce).
    pub extent: [u32; 2],
    /// Workgroups of the reduce pass (resolve).
    pub partial_count: u32,
    /// 1 when the history holds the last frame's exposure (resolve).
    pub has_history: u32,
    /// [`ExposureParams::key`].
    pub key: f32,
    /// [`ExposureParams::adaptation`].
    pub adaptation: f32,
    /// [`EXPOSURE_RANGE`].
    pub range: [f32; 2],
}

/// Floats of the exposure buffer: the exposure, then the log-average luminance it came from.
pub const EXPOSURE_FLOATS: u64 = 2;

/// The exposure history's buffers (a ping-pong pair under one key).
pub fn exposure_history(rg: &mut RenderGraph) -> History<Buffer> {
    rg.history_buffer("exposure", BufferDesc::new(EXPOSURE_FLOATS * 4))
}

/// Adds `exposure_reduce` over `direct` (+ `indirect`, RGBA16F at the rendered size) and
/// `exposure_resolve`, which writes this frame's exposure into `history.current` from the
/// log-average and, when `has_history`, from `history.previous`.
pub fn exposure(
    rg: &mut RenderGraph,
    direct: &Handle<Image>,
    indirect: Option<&Handle<Image>>,
    history: &mut History<Buffer>,
    has_history: bool,
    params: &ExposureParams,
) -> Handle<Buffer> {
    let e = direct.desc().extent;
    let groups = [e.width.div_ceil(TILE), e.height.div_ceil(TILE)];
    let partial_count = groups[0] * groups[1];
    let push = ExposurePush {
        extent: [e.width, e.height],
        partial_count,
        has_history: u32::from(has_history),
        key: params.key,
        adaptation: params.adaptation,
        range: [*EXPOSURE_RANGE.start(), *EXPOSURE_RANGE.end()],
    };
    let mut partials = rg.create_buffer(
        "exposure_partials",
        BufferDesc::new(u64::from(partial_count) * 8),
    );
    let shader = match indirect {
        Some(_) => &shaders::EXPOSURE_COMP_REDUCE_INDIRECT,
        None => &shaders::EXPOSURE_COMP_REDUCE_DIRECT,
    };
    let mut pass = rg.compute("exposure_reduce", shader);
    pass.read("direct", direct);
    if let Some(indirect) = indirect {
        pass.read("indirect_full", indirect);
    }
    pass.write("partials", &mut partials)
        .push(&push)
        .dispatch([e.width, e.height, 1]);
    rg.compute("exposure_resolve", &shaders::EXPOSURE_COMP_RESOLVE)
        .read("partials", &partials)
        .read("previous", &history.previous)
        .write("exposure", &mut history.current)
        .push(&push)
        .dispatch([TILE, TILE, 1]);
    history.current
}

/// CPU twin of the reduction: `ln L̄ = mean ln(δ + L)` over `radiance` (Rec. 709 luminance,
/// negative luminance as 0, non-finite pixels left out); `None` without a finite pixel.
pub fn log_average(radiance: impl IntoIterator<Item = Vec3>) -> Option<f64> {
    let (mut sum, mut count) = (0.0f64, 0u64);
    for r in radiance {
        let l = luminance(r);
        if l.is_finite() {
            sum += f64::from(LUMINANCE_FLOOR + l.max(0.0)).ln();
            count += 1;
        }
    }
    (count > 0).then(|| sum / count as f64)
}

/// The exposure that maps the log-average `ln_average` to `key`, clamped to [`EXPOSURE_RANGE`].
pub fn target_exposure(ln_average: f64, key: f32) -> f32 {
    ((f64::from(key) / ln_average.exp()) as f32)
        .clamp(*EXPOSURE_RANGE.start(), *EXPOSURE_RANGE.end())
}

/// The exposure a frame takes: `rate` of the way from `previous` to `target` in log space.
pub fn adapt(previous: f32, target: f32, rate: f32) -> f32 {
    (previous.ln() + (target.ln() - previous.ln()) * rate).exp()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_uniform_grey_frame_is_exposed_to_the_key() {
        let grey = Vec3::splat(0.5);
        let ln = log_average(std::iter::repeat_n(grey, 10)).unwrap();
        let e = target_exposure(ln, KEY);
        assert!(((0.5 + LUMINANCE_FLOOR) * e - KEY).abs() < 1e-6, "{e}");
        assert!(log_average(std::iter::empty()).is_none());
        assert_eq!(target_exposure(f64::from(1e-9f32).ln(), KEY), 1e3);
        let half_way = adapt(1.0, 4.0, 0.5);
        assert!((half_way - 2.0).abs() < 1e-6);
        assert_eq!(adapt(3.0, 5.0, 1.0), 5.0);
    }
}
