//! KHR_lights_punctual lights on the nodes of the displayed scene, placed in world space.

use glam::{Mat4, Vec3};
use gltf::json::extensions::scene::khr_lights_punctual::{Light as LightDef, Type};
use gltf::json::validation::Checked;

use super::ctx::Ctx;
use crate::error::Result;
use crate::scene::Scene;
use crate::types::{Light, LightKind};

/// Adds the lights of the shown nodes of `scene` to [`Scene::lights`] (and to their node's
/// light list), placed by the rest-pose `world` matrices.
pub(super) fn load_lights(
    ctx: &mut Ctx,
    doc: &gltf::Document,
    scene: &mut Scene,
    world: &[Mat4],
) -> Result<()> {
    let json = doc.as_json();
    let defs = json
        .extensions
        .as_ref()
        .and_then(|e| e.khr_lights_punctual.as_ref())
        .map(|l| l.lights.as_slice())
        .unwrap_or(&[]);
    let shown = scene.shown_nodes();
    for (i, node) in json.nodes.iter().enumerate() {
        let Some(light_ref) = node
            .extensions
            .as_ref()
            .and_then(|e| e.khr_lights_punctual.as_ref())
        else {
            continue;
        };
        if !shown.get(i).copied().unwrap_or(false) {
            continue;
        }
        let li = light_ref.light.value();
        let element = format!("nodes[{i}] KHR_lights_punctual.light {li}");
        let def = defs
            .get(li)
            .ok_or_else(|| ctx.invalid(&element, "the light does not exist"))?;
        let w = world.get(i).copied().unwrap_or(Mat4::IDENTITY);
        let light = light(ctx, &element, def, i, &w)?;
        let index = scene.lights.len();
        scene.lights.push(light);
        if let Some(n) = scene.nodes.get_mut(i) {
            n.lights.push(index);
        }
    }
    Ok(())
}

/// The light `def` on node `node` with world matrix `w`, its values checked finite and
/// non-negative; spot cone angles outside `inner < outer <= π/2` are a warning, and the
/// outer angle is clamped to π/2.
fn light(ctx: &mut Ctx, element: &str, def: &LightDef, node: usize, w: &Mat4) -> Result<Light> {
    let (kind, inner, outer) = kind_and_cone(ctx, element, def)?;
    let values = [def.intensity, inner, outer, def.range.unwrap_or(0.0)];
    if values.iter().any(|x| !x.is_finite() || *x < 0.0)
        || def.color.iter().any(|x| !x.is_finite() || *x < 0.0)
    {
        return Err(ctx.invalid(
            element,
            "intensity, colour, range and cone angles must be finite and non-negative",
        ));
    }
    if kind == LightKind::Spot && !(inner < outer && outer <= std::f32::consts::FRAC_PI_2 + 1e-6) {
        ctx.warn(
            element,
            format!(
                "spot cone angles inner {inner} / outer {outer} should satisfy inner < outer <= π/2"
            ),
        );
    }
    Ok(Light {
        position: w.transform_point3(Vec3::ZERO).to_array(),
        kind: kind as u32,
        direction: w
            .transform_vector3(Vec3::NEG_Z)
            .normalize_or(Vec3::NEG_Z)
            .to_array(),
        range: def.range.unwrap_or(0.0),
        color: def.color,
        intensity: def.intensity,
        inner_cone_angle: inner,
        outer_cone_angle: outer.min(std::f32::consts::FRAC_PI_2),
        node: node as u32,
        _pad: 0,
    })
}

/// The light's kind and its inner and outer cone angles (zero unless a spot light).
fn kind_and_cone(ctx: &Ctx, element: &str, def: &LightDef) -> Result<(LightKind, f32, f32)> {
    match &def.type_ {
        Checked::Valid(Type::Directional) => Ok((LightKind::Directional, 0.0, 0.0)),
        Checked::Valid(Type::Point) => Ok((LightKind::Point, 0.0, 0.0)),
        Checked::Valid(Type::Spot) => {
            let spot = def
                .spot
                .as_ref()
                .ok_or_else(|| ctx.invalid(element, "spot light without \"spot\" cone angles"))?;
            Ok((
                LightKind::Spot,
                spot.inner_cone_angle,
                spot.outer_cone_angle,
            ))
        }
        Checked::Invalid => Err(ctx.invalid(element, "unknown light type")),
    }
}
