//! A scene flattened for a host engine's rasteriser: world-space vertices and one draw per
//! primitive with its material factors. The host examples (Rust and C++, through the C API)
//! draw their own G-buffers from it.

use crate::Scene;
use glam::{Mat4, Vec3};

/// One primitive of a [`FlatScene`]: its range of indices and its material's factors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatDraw {
    /// First index in [`FlatScene::indices`].
    pub first_index: u32,
    /// Number of indices.
    pub index_count: u32,
    /// Linear base colour (the material's factor; textures are not applied).
    pub base_color: [f32; 3],
    /// Perceptual roughness.
    pub roughness: f32,
    /// Metalness.
    pub metallic: f32,
    /// Index of the primitive's material in the scene (`None`: it has none).
    pub material: Option<usize>,
}

/// Every mesh instance of a scene posed at one time, in world space, in one vertex and one
/// index array.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatScene {
    /// World position (xyz) then world normal (xyz) of each vertex.
    pub vertices: Vec<[f32; 6]>,
    /// Triangle list indices into `vertices`.
    pub indices: Vec<u32>,
    /// One draw per primitive.
    pub draws: Vec<FlatDraw>,
}

/// Factors of a primitive without a material: glTF's default material.
const DEFAULT_DRAW: ([f32; 3], f32, f32) = ([1.0; 3], 1.0, 1.0);

impl Scene {
    /// The nodes with a mesh, posed by the node animation at `t` (morph targets and skins at
    /// rest), flattened to world space.
    pub fn flatten_at(&self, t: f32) -> FlatScene {
        self.flatten(&self.world_transforms_at(t))
    }

    /// The nodes with a mesh placed by `world` (one matrix per node, as
    /// [`Scene::world_transforms_at`] or a host's own pose gives), flattened to world space.
    pub fn flatten(&self, world: &[Mat4]) -> FlatScene {
        let mut flat = FlatScene::default();
        for (node, m) in self.nodes.iter().zip(world) {
            let Some(mesh) = node.mesh.and_then(|i| self.meshes.get(i)) else {
                continue;
            };
            let normal_matrix = m.inverse().transpose();
            for p in &mesh.primitives {
                let base = flat.vertices.len() as u32;
                for (i, pos) in p.positions.iter().enumerate() {
                    let wp = m.transform_point3(*pos);
                    let n = p.normals.get(i).copied().unwrap_or(Vec3::Y);
                    let wn = normal_matrix.transform_vector3(n).normalize_or(Vec3::Y);
                    flat.vertices.push([wp.x, wp.y, wp.z, wn.x, wn.y, wn.z]);
                }
                let material = self.materials.get(p.material as usize);
                let (base_color, roughness, metallic) = material.map_or(DEFAULT_DRAW, |m| {
                    (
                        [m.base_color[0], m.base_color[1], m.base_color[2]],
                        m.roughness,
                        m.metallic,
                    )
                });
                flat.draws.push(FlatDraw {
                    first_index: flat.indices.len() as u32,
                    index_count: p.indices.len() as u32,
                    base_color,
                    roughness,
                    metallic,
                    material: material.map(|_| p.material as usize),
                });
                flat.indices.extend(p.indices.iter().map(|i| i + base));
            }
        }
        flat
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every index lands on a vertex, the draws tile the indices, and the Cornell box's
    /// normals are unit length.
    #[test]
    fn the_cornell_box_flattens_into_consistent_arrays() {
        let scene = Scene::builtin("cornell-box").expect("scene");
        let flat = scene.flatten_at(0.0);
        assert!(!flat.draws.is_empty());
        assert!(
            flat.indices
                .iter()
                .all(|&i| (i as usize) < flat.vertices.len())
        );
        let mut next = 0;
        for d in &flat.draws {
            assert_eq!(d.first_index, next);
            next += d.index_count;
        }
        assert_eq!(next as usize, flat.indices.len());
        for v in &flat.vertices {
            let n = Vec3::new(v[3], v[4], v[5]);
            assert!((n.length() - 1.0).abs() < 1e-4, "{v:?}");
        }
    }
}
