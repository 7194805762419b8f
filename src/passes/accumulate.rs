//! `accumulate`: the frame's indirect light accumulated over frames (issue 23, "history"), for
//! every GI technique alike; the same pass, in TAA mode ([`AccumulateParams::taa`]), is the direct
//! light's temporal antialiasing (issue 21). Each pixel's history is reprojected with the
//! G-buffer's motion vectors, bilinearly over the taps that show the pixel's surface (the amortised
//! HVL's disocclusion test, [`crate::passes::amortise::same_surface`]), clipped to the current
//! 3×3 neighbourhood's mean ± [`AccumulateParams::clip`] standard deviations per channel (variance
//! clipping, as TAA clips colour history; the box widened to hold the pixel's own light, so that a
//! static image keeps its history where a peak lies outside mean ± σ), and blended with weight 1/n,
//! n the history's length capped at [`AccumulateParams::max_frames`].
//!
//! The indirect light's history is a Holt filter (issue 43): what is clipped and blended is the
//! forecast, the level plus its trend ([`AccumulateParams::trend`]), so a light that changes
//! steadily is followed without the n − 1 frames of lag an EMA has; and the clip box is at
//! least the pixel's own noise from frame to frame ([`AccumulateParams::temporal`]), so light
//! that pops as a whole, whose 3×3 σ is small, keeps the history that averages it. Both live in
//! a second history image ([`AccumulateHistory::state`]). Only where the view holds still: a
//! moving pixel's history is a reprojection the clip judges, and keeps the plain filter. On the
//! motion scenes, against the path-traced truth's flicker, this took HVL on a circling point
//! light from 3.66× to 0.83× and IGI from 4.1× to 1.27× (docs/quality.md; the spatial clip
//! was what held the flicker: unclipped, the same history read 0.65× and 0.88×).
//!
//! Decisions: the clip box is per RGB channel rather than in YCoCg (indirect light is smooth and
//! chroma ghosts were not seen); background pixels are left out of the neighbourhood (their
//! indirect light is 0); the history length lives in the image's alpha, so a disocclusion restarts
//! at n = 1 and converges as fast as the first frames. Shader: `shaders/accumulate.comp`; CPU twin:
//! [`crate::reference::accumulate::accumulate_cpu`].

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use super::gbuffer::GBuffer;
use super::sample_history::{DEFAULT_SAMPLE_WEIGHT, SAMPLE_WEIGHT_RANGE};
use crate::declare::{OutOfRange, Section, Settings};
use crate::graph::{Handle, History, Image, ImageDesc, RenderGraph, vk};
use crate::shaders;

/// Smallest bilinear weight of the history taps that show a pixel's surface; below it the
/// history is rejected (`ACCUMULATE_MIN_WEIGHT` in shaders/include/accumulate.glsl).
pub const ACCUMULATE_MIN_WEIGHT: f32 = 0.01;

/// The indirect light's history restarts where the clip moved it by more than this share of
/// its luminance and the view holds still (`ACCUMULATE_CHANGE`): the light changed beyond the
/// neighbourhood's noise (a light switched off), and a history that kept counting would trail
/// it (issue 43, docs/quality.md). A moving pixel's history is a reprojection the clip judges.
pub const ACCUMULATE_CHANGE: f32 = 0.5;

/// Motion in pixels below which TAA counts a pixel as still: its history may then show any
/// surface of its 3×3 neighbourhood, so a still silhouette, whose jittered samples alternate
/// between two surfaces, keeps its history; a moving pixel's must show its own surface
/// (`TAA_STILL_PIXELS` in shaders/include/accumulate.glsl).
pub const TAA_STILL_PIXELS: f32 = 0.01;

/// Longest history of a moving pixel under TAA (`TAA_MOVING_FRAMES`): its jittered edges
/// alternate between surfaces, and a long history carried one surface's light onto the other
/// (a thin walking figure washed out into the window behind it with 16 frames).
pub const TAA_MOVING_FRAMES: u32 = 2;

/// Smallest 1 − luma of a blend-space value when it is mapped back to radiance
/// (`TAA_MIN_INVERSE`).
pub const TAA_MIN_INVERSE: f32 = 1e-4;

/// Default longest history: blend weight 1/8 once converged (about 8 frames of lag and of
/// noise averaging).
pub const DEFAULT_MAX_FRAMES: u32 = 8;
/// Allowed longest history (1: no accumulation).
pub const MAX_FRAMES_RANGE: RangeInclusive<u32> = 1..=256;
/// Default half-width of the clip box in standard deviations of the current neighbourhood.
/// Colour TAA uses about 1 (Salvi 2016: 0.75–1.25); GI is noisier: on `builtin:animated`, IGI's
/// flicker where the truth holds still is 3.9× the truth's at 1, 3.2× at 2, 2.8× at 3 and 1.4×
/// unclipped, at the same error (docs/quality.md).
pub const DEFAULT_CLIP: f32 = 3.0;
/// Allowed clip half-widths (0: the history is not clipped).
pub const CLIP_RANGE: RangeInclusive<f32> = 0.0..=16.0;

