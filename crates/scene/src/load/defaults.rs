//! What the loader adds to a scene that lacks it: a camera framing the scene and, without
//! lights or an environment, a sun. Each addition is a warning.

use glam::{Mat4, Vec3};

use super::ctx::Ctx;
use super::{DEFAULT_SUN_DIRECTION, DEFAULT_SUN_LUX, DEFAULT_YFOV};
use crate::scene::Scene;
use crate::types::{Camera, Light, LightKind, Projection};

/// Adds the default camera when `scene` has none and the default sun when it has neither
/// a light nor an environment; `world` holds the rest-pose world matrices.
pub(super) fn add_defaults(ctx: &mut Ctx, scene: &mut Scene, world: &[Mat4]) {
    if scene.cameras.is_empty() {
        let camera = default_camera(ctx, scene, world);
        scene.cameras.push(camera);
    }
    if scene.lights.is_empty() && scene.environment.is_none() {
        ctx.warn(
            "KHR_lights_punctual",
            format!("the scene has no light and no environment; adding a default directional sun of {DEFAULT_SUN_LUX} lux along {DEFAULT_SUN_DIRECTION}"),
        );
        scene.lights.push(default_sun());
    }
}

/// A perspective camera ([`DEFAULT_YFOV`]) on the +Z side of the scene bounds looking down
/// -Z at their centre, far enough to frame them; warns where it put it.
fn default_camera(ctx: &mut Ctx, scene: &Scene, world: &[Mat4]) -> Camera {
    let bounds = scene.bounds(world);
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), (bounds.extent().length() * 0.5).max(1e-3))
    };
    let distance = radius / (DEFAULT_YFOV * 0.5).sin();
    let eye = center + Vec3::Z * distance;
    ctx.warn(
        "cameras",
        format!(
            "the scene has no camera; using a default camera at {eye} looking down -Z at {center}"
        ),
    );
    Camera {
        name: "default camera (framing the scene bounds)".to_string(),
        projection: Projection::Perspective {
            yfov: DEFAULT_YFOV,
            aspect_ratio: None,
            znear: (distance - radius).max(distance * 1e-3),
            zfar: Some(distance + radius * 2.0),
        },
        world: Mat4::from_translation(eye),
        node: None,
    }
}

/// A white directional sun of [`DEFAULT_SUN_LUX`] lux along [`DEFAULT_SUN_DIRECTION`].
fn default_sun() -> Light {
    Light {
        position: [0.0; 3],
        kind: LightKind::Directional as u32,
        direction: DEFAULT_SUN_DIRECTION.to_array(),
        range: 0.0,
        color: [1.0; 3],
        intensity: DEFAULT_SUN_LUX,
        inner_cone_angle: 0.0,
        outer_cone_angle: 0.0,
        node: u32::MAX,
        _pad: 0,
    }
}
