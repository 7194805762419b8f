//! `update vertices`: the flattened scene's mesh-space vertices moved into the world vertex
//! buffer by their instances' records (shaders/update_vertices.comp), first in every frame.

use crate::graph::{Buffer, Handle, RenderGraph};
use crate::shaders;

/// Push constants of `shaders/update_vertices.comp` (4 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpdatePush {
    /// Number of vertices.
    pub vertex_count: u32,
}

/// Adds the pass: `world` (written) from `source` and `instances` (read).
pub fn update_vertices(
    rg: &mut RenderGraph,
    source: &Handle<Buffer>,
    instances: &Handle<Buffer>,
    world: &mut Handle<Buffer>,
    vertex_count: u32,
) {
    rg.compute("update vertices", &shaders::UPDATE_VERTICES_COMP)
        .read("source_vertices", source)
        .read("deform_instances", instances)
        .write("world_vertices", world)
        .push(&UpdatePush { vertex_count })
        .dispatch([vertex_count, 1, 1]);
}