/// Default β of the indirect light's trend (Holt 1957, linear exponential smoothing: the
/// level's change per frame, itself an EMA of weight β). A history of n frames trails a steady
/// ramp by n − 1 frames of its change; the trend carries it forward. On the motion scenes
/// (issue 43, docs/quality.md) 0.1 took HVL's lag on a sweeping spot from +0.019 to +0.011 at
/// less flicker; 0.2 and 0.3 cut the lag further and flickered more (IGI on sweep 1.3× → 2×).
pub const DEFAULT_TREND: f32 = 0.1;
/// Allowed trend weights (0: no trend, the plain EMA).
pub const TREND_RANGE: RangeInclusive<f32> = 0.0..=1.0;

/// Least luminance the temporal σ is spread over ([`AccumulateParams::temporal`];
/// `ACCUMULATE_MIN_LUMINANCE`).
pub const ACCUMULATE_MIN_LUMINANCE: f32 = 1e-6;

/// Longest history of temporal antialiasing (TAA of the direct light): 16 jittered frames, the
/// length of its jitter cycle ([`TAA_JITTER_CYCLE`]) twice over.
pub const TAA_MAX_FRAMES: u32 = 16;
/// Clip half-width of TAA in standard deviations (colour TAA's usual γ, Salvi 2016).
pub const TAA_CLIP: f32 = 1.0;
/// Frames of TAA's jitter sequence before it repeats.
pub const TAA_JITTER_CYCLE: u64 = 8;

/// `[history]`: how an image is accumulated over frames (the indirect light's history:
/// reprojected with the motion vectors, rejected on disocclusion, clipped to the current
/// neighbourhood; TAA's with [`AccumulateParams::taa`]). A single still frame is unchanged (it
/// has no history).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct AccumulateParams {
    /// Longest history n in frames: each frame blends in at least 1/n of its own light (1: no
    /// accumulation).
    #[serde(rename = "frames")]
    #[setting(default = DEFAULT_MAX_FRAMES, range = MAX_FRAMES_RANGE, affects = quality)]
    pub max_frames: u32,
    /// Half-width of the clip box in standard deviations of the current 3×3 neighbourhood
    /// (0: history not clipped).
    #[setting(default = DEFAULT_CLIP, range = CLIP_RANGE, affects = quality)]
    pub clip: f32,
    /// New random numbers every frame for the traced parts (sampled shadows, near field, sky,
    /// specular), so the history averages their noise (true), or each pixel's rays kept from
    /// frame to frame (false): their noise then holds still, as a fixed-seed path tracer's
    /// does, and only a real change of the light moves it (issue 43; docs/quality.md).
    #[setting(default = false, affects = quality)]
    pub reseed: bool,
    /// β of the indirect light's trend (Holt's linear exponential smoothing): the history
    /// forecasts this frame as its level plus the level's change per frame, an EMA of weight β,
    /// so a steadily changing light is followed without the n − 1 frames of lag of a plain
    /// history (0: no trend). The indirect light's history only, where the view holds still.
    #[setting(default = DEFAULT_TREND, range = TREND_RANGE, affects = quality)]
    pub trend: f32,
    /// The clip box widens to the pixel's own noise from frame to frame: σ per channel at least
    /// the standard deviation of the history's innovations (this frame against the forecast,
    /// an EMA of weight 1/n), spread over the channels as the neighbourhood's colour (issue 43).
    /// Smooth light that pops as a whole has a small 3×3 σ, so the spatial box alone rejected
    /// the history that would smooth it. The indirect light's history only, where the view
    /// holds still.
    #[setting(default = true, affects = quality)]
    pub temporal: bool,
    /// Weight of this frame in each HVL's and VPL's own history (issue 43): the samples'
    /// flux and normal are an EMA over the frames each continued, reset on a stated change
    /// (`src/passes/sample_history.rs`), so a sample crossing a crease turns over a few frames
    /// (1: no sample history). Applies with `frames = 1` too: it is the samples', not the
    /// screen's.
    #[setting(default = DEFAULT_SAMPLE_WEIGHT, range = SAMPLE_WEIGHT_RANGE, affects = quality)]
    pub samples: f32,
    /// The indirect light's history: linear radiance, the background passes through. Without
    /// it, TAA: the background accumulates too, a still pixel ([`TAA_STILL_PIXELS`]) keeps
    /// history of any surface of its 3×3 neighbourhood, and the blend is in the space
    /// x / (1 + luma(x)) (Karis 2014: a bright background's history cannot bleed into a dark
    /// object over it, as it does in linear HDR; luma:
    /// [`crate::capture::tonemap::luminance`]). Both restart where the history shows another
    /// surface.
    #[serde(skip)]
    #[setting(default = true)]
    pub geometry: bool,
}

