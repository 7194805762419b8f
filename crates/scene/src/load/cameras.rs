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
        if !is_valid(&projection) {
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

/// Whether the projection can be rendered: perspective with a field of view in (0, π), a
/// positive near plane, and a positive finite aspect ratio and a finite far plane beyond the
/// near one when given; orthographic with finite non-zero magnifications and a non-negative
/// near plane before a finite far plane.
fn is_valid(projection: &Projection) -> bool {
    match *projection {
        Projection::Perspective {
            yfov,
            aspect_ratio,
            znear,
            zfar,
        } => {
            yfov > 0.0
                && yfov < std::f32::consts::PI
                && znear > 0.0
                && aspect_ratio.is_none_or(|a| a > 0.0 && a.is_finite())
                && zfar.is_none_or(|f| f > znear && f.is_finite())
        }
        Projection::Orthographic {
            xmag,
            ymag,
            znear,
            zfar,
        } => {
            xmag.is_finite()
                && ymag.is_finite()
                && xmag != 0.0
                && ymag != 0.0
                && znear >= 0.0
                && zfar > znear
                && zfar.is_finite()
        }
    }
}
