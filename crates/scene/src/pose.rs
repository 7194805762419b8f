//! The time-dependent state of a scene ([`Pose`]: node matrices, morph weights, joint
//! matrices), computed once per frame on the CPU, and the CPU reference of vertex
//! deformation ([`Scene::instance_vertices`]) that a GPU pass mirrors line by line.
//!
//! Deformation, per vertex of a primitive of an instance (glTF 2.0 §3.7.2.2 and §3.7.3):
//!
//! 1. Morph: `p = p0 + Σ_i w_i · Δp_i` and `n = normalize(n0 + Σ_i w_i · Δn_i)` over the
//!    mesh's targets `i` with the node's weights `w_i` (tangents are not morphed).
//! 2. Place, skinned: `S = Σ_k weight_k · jointMatrix[joint_k]` over the vertex's four
//!    influences, with `jointMatrix[j] = world(skin.joints[j]) · inverseBind[j]`; then
//!    `p' = S · (p, 1)`, `n' = normalize(inverse(transpose(mat3(S))) · n)`,
//!    `t' = (normalize(mat3(S) · t.xyz), t.w)`. The node's own transform is not used.
//! 3. Place, rigid (not skinned): the same with `S` the instance's world matrix.

use glam::{Mat3, Mat4, Vec3, Vec4};

use crate::scene::Scene;
use crate::types::{Aabb, Instance, NO_SKIN};

/// The time-dependent state of a scene at one instant.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pose {
    /// World matrix of every node.
    pub world: Vec<Mat4>,
    /// Per node, the morph weights of its mesh (one per target); empty for a node without a
    /// mesh or whose mesh has no morph targets.
    pub weights: Vec<Vec<f32>>,
    /// Per skin, the joint matrices: `world(joint) · inverse bind`, one per joint.
    pub joints: Vec<Vec<Mat4>>,
}

/// The vertices of one primitive of one instance after morphing and skinning, in world
/// space, parallel to the primitive's vertex arrays.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct DeformedVertices {
    /// World positions.
    pub positions: Vec<Vec3>,
    /// Unit world normals.
    pub normals: Vec<Vec3>,
    /// World tangents: unit `xyz`, handedness `w` kept from the primitive.
    pub tangents: Vec<Vec4>,
}

impl Scene {
    /// Morph weights at rest, per node: the node's own weights, else its mesh's defaults,
    /// padded with zeros (or cut) to the mesh's target count; empty without morph targets.
    pub fn rest_weights(&self) -> Vec<Vec<f32>> {
        self.nodes
            .iter()
            .map(|n| {
                let Some(mesh) = n.mesh.and_then(|m| self.meshes.get(m)) else {
                    return Vec::new();
                };
                let mut w = n.weights.clone().unwrap_or_else(|| mesh.weights.clone());
                w.resize(mesh.target_count(), 0.0);
                w
            })
            .collect()
    }

    /// Morph weights per node at time `t` with every animation applied (later animations
    /// win where two drive the same node).
    pub fn weights_at(&self, t: f32) -> Vec<Vec<f32>> {
        let mut weights = self.rest_weights();
        for a in &self.animations {
            a.apply_weights(t, &mut weights);
        }
        weights
    }

    /// The pose for node world matrices and morph weights chosen by the caller: how a host
    /// that animates nodes itself poses the scene. `world` has one matrix per node (e.g.
    /// [`Scene::world_from_locals`] of its own local transforms), `weights` one list per node
    /// (e.g. [`Scene::rest_weights`] or [`Scene::weights_at`]); the joint matrices are
    /// computed from `world`. A joint naming a node outside `world` uses the identity.
    pub fn pose(&self, world: Vec<Mat4>, weights: Vec<Vec<f32>>) -> Pose {
        let joints = self
            .skins
            .iter()
            .map(|skin| {
                skin.joints
                    .iter()
                    .enumerate()
                    .map(|(j, &node)| {
                        let joint_world = world.get(node).copied().unwrap_or(Mat4::IDENTITY);
                        let inverse_bind =
                            skin.inverse_bind.get(j).copied().unwrap_or(Mat4::IDENTITY);
                        joint_world * inverse_bind
                    })
                    .collect()
            })
            .collect();
        Pose {
            world,
            weights,
            joints,
        }
    }

    /// The pose at time `t` (seconds) with every animation applied.
    pub fn pose_at(&self, t: f32) -> Pose {
        self.pose(self.world_transforms_at(t), self.weights_at(t))
    }

    /// The pose at rest: no animation, rest morph weights.
    pub fn rest_pose(&self) -> Pose {
        self.pose(self.rest_world_transforms(), self.rest_weights())
    }

