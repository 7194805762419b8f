//! The Cornell box, from the measured data published by the Cornell Program of Computer
//! Graphics (millimetres; converted to metres and turned 180° about +Y so the camera looks
//! down -Z, as glTF cameras do). Red wall on the left, green on the right, short and tall
//! blocks, and the ceiling lamp as a downward spot light plus an emissive patch.

use std::f32::consts::FRAC_PI_2;

use glam::{Quat, Vec2, Vec3};
use serde_json::json;

use super::shapes::MeshData;
use crate::glb_writer::GlbWriter;

/// Classic Cornell coordinates (mm) to scene coordinates (m): centred on the floor's middle.
fn p(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(-(x - 278.0), y, -(z - 279.6)) / 1000.0
}

/// Appends a quad wound so its front faces the point `toward` (or away from it).
fn quad_facing(m: &mut MeshData, c: [Vec3; 4], toward: Vec3, facing: bool) {
    let n = (c[1] - c[0]).cross(c[3] - c[0]);
    let centre = (c[0] + c[1] + c[2] + c[3]) * 0.25;
    let faces_toward = n.dot(toward - centre) > 0.0;
    let c = if faces_toward == facing {
        c
    } else {
        [c[3], c[2], c[1], c[0]]
    };
    m.quad(c, Vec2::ONE);
}

/// A block from its four top corners (mm), standing on the floor, faces outward.
fn block(top: [[f32; 3]; 4]) -> MeshData {
    let t = top.map(|[x, y, z]| p(x, y, z));
    let b = top.map(|[x, _, z]| p(x, 0.0, z));
    let centre = (t[0] + t[1] + t[2] + t[3] + b[0] + b[1] + b[2] + b[3]) / 8.0;
    let mut m = MeshData::default();
    quad_facing(&mut m, t, centre, false);
    for i in 0..4 {
        let j = (i + 1) % 4;
        quad_facing(&mut m, [t[i], t[j], b[j], b[i]], centre, false);
    }
    m
}

/// Builds the scene as GLB bytes.
pub fn build() -> Vec<u8> {
    let mut w = GlbWriter::new();
    let inside = p(278.0, 274.4, 279.6);
    let mut white = MeshData::default();
    let mut red = MeshData::default();
    let mut green = MeshData::default();
    // Floor, ceiling, back wall.
    quad_facing(
        &mut white,
        [
            p(552.8, 0., 0.),
            p(0., 0., 0.),
            p(0., 0., 559.2),
            p(549.6, 0., 559.2),
        ],
        inside,
        true,
    );
    quad_facing(
        &mut white,
        [
            p(556., 548.8, 0.),
            p(556., 548.8, 559.2),
            p(0., 548.8, 559.2),
            p(0., 548.8, 0.),
        ],
        inside,
        true,
    );
    quad_facing(
        &mut white,
        [
            p(549.6, 0., 559.2),
            p(0., 0., 559.2),
            p(0., 548.8, 559.2),
            p(556., 548.8, 559.2),
        ],
        inside,
        true,
    );
    quad_facing(
        &mut red,
        [
            p(552.8, 0., 0.),
            p(549.6, 0., 559.2),
            p(556., 548.8, 559.2),
            p(556., 548.8, 0.),
        ],
        inside,
        true,
    );
    quad_facing(
        &mut green,
        [
            p(0., 0., 559.2),
            p(0., 0., 0.),
            p(0., 548.8, 0.),
            p(0., 548.8, 559.2),
        ],
        inside,
        true,
    );
    let short = block([
        [130., 165., 65.],
        [82., 165., 225.],
        [240., 165., 272.],
        [290., 165., 114.],
    ]);
    let tall = block([
        [423., 330., 247.],
        [265., 330., 296.],
        [314., 330., 456.],
        [472., 330., 406.],
    ]);
    let mut lamp = MeshData::default();
    let y = 547.8; // 1 mm below the ceiling
    quad_facing(
        &mut lamp,
        [
            p(343., y, 227.),
            p(343., y, 332.),
            p(213., y, 332.),
            p(213., y, 227.),
        ],
        inside,
        true,
    );

    // Reflectances commonly used for the Cornell box in RGB renderers.
    let diffuse = |name: &str, c: [f32; 3]| json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}});
    let m_white = w.push("materials", diffuse("white", [0.73, 0.73, 0.73]));
    let m_red = w.push("materials", diffuse("red", [0.65, 0.05, 0.05]));
    let m_green = w.push("materials", diffuse("green", [0.12, 0.45, 0.15]));
    // The lamp's radiance (17, 12, 4) as a unit colour times KHR_materials_emissive_strength.
    let lamp_colour = [1.0, 12.0 / 17.0, 4.0 / 17.0];
    w.use_extension("KHR_materials_emissive_strength");
    let m_lamp = w.push(
        "materials",
        json!({"name": "lamp", "emissiveFactor": lamp_colour,
               "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 17.0}},
               "pbrMetallicRoughness": {"baseColorFactor": [0.78, 0.78, 0.78, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
    );

    let walls = w.mesh(
        "walls",
        &[(&white, m_white), (&red, m_red), (&green, m_green)],
    );
    let short = w.mesh("short block", &[(&short, m_white)]);
    let tall = w.mesh("tall block", &[(&tall, m_white)]);
    let lamp = w.mesh("lamp", &[(&lamp, m_lamp)]);
    let mut roots = vec![
        w.push("nodes", json!({"name": "walls", "mesh": walls})),
        w.push("nodes", json!({"name": "short block", "mesh": short})),
        w.push("nodes", json!({"name": "tall block", "mesh": tall})),
        w.push("nodes", json!({"name": "lamp", "mesh": lamp})),
    ];
    // Radiant intensity straight down of the 130 mm × 105 mm lamp: L · A.
    let intensity = 17.0 * 0.130 * 0.105;
    let light = w.light(json!({"name": "ceiling lamp", "type": "spot", "color": lamp_colour, "intensity": intensity,
                               "spot": {"innerConeAngle": 0.0, "outerConeAngle": FRAC_PI_2 - 1e-4}}));
    let down = Quat::from_rotation_x(-FRAC_PI_2);
    let lamp_pos = p(278.0, 547.0, 279.5);
    roots.push(w.push(
        "nodes",
        json!({"name": "ceiling lamp", "translation": lamp_pos.to_array(), "rotation": down.to_array(),
               "extensions": {"KHR_lights_punctual": {"light": light}}}),
    ));
    // The classic camera: (278, 273, -800) mm, 35 mm focal length, 25 mm film.
    let yfov = 2.0 * (12.5f32 / 35.0).atan();
    let camera = w.push(
        "cameras",
        json!({"name": "cornell camera", "type": "perspective",
               "perspective": {"yfov": yfov, "aspectRatio": 1.0, "znear": 0.01, "zfar": 10.0}}),
    );
    roots.push(w.push("nodes", json!({"name": "camera", "camera": camera, "translation": p(278.0, 273.0, -800.0).to_array()})));
    w.scene("cornell-box", &roots);
    w.to_glb()
}
