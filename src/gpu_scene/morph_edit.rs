//! Morph targets rewritten between frames: how a host's deformed vertices (skinning, cloth)
//! reach the scene (`GiContext::deform_mesh`, docs/embedding.md). A host mesh that deforms is
//! a mesh with one morph target at weight 1; each new shape replaces that target's deltas,
//! on the CPU rig (which the deformers' BVH refit reads) and in the GPU delta buffer (which
//! `update vertices` reads), uploaded with the next declared frame.

use super::{GpuScene, SceneUploadError};
use glam::Vec3;

impl GpuScene {
    /// Replaces the deltas of morph target `target` of primitive `primitive` of mesh `mesh`
    /// with `positions` and `normals` (one each per vertex of the primitive), for the next
    /// declared frame and every later one. The primitive's bounds grow to hold the new shape.
    /// A target the scene lacks, a length that does not match or a non-finite delta is
    /// refused and nothing changes.
    pub fn set_morph_target(
        &mut self,
        mesh: usize,
        primitive: usize,
        target: usize,
        positions: &[Vec3],
        normals: &[Vec3],
    ) -> Result<(), SceneUploadError> {
        let refuse = |m: String| Err(SceneUploadError::Update(m));
        let Some(prims) = self.rig.meshes.get(mesh).map(|m| &m.primitives) else {
            return refuse(format!("mesh {mesh} is not in the scene"));
        };
        let Some(prim) = prims.get(primitive) else {
            return refuse(format!("mesh {mesh} has no primitive {primitive}"));
        };
        if target >= prim.targets.len() {
            return refuse(format!(
                "primitive {primitive} of mesh {mesh} has no morph target {target}"
            ));
        }
        let count = prim.positions.len();
        if positions.len() != count || normals.len() != count {
            return refuse(format!(
                "morph target of mesh {mesh}: {} positions and {} normals for {count} vertices",
                positions.len(),
                normals.len()
            ));
        }
        if !positions.iter().chain(normals).all(|v| v.is_finite()) {
            return refuse(format!("morph target of mesh {mesh} is not finite"));
        }
        // Where the primitive's block starts within an instance's deltas (laid out target by
        // target, primitive by primitive, as `Geometry::flatten` does).
        let per_target: usize = prims.iter().map(|p| p.positions.len()).sum();
        let before: usize = prims[..primitive].iter().map(|p| p.positions.len()).sum();
        let within = target * per_target + before;
        for range in self.instances.iter().filter(|r| r.mesh as usize == mesh) {
            let first = 2 * (range.delta_base as usize + within);
            for (i, (p, n)) in positions.iter().zip(normals).enumerate() {
                self.deltas[first + 2 * i] = p.extend(0.0).to_array();
                self.deltas[first + 2 * i + 1] = n.extend(0.0).to_array();
            }
        }
        let prim = &mut self.rig.meshes[mesh].primitives[primitive];
        let morph = &mut prim.targets[target];
        morph.positions = positions.to_vec();
        morph.normals = normals.to_vec();
        for (rest, delta) in prim.positions.iter().zip(positions) {
            prim.bounds.grow(*rest + *delta);
        }
        self.deltas_pending = true;
        self.deltas_edited = true;
        Ok(())
    }

    /// The frame's world bounds (RSM fits, ray offsets) after set targets: recomputed once
    /// per declared frame that follows a [`GpuScene::set_morph_target`], not once per call.
    pub(super) fn refresh_edited_bounds(&mut self) {
        if self.deltas_pending {
            let bounds = self.rig.pose_bounds(&self.state.pose);
            self.state.bounds = (bounds.min, bounds.max);
        }
    }

    /// A declared frame was dropped unrun: an upload of set targets it held never happened, so
    /// the next frame uploads them again (only when a target was ever set).
    pub fn forget_uploads(&mut self) {
        self.deltas_pending |= self.deltas_edited;
    }
}
