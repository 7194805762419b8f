//! `sample_history`: each HVL's and VPL's own history (issue 43, item 2). The flux cache's
//! records carry identities (light, sample index; `shaders/hvl_flux.comp`), so a sample can be
//! filtered across frames in sample space, with no neighbourhood clip: its flux and its normal
//! (the axis of its SH emission) are an EMA of weight [`AccumulateParams::samples`] over the
//! frames it continued, while its position and radius are this frame's, so a sample that
//! slides with its light does not trail it. What steps at once where a sample crosses a crease
//! (its normal turns by 90°, its colour changes) turns over a few frames instead.
//!
//! A sample starts over on a stated change (`shaders/sample_history.comp`, CPU twin
//! [`crate::reference::sample_history`]): no last frame, no record of its identity last frame,
//! a move of more than [`SAMPLE_JUMP_RADII`] radii (another surface), a flux changed by more
//! than [`SAMPLE_FLUX_RATIO`] either way (its light changed), a normal turned past
//! [`SAMPLE_MIN_NORMAL_COS`].
//!
//! [`AccumulateParams::samples`]: super::accumulate::AccumulateParams::samples

use std::ops::RangeInclusive;

use crate::graph::{Buffer, BufferDesc, Handle, RenderGraph};
use crate::passes::hvl::cache_bytes;
use crate::shaders;

/// Default weight of this frame in each sample's EMA: about two frames of memory. On the
/// motion scenes (docs/quality.md, issue 43) it is what a crease crossing is spread over.
pub const DEFAULT_SAMPLE_WEIGHT: f32 = 0.5;
/// Allowed weights (1: no sample history).
pub const SAMPLE_WEIGHT_RANGE: RangeInclusive<f32> = 0.05..=1.0;
/// A sample that moved more than this many radii (the larger of its two) jumped to another
/// surface (an RSM depth step) and starts over: one radius is the spacing of its neighbours,
/// and a sliding sample moves a fraction of it per frame.
pub const SAMPLE_JUMP_RADII: f32 = 1.0;
/// A sample whose flux changed by more than this ratio either way starts over: its light was
/// switched or cut (the frame's light cut uses the same ratio, `LIGHT_CUT_RATIO`), or it is
/// fading in from nothing.
pub const SAMPLE_FLUX_RATIO: f32 = 2.0;
/// A sample whose normal turned past this cosine (120°) starts over: blending opposite normals
/// would cancel them. A room's creases (90°) are crossed with a blend.
pub const SAMPLE_MIN_NORMAL_COS: f32 = -0.5;

/// Push constants of `shaders/sample_history.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SampleHistoryPush {
    /// Records in the cache (M), and identities per light in the history.
    pub count: u32,
    /// Lights the history holds (identity `light * count + sample index`).
    pub lights: u32,
    /// 1 when the history holds the last frame.
    pub has_history: u32,
    /// Weight of this frame in the blend.
    pub weight: f32,
    /// [`SAMPLE_JUMP_RADII`].
    pub jump: f32,
    /// [`SAMPLE_FLUX_RATIO`].
    pub ratio: f32,
    /// [`SAMPLE_MIN_NORMAL_COS`].
    pub min_cos: f32,
    /// Padding.
    pub pad: u32,
}

impl SampleHistoryPush {
    /// The push of a cache of `count` records over `lights` lights, blending by `weight`.
    pub fn new(count: u32, lights: u32, weight: f32, has_history: bool) -> Self {
        Self {
            count,
            lights,
            has_history: u32::from(has_history),
            weight,
            jump: SAMPLE_JUMP_RADII,
            ratio: SAMPLE_FLUX_RATIO,
            min_cos: SAMPLE_MIN_NORMAL_COS,
            pad: 0,
        }
    }
}

/// Which frame last wrote a technique's sample history, and its layout: the next frame may
/// read it only if it directly follows and holds as many records and lights.
#[derive(Debug, Default)]
pub struct SampleSchedule {
    last: Option<(u64, u32, u32)>,
}

impl SampleSchedule {
    /// Whether `frame` (of `count` records over `lights` lights) has the last frame's history;
    /// records it as the last.
    pub fn next(&mut self, frame: u64, count: u32, lights: u32) -> bool {
        let has = self.last == Some((frame.wrapping_sub(1), count, lights));
        self.last = Some((frame, count, lights));
        has
    }

    /// Forgets the history (a new scene, a light cut, a frame dropped unrun).
    pub fn reset(&mut self) {
        self.last = None;
    }
}

/// What a frame asks of a technique's sample history: the weight of this frame
/// ([`AccumulateParams::samples`]; 1: none) and how many sample sequences the identities' first
/// part ranges over.
///
/// [`AccumulateParams::samples`]: super::accumulate::AccumulateParams::samples
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleSetup {
    /// Weight of this frame.
    pub weight: f32,
    /// Sample sequences: the scene's lights times
    /// [`FACES_PER_LIGHT`](crate::passes::hvl::flux::FACES_PER_LIGHT) (each RSM face owns one,
    /// [`sequence_id`](crate::passes::hvl::flux::sequence_id)).
    pub lights: u32,
}

impl SampleSetup {
    /// The push of this frame's pass over a cache of `count` records (`None` at weight 1: no
    /// history, and `schedule` forgets it); `schedule` records the frame.
    pub fn push(
        self,
        schedule: &mut SampleSchedule,
        frame: u64,
        count: u32,
    ) -> Option<SampleHistoryPush> {
        if self.weight >= 1.0 || self.lights == 0 {
            schedule.reset();
            return None;
        }
        let has = schedule.next(frame, count, self.lights);
        Some(SampleHistoryPush::new(count, self.lights, self.weight, has))
    }
}

/// Filters `cache` (`push.count` records) in place by each sample's history kept under `key`
/// (a history buffer of `push.lights × push.count` records, cleared before it is written, so
/// an identity missing this frame is no history the next).
pub fn sample_history(
    rg: &mut RenderGraph,
    key: &str,
    cache: &mut Handle<Buffer>,
    push: &SampleHistoryPush,
) {
    let desc = BufferDesc::new(cache_bytes(push.count) * u64::from(push.lights.max(1)));
    let mut history = rg.history_buffer(key, desc);
    rg.fill_buffer(&format!("{key} clear"), &mut history.current, 0);
    rg.compute(key, &shaders::SAMPLE_HISTORY_COMP)
        .write("cache", cache)
        .read("previous", &history.previous)
        .write("current", &mut history.current)
        .push(push)
        .dispatch([push.count, 1, 1]);
}
