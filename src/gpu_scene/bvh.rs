//! The scene's BVH on the GPU, for ray traversal in compute shaders (`shaders/include/trace.glsl`).
//!
//! Built with shine-scene's binned-SAH [`Bvh`] from the same world transforms as
//! [`crate::gpu_scene::GpuScene::upload`]; the nodes are uploaded as they are ([`BvhNode`],
//! 32 bytes) and every triangle as a [`GpuBvhTriangle`] (48 bytes) whose `index` is its
//! triangle index in the flattened index buffer of [`crate::gpu_scene::GpuScene`]
//! (`indices[3 * index + k]` are its vertices), so a hit is shaded with the interpolated
//! vertex attributes and the material of the raster passes.

use glam::Mat4;
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, vk};
use shine_scene::Scene;
use shine_scene::bvh::{Bvh, BvhNode};

use crate::gpu_scene::SceneUploadError;
use crate::graph::{ExternalState, Handle, RenderGraph};

/// A [`GpuBvh`]'s buffers imported into a frame graph, bound by the names `trace.glsl`
/// declares (`bvh_nodes`, `bvh_triangles`).
#[derive(Debug, Clone, Copy)]
pub struct TraceBuffers {
    /// `bvh_nodes`.
    pub nodes: Handle<crate::graph::Buffer>,
    /// `bvh_triangles`.
    pub triangles: Handle<crate::graph::Buffer>,
}

/// A BVH triangle as `trace.glsl` reads it (48 bytes): world-space vertices and the
/// triangle's index in the flattened scene index buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuBvhTriangle {
    /// First vertex (world space).
    pub v0: [f32; 3],
    /// Triangle index in the flattened index buffer (vertices `3 * index .. 3 * index + 3`).
    pub index: u32,
    /// Second vertex.
    pub v1: [f32; 3],
    /// Padding.
    pub _pad0: u32,
    /// Third vertex.
    pub v2: [f32; 3],
    /// Padding.
    pub _pad1: u32,
}

/// The BVH of a scene at one instant, on the GPU.
pub struct GpuBvh {
    /// Nodes ([`BvhNode`], root first, depth-first order: left child = node + 1).
    pub nodes: Buffer,
    /// Triangles in leaf order ([`GpuBvhTriangle`]).
    pub triangles: Buffer,
    /// Number of nodes.
    pub node_count: u32,
    /// Number of triangles.
    pub triangle_count: u32,
    /// The CPU BVH the buffers were made from (tests compare GPU hits against it).
    pub bvh: Bvh,
    /// For every triangle of `bvh.triangles`, its index in the flattened index buffer.
    pub flat_index: Vec<u32>,
}

impl GpuBvh {
    /// Imports both buffers into `rg`, read-only, in `state` before and after the frame.
    pub fn import(&self, rg: &mut RenderGraph, state: ExternalState) -> TraceBuffers {
        TraceBuffers {
            nodes: rg.import_gpu_buffer(&self.nodes, state, state),
            triangles: rg.import_gpu_buffer(&self.triangles, state, state),
        }
    }

    /// Builds the BVH of `scene` at time `t` (seconds, animations applied) and uploads it.
    pub fn upload(device: &Device, scene: &Scene, t: f32) -> Result<Self, SceneUploadError> {
        let world = scene.world_transforms_at(t);
        let (bvh, flat_index) = build(scene, &world)?;
        let gpu_triangles: Vec<GpuBvhTriangle> = bvh
            .triangles
            .iter()
            .zip(&flat_index)
            .map(|(t, &index)| GpuBvhTriangle {
                v0: t.v0,
                index,
                v1: t.v1,
                v2: t.v2,
                ..GpuBvhTriangle::default()
            })
            .collect();
        let storage = |name, data: &[u8]| {
            Buffer::with_data(
                device,
                &BufferDesc {
                    name,
                    size: data.len().max(16) as u64,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
                data,
            )
        };
        let too_large = |what: &str| SceneUploadError::TooLarge(format!("over 4G BVH {what}"));
        Ok(Self {
            nodes: storage("bvh nodes", bytemuck::cast_slice(&bvh.nodes))?,
            triangles: storage("bvh triangles", bytemuck::cast_slice(&gpu_triangles))?,
            node_count: u32::try_from(bvh.nodes.len()).map_err(|_| too_large("nodes"))?,
            triangle_count: u32::try_from(gpu_triangles.len())
                .map_err(|_| too_large("triangles"))?,
            bvh,
            flat_index,
        })
    }
}

/// Builds the BVH for `world` and maps every BVH triangle to its index in the flattened
/// index buffer (instances in [`Scene::instances`] order, then primitives, then triangles:
/// the order in which `GpuScene::upload` concatenates them).
fn build(scene: &Scene, world: &[Mat4]) -> Result<(Bvh, Vec<u32>), SceneUploadError> {
    let bvh = Bvh::from_scene(scene, world);
    if bvh.triangles.is_empty() {
        return Err(SceneUploadError::Empty);
    }
    // First flat triangle of every (instance, primitive).
    let mut first: Vec<Vec<u64>> = Vec::with_capacity(bvh.instances.len());
    let mut next = 0u64;
    for instance in &bvh.instances {
        let mut starts = Vec::new();
        if let Some(mesh) = scene.meshes.get(instance.mesh as usize) {
            for primitive in &mesh.primitives {
                starts.push(next);
                next += (primitive.indices.len() / 3) as u64;
            }
        }
        first.push(starts);
    }
    let flat_index = bvh
        .triangles
        .iter()
        .map(|t| {
            let start = first
                .get(t.instance as usize)
                .and_then(|s| s.get(t.primitive as usize))
                .copied()
                .unwrap_or(0);
            u32::try_from(start + u64::from(t.triangle))
                .map_err(|_| SceneUploadError::TooLarge("over 4G triangles".into()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((bvh, flat_index))
}

/// `BvhNode` as `trace.glsl` reads it: two vec4 (min, left_or_first bits; max, count bits).
const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);
const _: () = assert!(std::mem::size_of::<GpuBvhTriangle>() == 48);
