//! Cameras on the nodes of the displayed scene, their projections checked.

use glam::Mat4;

use super::ctx::Ctx;
use crate::error::Result;
use crate::scene::Scene;
use crate::types::{Camera, Projection};

/// Adds the cameras of the shown nodes of `scene` to [`Scene::cameras`] (and links them
/// from their node), placed by the rest-pose `world` matrices.
pub(super) fn load_cameras(
    ctx: &Ctx,
    doc: &gltf::Document,
    scene: &mut Scene,
    world: &[Mat4],
) -> Result<()> {
    let shown = scene.shown_nodes();
    for node in doc.nodes() {
        let Some(cam) = node.camera() else { continue };
        if !shown.get(node.index()).copied().unwrap_or(false) {
            continue;
        }
        let element = format!(
            "cameras[{}] {:?} (on nodes[{}])",
            cam.index(),
            cam.name().unwrap_or(""),
            node.index()
        );
        let projection = projection(&cam);
        if !projection.is_valid() {
            return Err(ctx.invalid(&element, format!("invalid projection {projection:?}")));
        }
        let index = scene.cameras.len();
        scene.cameras.push(Camera {
            name: cam
                .name()
                .map_or_else(|| format!("camera{}", cam.index()), str::to_string),
            projection,
            world: world.get(node.index()).copied().unwrap_or(Mat4::IDENTITY),
            node: Some(node.index()),
        });
        if let Some(n) = scene.nodes.get_mut(node.index()) {
            n.camera = Some(index);
        }
    }
    Ok(())
}

/// The camera's projection as stored in the file.
fn projection(cam: &gltf::Camera<'_>) -> Projection {
    match cam.projection() {
        gltf::camera::Projection::Perspective(p) => Projection::Perspective {
            yfov: p.yfov(),
            aspect_ratio: p.aspect_ratio(),
            znear: p.znear(),
            zfar: p.zfar(),
        },
        gltf::camera::Projection::Orthographic(o) => Projection::Orthographic {
            xmag: o.xmag(),
            ymag: o.ymag(),
            znear: o.znear(),
            zfar: o.zfar(),
        },
    }
}
