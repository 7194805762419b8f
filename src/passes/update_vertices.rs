//! `update vertices`: the flattened scene's mesh-space vertices morphed, skinned or placed by
//! their instances' records into the world vertex buffer (shaders/update_vertices.comp),
//! first in every frame.

use crate::graph::{Buffer, Handle, RenderGraph};
use crate::shaders;

/// Push constants of `shaders/update_vertices.comp` (4 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpdatePush {
    /// Number of vertices.
    pub vertex_count: u32,
}

/// What the pass reads.
pub struct DeformInputs {
    /// Mesh-space vertices (`shine::gpu_scene::Vertex`).
    pub source: Handle<Buffer>,
    /// Per vertex, its skin influences (`SkinVertex`).
    pub skin: Handle<Buffer>,
    /// Morph deltas.
    pub deltas: Handle<Buffer>,
    /// The frame's instance records (`DeformInstance`).
    pub instances: Handle<Buffer>,
    /// The frame's joint matrices.
    pub joints: Handle<Buffer>,
    /// The frame's morph weights.
    pub weights: Handle<Buffer>,
    /// Number of vertices.
    pub vertex_count: u32,
}

/// Adds the pass, writing `world`.
pub fn update_vertices(rg: &mut RenderGraph, inputs: &DeformInputs, world: &mut Handle<Buffer>) {
    rg.compute("update vertices", &shaders::UPDATE_VERTICES_COMP)
        .read("source_vertices", &inputs.source)
        .read("skin_vertices", &inputs.skin)
        .read("morph_deltas", &inputs.deltas)
        .read("deform_instances", &inputs.instances)
        .read("joint_matrices", &inputs.joints)
        .read("morph_weights", &inputs.weights)
        .write("world_vertices", world)
        .push(&UpdatePush {
            vertex_count: inputs.vertex_count,
        })
        .dispatch([inputs.vertex_count, 1, 1]);
}
