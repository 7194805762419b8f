//! `gbuffer history`: the G-buffer's geometric normal and linear depth kept across frames in a
//! ping-pong pair of temporal images (`RenderGraph::history_image`), so a frame can read the
//! previous frame's (temporal reuse, disocclusion tests, hosts).

use super::gbuffer::GBuffer;
use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::shaders;

/// Push constants of `shaders/gbuffer_history.comp` (8 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HistoryPush {
    /// Image size.
    pub extent: [u32; 2],
}

/// Format of the history images: geometric normal xyz (the shading normal would change with a
/// normal map's texel under a jittered sample), linear view depth w.
pub const HISTORY_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// Writes this frame's normal and depth into the history; returns the previous frame's
/// (undefined on the first frame of a size: check `Compiler::has_history`).
pub fn gbuffer_history(rg: &mut RenderGraph, g: &GBuffer) -> Handle<Image> {
    let [w, h] = g.extent;
    let mut history = rg.history_image("gbuffer history", ImageDesc::new_2d(HISTORY_FORMAT, w, h));
    rg.compute("gbuffer history", &shaders::GBUFFER_HISTORY_COMP)
        .read("gb_position", &g.position)
        .read("gb_geometric_normal", &g.geometric_normal)
        .write("history", &mut history.current)
        .push(&HistoryPush { extent: [w, h] })
        .dispatch([w, h, 1]);
    history.previous
}