    /// Whether the instance's vertices move relative to each other: it is skinned or its
    /// mesh has morph targets. Other instances are rigid (their `world` matrix places them).
    pub fn is_deforming(&self, instance: &Instance) -> bool {
        instance.skin != NO_SKIN
            || self
                .meshes
                .get(instance.mesh as usize)
                .is_some_and(|m| m.target_count() > 0)
    }

    /// The world-space vertices of primitive `primitive` of `instance` in `pose`: morphed,
    /// then skinned or placed by the instance's world matrix (see the module docs for the
    /// formulas). `None` when the mesh or primitive does not exist.
    ///
    /// This is the reference the GPU deformation pass is tested against. Missing weights
    /// count as zero; a primitive without joints in a skinned instance is placed by its
    /// node's world matrix in `pose`.
    pub fn instance_vertices(
        &self,
        pose: &Pose,
        instance: &Instance,
        primitive: usize,
    ) -> Option<DeformedVertices> {
        let prim = self
            .meshes
            .get(instance.mesh as usize)?
            .primitives
            .get(primitive)?;
        let weights = pose
            .weights
            .get(instance.node as usize)
            .map_or(&[][..], Vec::as_slice);

        // 1. Morph targets (glTF 2.0 §3.7.2.2): base plus weighted deltas.
        let mut positions = prim.positions.clone();
        let mut normals = prim.normals.clone();
        for (target, &w) in prim.targets.iter().zip(weights) {
            if w == 0.0 {
                continue;
            }
            for (p, d) in positions.iter_mut().zip(&target.positions) {
                *p += w * *d;
            }
            for (n, d) in normals.iter_mut().zip(&target.normals) {
                *n += w * *d;
            }
        }
        for n in &mut normals {
            *n = n.normalize_or(Vec3::Y);
        }

        // 2. Skin (glTF 2.0 §3.7.3) or 3. rigid placement.
        let joints = (instance.skin != NO_SKIN && prim.is_skinned())
            .then(|| pose.joints.get(instance.skin as usize))
            .flatten();
        let rigid = if instance.skin == NO_SKIN {
            Mat4::from_cols_array_2d(&instance.world)
        } else {
            let node = pose.world.get(instance.node as usize);
            node.copied().unwrap_or(Mat4::IDENTITY)
        };
        let mut out = DeformedVertices {
            positions: Vec::with_capacity(positions.len()),
            normals: Vec::with_capacity(normals.len()),
            tangents: Vec::with_capacity(prim.tangents.len()),
        };
        for (i, (p, n)) in positions.iter().zip(&normals).enumerate() {
            let m = match joints {
                Some(joint_matrices) => skin_matrix(
                    joint_matrices,
                    prim.joints.get(i).copied().unwrap_or([0; 4]),
                    prim.weights.get(i).copied().unwrap_or(Vec4::X),
                ),
                None => rigid,
            };
            let m3 = Mat3::from_mat4(m);
            let normal_matrix = m3.inverse().transpose();
            out.positions.push(m.transform_point3(*p));
            out.normals.push((normal_matrix * *n).normalize_or(Vec3::Y));
            if let Some(t) = prim.tangents.get(i) {
                let dir = (m3 * t.truncate()).normalize_or(Vec3::X);
                out.tangents.push(dir.extend(t.w));
            }
        }
        Some(out)
    }

    /// World-space bounds of all instances in `pose`: deforming instances from their
    /// deformed vertices, rigid ones from their mesh bounds.
    pub fn pose_bounds(&self, pose: &Pose) -> Aabb {
        let mut bounds = Aabb::EMPTY;
        for inst in self.instances(&pose.world) {
            let Some(mesh) = self.meshes.get(inst.mesh as usize) else {
                continue;
            };
            if !self.is_deforming(&inst) {
                let m = Mat4::from_cols_array_2d(&inst.world);
                bounds = bounds.union(&mesh.bounds().transformed(&m));
                continue;
            }
            for k in 0..mesh.primitives.len() {
                for p in self
                    .instance_vertices(pose, &inst, k)
                    .map(|v| v.positions)
                    .unwrap_or_default()
                {
                    bounds.grow(p);
                }
            }
        }
        bounds
    }
}

/// The skinning matrix of one vertex: `Σ_k weights[k] · joint_matrices[joints[k]]` (glTF 2.0
/// §3.7.3). A joint index outside `joint_matrices` contributes its weight times the identity.
pub fn skin_matrix(joint_matrices: &[Mat4], joints: [u32; 4], weights: Vec4) -> Mat4 {
    let mut m = Mat4::ZERO;
    for (j, w) in joints.into_iter().zip(weights.to_array()) {
        let jm = joint_matrices
            .get(j as usize)
            .copied()
            .unwrap_or(Mat4::IDENTITY);
        m += jm * w;
    }
    m
}
