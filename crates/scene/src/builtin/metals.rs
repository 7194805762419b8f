//! `metals`: four rough metal spheres in a closed matte room under a spot and a point light,
//! the scene a specular denoiser is measured on at one sample per pixel. Nothing was tuned
//! on it.
//!
//! The room is unlike the other built-ins in its proportions (5 m × 2.8 m × 5 m) and colours
//! (a sage back wall, warm white side walls, a light grey ceiling, a mid-grey floor); its large
//! flat matte walls are judged too. The spheres stand on the floor in a row across the room,
//! from the camera's left: a chrome mirror (roughness 0.03), silver (0.1), gold (0.3, the one
//! the denoiser's error is quoted on) and copper (0.5). A warm spot light high in the front
//! left corner aims at the row; a cool point light hangs near the ceiling on the right. No
//! sky, no emissive surface, nothing moves.

use glam::{Quat, Vec2, Vec3};
use serde_json::json;

use super::shapes::{self, MeshData};
use super::tracks::aim;
use crate::glb_writer::GlbWriter;

/// Width (x), height and depth (z) of the room, in metres.
const W: f32 = 5.0;
const H: f32 = 2.8;
const D: f32 = 5.0;
/// Radius of the spheres, metres.
const RADIUS: f32 = 0.42;
/// Distance between neighbouring spheres' centres along x, metres (a 0.16 m gap).
const SPACING: f32 = 1.0;
/// Depth (z) of the row's centres: 0.4 m of floor between the row and the back wall.
const ROW_Z: f32 = -1.65;
/// The spheres' metals from the camera's left to its right: name, base colour, roughness.
const METALS: [(&str, [f32; 3], f32); 4] = [
    ("chrome", [0.95, 0.95, 0.95], 0.03),
    ("silver", [0.97, 0.96, 0.91], 0.1),
    ("gold", [1.0, 0.78, 0.34], 0.3),
    ("copper", [0.95, 0.64, 0.54], 0.5),
];
/// Intensity of the warm spot light, candela.
const SPOT_CD: f32 = 70.0;
/// Intensity of the cool point light, candela.
const LAMP_CD: f32 = 14.0;
/// Vertical field of view of the camera, radians.
const YFOV: f32 = 0.95;

/// The room's surfaces seen from inside, by material: floor, ceiling, the side (-X, +X) and
/// front (+Z) walls, and the back (-Z) wall.
fn room() -> [MeshData; 4] {
    let (x, z) = (W * 0.5, D * 0.5);
    let c = Vec3::new;
    let (floor, ceiling) = shapes::floor_and_ceiling(W, D, H, Vec2::new(W, D));
    let mut walls = MeshData::default();
    walls
        .quad(
            [c(-x, 0., z), c(-x, 0., -z), c(-x, H, -z), c(-x, H, z)],
            Vec2::new(D, H),
        )
        .quad(
            [c(x, 0., -z), c(x, 0., z), c(x, H, z), c(x, H, -z)],
            Vec2::new(D, H),
        )
        .quad(
            [c(x, 0., z), c(-x, 0., z), c(-x, H, z), c(x, H, z)],
            Vec2::new(W, H),
        );
    let mut back = MeshData::default();
    back.quad(
        [c(-x, 0., -z), c(x, 0., -z), c(x, H, -z), c(-x, H, -z)],
        Vec2::new(W, H),
    );
    [floor, ceiling, walls, back]
}

/// Centre of sphere `i` (0 to 3, left to right as the camera sees them), resting on the floor.
fn sphere_centre(i: usize) -> Vec3 {
    let x = (i as f32 - 1.5) * SPACING;
    Vec3::new(x, RADIUS, ROW_Z)
}

/// Builds the scene as GLB bytes.
pub fn build() -> Vec<u8> {
    let mut w = GlbWriter::new();
    let matte = |name: &str, c: [f32; 3], roughness: f32| {
        json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0],
               "metallicFactor": 0.0, "roughnessFactor": roughness}})
    };
    let materials = [
        ("grey floor", [0.45, 0.45, 0.45], 0.8),
        ("grey ceiling", [0.78, 0.78, 0.76], 1.0),
        ("warm white walls", [0.82, 0.78, 0.7], 0.95),
        ("sage wall", [0.45, 0.55, 0.4], 0.95),
    ]
    .map(|(n, c, r)| w.push("materials", matte(n, c, r)));
    let parts = room();
    let room = w.mesh("room", &parts.iter().zip(materials).collect::<Vec<_>>());
    let mut roots = vec![w.push("nodes", json!({"name": "room", "mesh": room}))];

    // One finely tessellated sphere, its accessors shared by the four meshes (one per metal),
    // which keeps the file small.
    let ball = shapes::uv_sphere(RADIUS, 64, 32);
    let attributes = json!({"POSITION": w.vec3(&ball.positions, true),
                            "NORMAL": w.vec3(&ball.normals, false),
                            "TEXCOORD_0": w.vec2(&ball.uvs)});
    let indices = w.indices(&ball.indices);
    for (i, (name, c, roughness)) in METALS.into_iter().enumerate() {
        let material = w.push(
            "materials",
            json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0],
                   "metallicFactor": 1.0, "roughnessFactor": roughness}}),
        );
        let mesh = w.push(
            "meshes",
            json!({"name": format!("{name} sphere"), "primitives": [{"attributes": attributes,
                   "indices": indices, "material": material, "mode": 4}]}),
        );
        roots.push(w.push(
            "nodes",
            json!({"name": format!("{name} sphere"), "mesh": mesh,
                   "translation": sphere_centre(i).to_array()}),
        ));
    }

    let light_node = |w: &mut GlbWriter, name: &str, light: usize, at: Vec3, rotation: Quat| {
        w.push(
            "nodes",
            json!({"name": name, "translation": at.to_array(), "rotation": rotation.to_array(),
                   "extensions": {"KHR_lights_punctual": {"light": light}}}),
        )
    };
    let spot = w.light(
        json!({"name": "warm spot", "type": "spot", "color": [1.0, 0.9, 0.75], "intensity": SPOT_CD,
               "spot": {"innerConeAngle": 0.4, "outerConeAngle": 35f32.to_radians()}}),
    );
    let spot_at = Vec3::new(-2.2, H - 0.15, 2.2);
    let spot_target = Vec3::new(0.0, RADIUS, ROW_Z);
    roots.push(light_node(
        &mut w,
        "warm spot",
        spot,
        spot_at,
        aim(spot_at, spot_target),
    ));
    let lamp = w.light(
        json!({"name": "cool lamp", "type": "point", "color": [0.75, 0.85, 1.0],
               "intensity": LAMP_CD, "range": 15.0}),
    );
    let lamp_at = Vec3::new(1.6, H - 0.6, 0.4);
    roots.push(light_node(
        &mut w,
        "cool lamp",
        lamp,
        lamp_at,
        Quat::IDENTITY,
    ));

    let camera = w.push(
        "cameras",
        json!({"name": "front wall", "type": "perspective", "perspective": {"yfov": YFOV, "znear": 0.05, "zfar": 30.0}}),
    );
    let eye = Vec3::new(0.0, 1.5, 2.35);
    let target = Vec3::new(0.0, 0.55, ROW_Z);
    roots.push(w.push(
        "nodes",
        json!({"name": "camera", "camera": camera, "translation": eye.to_array(),
               "rotation": aim(eye, target).to_array()}),
    ));
    w.scene("metals", &roots);
    w.to_glb()
}
