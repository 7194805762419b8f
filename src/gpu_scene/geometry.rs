//! The scene's geometry flattened for one draw: every instance's primitives concatenated
//! (instances in [`Scene::instances`] order, then primitives, then vertices), in mesh space.
//! The `update vertices` pass (src/passes/update_vertices.rs) moves them into the world
//! vertex buffer every frame; the index buffer is shared by both and never changes.

use glam::Mat4;
use shine_scene::Scene;

use super::{SceneUploadError, Vertex};

/// Where one instance's vertices and triangles lie in the flattened buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InstanceRange {
    /// The instance's mesh.
    pub mesh: u32,
    /// The instance's node.
    pub node: u32,
    /// Its first vertex.
    pub first_vertex: u32,
    /// Its vertex count.
    pub vertex_count: u32,
    /// Its first triangle (flattened index / 3).
    pub first_triangle: u32,
}

/// The flattened geometry.
pub struct Geometry {
    /// Mesh-space vertices; `instance` says whose.
    pub source: Vec<Vertex>,
    /// Triangle list indices into the flattened vertices.
    pub indices: Vec<u32>,
    /// One range per instance.
    pub instances: Vec<InstanceRange>,
}

impl Geometry {
    /// Flattens every instance of `scene` (the set of instances does not change over time:
    /// only their matrices do).
    pub fn flatten(scene: &Scene) -> Result<Self, SceneUploadError> {
        let too_large = |what: &str| SceneUploadError::TooLarge(format!("over 4G {what}"));
        let mut source = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let mut instances = Vec::new();
        let placed = scene.instances(&scene.rest_world_transforms());
        for (index, instance) in placed.iter().enumerate() {
            let Some(mesh) = scene.meshes.get(instance.mesh as usize) else {
                continue;
            };
            let first_vertex = u32::try_from(source.len()).map_err(|_| too_large("vertices"))?;
            let first_triangle =
                u32::try_from(indices.len() / 3).map_err(|_| too_large("triangles"))?;
            let instance_index = u32::try_from(index).map_err(|_| too_large("instances"))?;
            for primitive in &mesh.primitives {
                let base = u32::try_from(source.len()).map_err(|_| too_large("vertices"))?;
                for (i, p) in primitive.positions.iter().enumerate() {
                    source.push(Vertex {
                        position: p.to_array(),
                        material: primitive.material,
                        normal: primitive
                            .normals
                            .get(i)
                            .map_or([0.0, 1.0, 0.0], |n| n.to_array()),
                        instance: instance_index,
                        tangent: primitive
                            .tangents
                            .get(i)
                            .map_or([1.0, 0.0, 0.0, 1.0], |t| t.to_array()),
                        uv: primitive.uvs.get(i).map_or([0.0; 2], |uv| uv.to_array()),
                        ..Vertex::default()
                    });
                }
                indices.extend(primitive.indices.iter().map(|i| base + i));
            }
            let vertex_count =
                u32::try_from(source.len()).map_err(|_| too_large("vertices"))? - first_vertex;
            instances.push(InstanceRange {
                mesh: instance.mesh,
                node: instance.node,
                first_vertex,
                vertex_count,
                first_triangle,
            });
        }
        if indices.is_empty() {
            return Err(SceneUploadError::Empty);
        }
        u32::try_from(indices.len()).map_err(|_| too_large("indices"))?;
        Ok(Self {
            source,
            indices,
            instances,
        })
    }
}

/// One instance as the `update vertices` pass reads it (128 bytes): how its mesh-space
/// vertices reach the world.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DeformInstance {
    /// Mesh-to-world matrix.
    pub world: [[f32; 4]; 4],
    /// Inverse transpose of its upper 3×3 (normals), as a 4×4.
    pub normal: [[f32; 4]; 4],
}

impl DeformInstance {
    /// The record of an instance placed by `world`.
    pub fn rigid(world: &Mat4) -> Self {
        let normal = Mat4::from_mat3(glam::Mat3::from_mat4(*world).inverse().transpose());
        Self {
            world: world.to_cols_array_2d(),
            normal: normal.to_cols_array_2d(),
        }
    }
}
