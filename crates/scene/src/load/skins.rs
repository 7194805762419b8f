//! Skins (glTF 2.0 §3.7.3) and the checks that need nodes, meshes and skins together: joint
//! indices within the node's skin, morph weight counts.
//!
//! Read from the JSON: gltf 1.4's skin wrappers unwrap their joint and accessor references.

use glam::Mat4;
use gltf::accessor::Dimensions;

use super::accessor::Buffers;
use super::ctx::{Ctx, finite_rows};
use crate::error::Result;
use crate::scene::Scene;
use crate::types::Skin;

/// Every skin of `doc`: at least one joint, each an existing node, and as many inverse bind
/// matrices as joints (finite MAT4 floats) or none (identities).
pub(super) fn load_skins(ctx: &Ctx, buffers: &Buffers, doc: &gltf::Document) -> Result<Vec<Skin>> {
    let json = doc.as_json();
    let mut out = Vec::new();
    for (si, skin) in json.skins.iter().enumerate() {
        let name = skin.name.clone().unwrap_or_else(|| format!("skin{si}"));
        let element = format!("skins[{si}] {name:?}");
        if skin.joints.is_empty() {
            return Err(ctx.invalid(&element, "has no joints"));
        }
        let joints: Vec<usize> = skin.joints.iter().map(|j| j.value()).collect();
        if let Some(bad) = joints.iter().find(|&&j| j >= json.nodes.len()) {
            return Err(ctx.invalid(
                format!("{element} joints"),
                format!("node {bad} does not exist ({} nodes)", json.nodes.len()),
            ));
        }
        let inverse_bind = match &skin.inverse_bind_matrices {
            None => vec![Mat4::IDENTITY; joints.len()],
            Some(index) => {
                let what = format!("{element} inverseBindMatrices");
                let acc = doc.accessors().nth(index.value()).ok_or_else(|| {
                    ctx.invalid(&what, format!("accessor {} does not exist", index.value()))
                })?;
                let values = buffers
                    .read_rows(&acc, Dimensions::Mat4)
                    .map_err(|m| ctx.invalid(format!("{what} (accessors[{}])", acc.index()), m))?;
                let matrices = finite_rows(ctx, &what, "", &values, 16, |c| {
                    let mut m = [0.0; 16];
                    m.copy_from_slice(c);
                    Mat4::from_cols_array(&m)
                })?;
                if matrices.len() != joints.len() {
                    return Err(ctx.invalid(
                        what,
                        format!(
                            "has {} matrices for {} joints; it needs one per joint",
                            matrices.len(),
                            joints.len()
                        ),
                    ));
                }
                matrices
            }
        };
        out.push(Skin {
            name,
            joints,
            inverse_bind,
        });
    }
    Ok(out)
}

/// Checks each node against its mesh and skin, in `scene` (nodes, meshes and skins loaded):
/// node morph weights must match the mesh's target count; a skinned node's mesh must have
/// joints in every primitive (else it is drawn rigid, with a warning) and joint indices
/// below the skin's joint count; a mesh with joints on a node without a skin is drawn rigid,
/// with a warning.
pub(super) fn check_nodes(ctx: &mut Ctx, scene: &mut Scene) -> Result<()> {
    for (i, node) in scene.nodes.iter_mut().enumerate() {
        let element = format!("nodes[{i}] {:?}", node.name);
        let mesh_index = node.mesh.unwrap_or(0);
        let mesh = node.mesh.and_then(|m| scene.meshes.get(m));
        if let Some(w) = &node.weights {
            let targets = mesh.map_or(0, |m| m.target_count());
            if w.len() != targets {
                return Err(ctx.invalid(
                    format!("{element} weights"),
                    format!("has {} weights for {targets} morph targets", w.len()),
                ));
            }
        }
        let Some(mesh) = mesh else {
            if node.skin.take().is_some() {
                ctx.warn(&element, "has a skin but no mesh; the skin is ignored");
            }
            continue;
        };
        let skinned = mesh.primitives.iter().filter(|p| p.is_skinned()).count();
        let Some(s) = node.skin else {
            if skinned > 0 {
                ctx.warn(
                    &element,
                    format!(
                        "mesh {:?} has JOINTS_0 but the node has no skin; it is drawn rigid",
                        mesh.name
                    ),
                );
            }
            continue;
        };
        if skinned < mesh.primitives.len() {
            ctx.warn(
                &element,
                format!(
                    "has a skin but primitives of mesh {:?} have no JOINTS_0; it is drawn rigid",
                    mesh.name
                ),
            );
            node.skin = None;
            continue;
        }
        let count = scene.skins.get(s).map_or(0, |skin| skin.joints.len());
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let max = prim.joints.iter().flatten().copied().max().unwrap_or(0);
            if max as usize >= count {
                return Err(ctx.invalid(
                    format!("meshes[{mesh_index}] {:?} primitives[{p}] JOINTS_0", mesh.name),
                    format!(
                        "joint index {max} is out of range for skins[{s}] ({count} joints) used by {element}"
                    ),
                ));
            }
        }
    }
    Ok(())
}
