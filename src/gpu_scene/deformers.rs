//! Bottom levels of deforming instances (skinned or morphing): one per instance, over its
//! deformed triangles in world space, built once at upload and refitted every frame on the
//! CPU from [`Scene::instance_vertices`] (the topology is kept; the boxes follow the
//! vertices). They come first in the bottom-level buffers, so one prefix copy per frame
//! refreshes all of them (docs/performance.md has the cost).

use shine_scene::bvh::{Bvh, BvhTriangle};
use shine_scene::{Aabb, Instance, Pose, Scene};

use super::bvh::{BottomLevels, local_index, push_triangles, triangle_starts};
use super::geometry::InstanceRange;

/// One deforming instance's bottom level.
struct Deformer {
    /// Index into the instance ranges.
    instance: usize,
    /// Its hierarchy (world space, refitted in place).
    bvh: Bvh,
    /// Per primitive of its mesh, the index of its first triangle within the mesh.
    starts: Vec<u32>,
}

/// Every deforming instance's bottom level.
#[derive(Default)]
pub struct Deformers {
    list: Vec<Deformer>,
}

/// The shine-scene instance a range stands for in `pose`.
fn instance(range: &InstanceRange, pose: &Pose) -> Instance {
    let world = pose
        .world
        .get(range.node as usize)
        .copied()
        .unwrap_or_default();
    Instance {
        world: world.to_cols_array_2d(),
        mesh: range.mesh,
        node: range.node,
        skin: range.skin,
        _pad: 0,
    }
}

/// The deformed triangles of `range` in `pose` (world space).
fn triangles(scene: &Scene, range: &InstanceRange, pose: &Pose) -> Vec<BvhTriangle> {
    let inst = instance(range, pose);
    let mut out = Vec::new();
    let Some(mesh) = scene.meshes.get(range.mesh as usize) else {
        return out;
    };
    for (p, primitive) in mesh.primitives.iter().enumerate() {
        if let Some(v) = scene.instance_vertices(pose, &inst, p) {
            push_triangles(&v.positions, &primitive.indices, p, &mut out);
        }
    }
    out
}

impl Deformers {
    /// Builds the bottom levels of every deforming instance of `ranges` in `pose` and
    /// appends them to `bottom`, which must be empty (they form its prefix). Returns the
    /// deformers and, per range, its root and bounds (`None` for rigid instances).
    pub fn build(
        scene: &Scene,
        ranges: &[InstanceRange],
        pose: &Pose,
        bottom: &mut BottomLevels,
    ) -> (Self, Vec<Option<(u32, Aabb)>>) {
        let mut list = Vec::new();
        let mut roots = vec![None; ranges.len()];
        for (i, range) in ranges.iter().enumerate() {
            if !scene.is_deforming(&instance(range, pose)) {
                continue;
            }
            let starts = scene
                .meshes
                .get(range.mesh as usize)
                .map(triangle_starts)
                .unwrap_or_default();
            let bvh = Bvh::build(triangles(scene, range, pose));
            roots[i] = Some(bottom.append(&bvh, |t| local_index(&starts, t)));
            list.push(Deformer {
                instance: i,
                bvh,
                starts,
            });
        }
        (Self { list }, roots)
    }

    /// Whether there is any deforming instance.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Refits every deformer to `pose`; returns the bottom-level prefix they occupy (nodes
    /// and triangles laid out as at build) and, per range, its root and new bounds.
    pub fn refit(
        &mut self,
        scene: &Scene,
        ranges: &[InstanceRange],
        pose: &Pose,
    ) -> (BottomLevels, Vec<Option<(u32, Aabb)>>) {
        let mut prefix = BottomLevels::default();
        let mut roots = vec![None; ranges.len()];
        for d in &mut self.list {
            let Some(range) = ranges.get(d.instance) else {
                continue;
            };
            let fresh = triangles(scene, range, pose);
            for t in &mut d.bvh.triangles {
                let start = d.starts.get(t.primitive as usize).copied().unwrap_or(0);
                if let Some(f) = fresh.get((start + t.triangle) as usize) {
                    (t.v0, t.v1, t.v2) = (f.v0, f.v1, f.v2);
                }
            }
            d.bvh.refit_bounds();
            let starts = &d.starts;
            roots[d.instance] = Some(prefix.append(&d.bvh, |t| local_index(starts, t)));
        }
        (prefix, roots)
    }
}