impl AccumulateParams {
    /// Temporal antialiasing of the direct light.
    pub fn taa() -> Self {
        Self {
            max_frames: TAA_MAX_FRAMES,
            clip: TAA_CLIP,
            reseed: false,
            trend: 0.0,
            temporal: false,
            samples: 1.0,
            geometry: false,
        }
    }
}

/// TAA's sub-pixel camera jitter of frame `frame`, in pixels within ±0.5: the Halton (2, 3)
/// points 1 to [`TAA_JITTER_CYCLE`], centred.
pub fn taa_jitter(frame: u64) -> [f32; 2] {
    let index = (frame % TAA_JITTER_CYCLE) as u32 + 1;
    [halton(index, 2) - 0.5, halton(index, 3) - 0.5]
}

/// The radical inverse of `index` in `base`.
fn halton(mut index: u32, base: u32) -> f32 {
    let (mut value, mut scale) = (0.0f32, 1.0f32);
    while index > 0 {
        scale /= base as f32;
        value += scale * (index % base) as f32;
        index /= base;
    }
    value
}

impl AccumulateParams {
    /// Checks both parameters against their ranges.
    pub fn validate(&self) -> Result<(), OutOfRange> {
        self.check_in("history.")
    }
}

/// Push constants of `shaders/accumulate.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AccumulatePush {
    /// Image size.
    pub extent: [u32; 2],
    /// 1 when the history holds the previous frame.
    pub has_history: u32,
    /// Longest history n.
    pub max_frames: f32,
    /// Clip half-width in standard deviations.
    pub clip: f32,
    /// 1: the indirect light's mode, 0: TAA ([`AccumulateParams::geometry`]).
    pub geometry: u32,
    /// β of the trend ([`AccumulateParams::trend`]; 0 under TAA).
    pub trend: f32,
    /// 1: the clip box widens to the temporal noise ([`AccumulateParams::temporal`]).
    pub temporal: u32,
}

/// Format of the accumulated light: rgb radiance, alpha the history length.
pub const ACCUMULATED_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// Format of the filter state: rgb the trend, alpha the innovations' variance (luminance²).
pub const STATE_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// An accumulation's temporal images: the light and the filter's state, each a ping-pong pair.
pub struct AccumulateHistory {
    /// The accumulated light (alpha: history length).
    pub light: History<Image>,
    /// The trend (rgb) and the innovations' variance (alpha) of the indirect light's filter;
    /// zero under TAA.
    pub state: History<Image>,
}

/// The ping-pong pairs of accumulated images `key` (and `key state`) for frames of `extent`.
pub fn accumulate_history(rg: &mut RenderGraph, key: &str, extent: [u32; 2]) -> AccumulateHistory {
    let [w, h] = extent;
    AccumulateHistory {
        light: rg.history_image(key, ImageDesc::new_2d(ACCUMULATED_FORMAT, w, h)),
        state: rg.history_image(
            &format!("{key} state"),
            ImageDesc::new_2d(STATE_FORMAT, w, h),
        ),
    }
}

/// Adds the pass `name` (shaders/accumulate.comp): `current` (this frame's light on the
/// surfaces of `g`) blended into the reprojected history (`history`'s previous images, valid
/// when `has_history`; its geometry is `history_geometry`, the previous frame's `gbuffer
/// history`). Writes the current images and returns the light.
#[allow(clippy::too_many_arguments)]
pub fn accumulate(
    rg: &mut RenderGraph,
    name: &str,
    current: &Handle<Image>,
    g: &GBuffer,
    history_geometry: &Handle<Image>,
    history: &mut AccumulateHistory,
    params: &AccumulateParams,
    has_history: bool,
) -> Result<Handle<Image>, OutOfRange> {
    params.validate()?;
    let push = AccumulatePush {
        extent: g.extent,
        has_history: u32::from(has_history),
        max_frames: params.max_frames as f32,
        clip: params.clip,
        geometry: u32::from(params.geometry),
        trend: if params.geometry { params.trend } else { 0.0 },
        temporal: u32::from(params.geometry && params.temporal),
    };
    rg.compute(name, &shaders::ACCUMULATE_COMP)
        .read("current", current)
        .read("gb_position", &g.position)
        .read("gb_geometric_normal", &g.geometric_normal)
        .read("gb_motion", &g.motion)
        .read("history_geometry", history_geometry)
        .read("history_light", &history.light.previous)
        .write("accumulated", &mut history.light.current)
        .read("history_state", &history.state.previous)
        .write("state", &mut history.state.current)
        .push(&push)
        .dispatch([g.extent[0], g.extent[1], 1]);
    Ok(history.light.current)
}
