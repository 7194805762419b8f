//! `hvl_resolve`: the HVL gather amortised over frames (paper 001, "GI need not update every
//! frame"). With `hvl.slices = 4` the gather shades one receiver of every 2×2 cell per frame,
//! in turn; `hvl_resolve` (shaders/hvl_resolve.comp) carries the other three over from the
//! previous frame's resolved light, reprojected with the G-buffer's motion vectors, and rejects
//! history where the surface was not visible then (depth or normal too different):
//! `hvl_regather_mask` marks those receivers and a second gather shades them the same frame
//! (paper 001's priority refresh of what moved). Refreshed receivers blend fresh light into
//! valid history ([`RESOLVE_ALPHA`]), the others keep theirs. Tried and dropped
//! (docs/quality.md): filling disocclusions from the cell's fresh value, pulling every receiver
//! towards it each frame, and filling from the nearest of nine refreshed receivers; all
//! flickered more than the per-frame gather. CPU twin:
//! [`crate::reference::resolve::resolve_cpu`].

use glam::Vec3;

use super::HvlError;
use crate::graph::{History, Image, ImageDesc, RenderGraph, vk};
use crate::passes::receivers::Receivers;
use crate::shaders;
use shine_graph::Handle;

/// Weight of the fresh gather at a refreshed receiver whose history is valid (an exponential
/// history: lag of about 1/α refreshes, less flicker).
pub const RESOLVE_ALPHA: f32 = 0.5;
/// Largest relative difference of linear depth between a receiver and its history.
pub const RESOLVE_DEPTH_TOLERANCE: f32 = 0.1;
/// Smallest cosine between a receiver's normal and its history's.
pub const RESOLVE_NORMAL_COS: f32 = 0.9;
/// Receivers per refresh cell (2×2): the HVL gather of a frame shades one of them.
pub const SLICES: u32 = 4;
/// The gather's slice that shades the receivers `hvl_regather_mask` marked
/// (`HVL_REGATHER_SLICE` in shaders/include/hvl_resolve.glsl).
pub const REGATHER_SLICE: u32 = SLICES + 1;

/// Whether history at `depth_then` with normal `n_then` shows the same surface as a receiver
/// at `depth` with unit normal `n` (`resolve_same_surface` in shaders/include/hvl_resolve.glsl).
pub fn same_surface(depth: f32, n: Vec3, depth_then: f32, n_then: Vec3) -> bool {
    depth_then > 0.0
        && (depth_then - depth).abs() <= RESOLVE_DEPTH_TOLERANCE * depth
        && n.dot(n_then) >= RESOLVE_NORMAL_COS * n_then.length()
}

/// The refreshed receiver of every cell in frame `frame`: its offset index k (x = k & 1,
/// y = k >> 1), as the gather's and the resolve's `slice` = 1 + k.
pub fn slice_of_frame(frame: u64) -> u32 {
    1 + (frame % u64::from(SLICES)) as u32
}

/// Push constants of `shaders/hvl_resolve.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ResolvePush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Full-resolution size (of the motion image).
    pub full_extent: [u32; 2],
    /// 1 + k: the refreshed receiver of every cell; 0: every receiver was gathered.
    pub slice: u32,
    /// 1 when the history holds the previous frame.
    pub has_history: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// The resolve's temporal images: light and (normal, linear depth), receiver resolution.
pub struct ResolveHistory {
    /// Resolved light.
    pub light: History<Image>,
    /// Receiver normal and linear depth.
    pub geometry: History<Image>,
}

impl ResolveHistory {
    /// The pair of history images for receivers of `extent`.
    pub fn declare(rg: &mut RenderGraph, extent: [u32; 2]) -> Self {
        let desc = ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, extent[0], extent[1]);
        Self {
            light: rg.history_image("hvl resolved", desc),
            geometry: rg.history_image("hvl resolved geometry", desc),
        }
    }
}

/// Adds `hvl_regather_mask`: marks, in `fresh` (this frame's gather at the receivers of
/// `slice`), every other receiver whose history does not show its surface (alpha -1; 0
/// elsewhere), for a second gather with [`REGATHER_SLICE`]. Returns `fresh` after it.
pub fn hvl_regather_mask(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    fresh: &mut Handle<Image>,
    motion: &Handle<Image>,
    history: &ResolveHistory,
    slice: u32,
    has_history: bool,
) -> Result<(), HvlError> {
    let push = resolve_push(receivers, motion, slice, has_history)?;
    rg.compute("hvl_regather_mask", &shaders::HVL_RESOLVE_COMP_MASK)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("gb_motion", motion)
        .read("history_geometry", &history.geometry.previous)
        .write("fresh", fresh)
        .push(&push)
        .dispatch([push.extent[0], push.extent[1], 1]);
    Ok(())
}

/// The push constants of both variants, after checking `slice`.
fn resolve_push(
    receivers: &Receivers,
    motion: &Handle<Image>,
    slice: u32,
    has_history: bool,
) -> Result<ResolvePush, HvlError> {
    if slice > SLICES {
        return Err(HvlError::Size {
            name: "slice",
            actual: slice.to_string(),
            expected: format!("0..={SLICES}"),
        });
    }
    let full = motion.desc().extent;
    Ok(ResolvePush {
        extent: receivers.extent,
        full_extent: [full.width, full.height],
        slice,
        has_history: u32::from(has_history),
        pad: [0; 2],
    })
}

/// Adds `hvl_resolve`: this frame's gathers `fresh` (at the receivers of `slice` and those
/// `hvl_regather_mask` marked; at every receiver for `slice` 0, which then passes through) and
/// the reprojected history into the history's current images; returns the resolved light.
pub fn hvl_resolve(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    fresh: &Handle<Image>,
    motion: &Handle<Image>,
    history: &mut ResolveHistory,
    slice: u32,
    has_history: bool,
) -> Result<Handle<Image>, HvlError> {
    let push = resolve_push(receivers, motion, slice, has_history)?;
    rg.compute("hvl_resolve", &shaders::HVL_RESOLVE_COMP_RESOLVE)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("fresh", fresh)
        .read("gb_motion", motion)
        .read("history_light", &history.light.previous)
        .read("history_geometry", &history.geometry.previous)
        .write("resolved", &mut history.light.current)
        .write("resolved_geometry", &mut history.geometry.current)
        .push(&push)
        .dispatch([push.extent[0], push.extent[1], 1]);
    Ok(history.light.current)
}
