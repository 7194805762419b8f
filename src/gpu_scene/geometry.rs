//! The scene's geometry flattened for one draw: every instance's primitives concatenated
//! (instances in [`Scene::instances`] order, then primitives, then vertices), in mesh space,
//! with what deforms them: per vertex its four joints and weights ([`SkinVertex`]), per
//! morphing instance its targets' deltas. The `update vertices` pass
//! (src/passes/update_vertices.rs) moves them into the world vertex buffer every frame; the
//! index buffer is shared by both and never changes.

use glam::{Mat4, Vec3};
use shine_scene::{NO_SKIN, Pose, Scene};

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
    /// Its skin (index into `Scene::skins`), or [`NO_SKIN`].
    pub skin: u32,
    /// Its morph targets' first delta in [`Geometry::deltas`] (pairs of vec4 per vertex and
    /// target, target-major: `delta_base + target · vertex_count + vertex`).
    pub delta_base: u32,
    /// Its mesh's morph target count.
    pub target_count: u32,
}

/// A vertex's skin influences as the `update vertices` pass reads them (32 bytes); all
/// weights zero for a vertex that is not skinned.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SkinVertex {
    /// Joint indices into the instance's skin.
    pub joints: [u32; 4],
    /// Their weights (sum 1).
    pub weights: [f32; 4],
}

/// The flattened geometry.
pub struct Geometry {
    /// Mesh-space vertices; `instance` says whose.
    pub source: Vec<Vertex>,
    /// Triangle list indices into the flattened vertices.
    pub indices: Vec<u32>,
    /// Per vertex, its skin influences.
    pub skin: Vec<SkinVertex>,
    /// Morph deltas: (position, 0), (normal, 0) per vertex and target.
    pub deltas: Vec<[f32; 4]>,
    /// One range per instance.
    pub instances: Vec<InstanceRange>,
}

impl Geometry {
    /// Flattens every instance of `scene` (the set of instances does not change over time:
    /// only their matrices do).
    pub fn flatten(scene: &Scene) -> Result<Self, SceneUploadError> {
        let too_large = |what: &str| SceneUploadError::TooLarge(format!("over 4G {what}"));
        let mut source = Vec::new();
        let mut skin = Vec::new();
        let mut deltas: Vec<[f32; 4]> = Vec::new();
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
                    skin.push(SkinVertex {
                        joints: primitive.joints.get(i).copied().unwrap_or_default(),
                        weights: primitive.weights.get(i).map_or([0.0; 4], |w| w.to_array()),
                    });
                }
                indices.extend(primitive.indices.iter().map(|i| base + i));
            }
            let vertex_count =
                u32::try_from(source.len()).map_err(|_| too_large("vertices"))? - first_vertex;
            let target_count = mesh.target_count();
            let delta_base = u32::try_from(deltas.len() / 2).map_err(|_| too_large("deltas"))?;
            for target in 0..target_count {
                for primitive in &mesh.primitives {
                    let t = primitive.targets.get(target);
                    for i in 0..primitive.positions.len() {
                        let get = |v: Option<&Vec<Vec3>>| {
                            v.and_then(|v| v.get(i)).copied().unwrap_or_default()
                        };
                        deltas.push(get(t.map(|t| &t.positions)).extend(0.0).to_array());
                        deltas.push(get(t.map(|t| &t.normals)).extend(0.0).to_array());
                    }
                }
            }
            instances.push(InstanceRange {
                mesh: instance.mesh,
                node: instance.node,
                first_vertex,
                vertex_count,
                first_triangle,
                skin: instance.skin,
                delta_base,
                target_count: target_count as u32,
            });
        }
        if indices.is_empty() {
            return Err(SceneUploadError::Empty);
        }
        u32::try_from(indices.len()).map_err(|_| too_large("indices"))?;
        Ok(Self {
            source,
            indices,
            skin,
            deltas,
            instances,
        })
    }
}

/// One instance as the `update vertices` pass reads it (160 bytes): how its mesh-space
/// vertices reach the world (`shaders/include/deform.glsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DeformInstance {
    /// Placement of its unskinned vertices: the node's world matrix.
    pub world: [[f32; 4]; 4],
    /// Inverse transpose of its upper 3×3 (normals), as a 4×4.
    pub normal: [[f32; 4]; 4],
    /// First joint matrix of its skin in the frame's joint buffer ([`NO_SKIN`]: rigid),
    /// first delta, morph target count, first weight in the frame's weight buffer.
    pub deform: [u32; 4],
    /// First vertex, vertex count, padding.
    pub range: [u32; 4],
}

/// The frame's deformation data: one record per instance, the joint matrices of every skin
/// and the morph weights of every morphing instance, concatenated.
pub struct DeformFrame {
    /// Per instance.
    pub instances: Vec<DeformInstance>,
    /// Every skin's joint matrices.
    pub joints: Vec<[[f32; 4]; 4]>,
    /// Every morphing instance's weights.
    pub weights: Vec<f32>,
}

impl DeformFrame {
    /// The records of `instances` in `pose`.
    pub fn new(instances: &[InstanceRange], pose: &Pose) -> Self {
        let mut joint_base = Vec::with_capacity(pose.joints.len());
        let mut joints = Vec::new();
        for skin in &pose.joints {
            joint_base.push(joints.len() as u32);
            joints.extend(skin.iter().map(Mat4::to_cols_array_2d));
        }
        let mut weights = Vec::new();
        let records = instances
            .iter()
            .map(|r| {
                let world = pose
                    .world
                    .get(r.node as usize)
                    .copied()
                    .unwrap_or(Mat4::IDENTITY);
                let normal = Mat4::from_mat3(glam::Mat3::from_mat4(world).inverse().transpose());
                let weight_base = weights.len() as u32;
                let node_weights = pose.weights.get(r.node as usize);
                weights.extend(
                    (0..r.target_count as usize)
                        .map(|k| node_weights.and_then(|w| w.get(k)).copied().unwrap_or(0.0)),
                );
                let skin = joint_base.get(r.skin as usize).copied().unwrap_or(NO_SKIN);
                DeformInstance {
                    world: world.to_cols_array_2d(),
                    normal: normal.to_cols_array_2d(),
                    deform: [skin, r.delta_base, r.target_count, weight_base],
                    range: [r.first_vertex, r.vertex_count, 0, 0],
                }
            })
            .collect();
        Self {
            instances: records,
            joints,
            weights,
        }
    }
}
