//! `room`: a 5 m × 3 m × 6 m room seen from inside, for papers 000 (normal-mapped and glossy
//! surfaces under instant GI) and 003 (HVLs from an RSM of two lights). Textured tiled floor
//! with a normal map and a metallic-roughness map, plaster walls, a blue accent wall, a gold
//! sphere, a glossy red box and a chrome torus; a warm point lamp and a cool spot light.

use glam::{Mat4, Quat, Vec2, Vec3};
use serde_json::json;

use super::shapes::{self, MeshData};
use super::textures;
use crate::glb_writer::GlbWriter;

const W: f32 = 5.0;
const H: f32 = 3.0;
const D: f32 = 6.0;

/// Builds the scene as GLB bytes.
pub fn build() -> Vec<u8> {
    let mut w = GlbWriter::new();
    let tiles = w.png_texture("floor tiles", &textures::tiles_albedo(128));
    let tiles_n = w.png_texture("floor tiles normal", &textures::tiles_normal(128));
    let tiles_mr = w.png_texture(
        "floor tiles metallic-roughness",
        &textures::tiles_metallic_roughness(64),
    );
    let plaster = w.png_texture("plaster", &textures::plaster_albedo(64));

    let m_floor = w.push(
        "materials",
        json!({"name": "tiles",
               "pbrMetallicRoughness": {"baseColorTexture": {"index": tiles}, "metallicRoughnessTexture": {"index": tiles_mr},
                                        "metallicFactor": 1.0, "roughnessFactor": 1.0},
               "normalTexture": {"index": tiles_n, "scale": 1.0}}),
    );
    let m_plaster = w.push(
        "materials",
        json!({"name": "plaster", "pbrMetallicRoughness": {"baseColorTexture": {"index": plaster}, "metallicFactor": 0.0, "roughnessFactor": 0.9}}),
    );
    let m_accent = w.push(
        "materials",
        json!({"name": "blue paint", "pbrMetallicRoughness": {"baseColorTexture": {"index": plaster},
               "baseColorFactor": [0.35, 0.5, 0.85, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}}),
    );
    let m_ceiling = w.push(
        "materials",
        json!({"name": "ceiling", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.9, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
    );
    let m_gold = w.push(
        "materials",
        json!({"name": "polished gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.78, 0.34, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.15}}),
    );
    let m_red = w.push(
        "materials",
        json!({"name": "glossy red", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.06, 0.05, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.2}}),
    );
    let m_chrome = w.push(
        "materials",
        json!({"name": "chrome", "pbrMetallicRoughness": {"baseColorFactor": [0.95, 0.95, 0.95, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.05}}),
    );

    let (x, z) = (W * 0.5, D * 0.5);
    let c = |px: f32, py: f32, pz: f32| Vec3::new(px, py, pz);
    let mut floor = MeshData::default();
    floor.quad(
        [c(-x, 0., z), c(x, 0., z), c(x, 0., -z), c(-x, 0., -z)],
        Vec2::new(W / 2.0, D / 2.0),
    );
    let mut ceiling = MeshData::default();
    ceiling.quad(
        [c(-x, H, -z), c(x, H, -z), c(x, H, z), c(-x, H, z)],
        Vec2::ONE,
    );
    let mut walls = MeshData::default();
    walls
        .quad(
            [c(-x, 0., z), c(-x, 0., -z), c(-x, H, -z), c(-x, H, z)],
            Vec2::new(D / 2.0, H / 2.0),
        ) // left, faces +X
        .quad(
            [c(x, 0., -z), c(x, 0., z), c(x, H, z), c(x, H, -z)],
            Vec2::new(D / 2.0, H / 2.0),
        ) // right, faces -X
        .quad(
            [c(x, 0., z), c(-x, 0., z), c(-x, H, z), c(x, H, z)],
            Vec2::new(W / 2.0, H / 2.0),
        ); // front, faces -Z
    let mut accent = MeshData::default();
    accent.quad(
        [c(-x, 0., -z), c(x, 0., -z), c(x, H, -z), c(-x, H, -z)],
        Vec2::new(W / 2.0, H / 2.0),
    ); // back, faces +Z

    let room = w.mesh_parts(
        "room",
        &[
            (&floor, m_floor, true),
            (&walls, m_plaster, false),
            (&accent, m_accent, false),
            (&ceiling, m_ceiling, false),
        ],
    );
    let sphere = w.mesh("gold sphere", &[(&shapes::uv_sphere(0.5, 48, 24), m_gold)]);
    let cube = w.mesh(
        "red box",
        &[(&shapes::cuboid(Vec3::new(0.9, 0.9, 0.9)), m_red)],
    );
    let torus = w.mesh(
        "chrome torus",
        &[(&shapes::torus(0.35, 0.12, 40, 16), m_chrome)],
    );

    let mut roots = vec![
        w.push("nodes", json!({"name": "room", "mesh": room})),
        w.push(
            "nodes",
            json!({"name": "gold sphere", "mesh": sphere, "translation": [-1.0, 0.5, -1.2]}),
        ),
        w.push(
            "nodes",
            json!({"name": "red box", "mesh": cube, "translation": [1.1, 0.45, -1.6],
                   "rotation": Quat::from_rotation_y(0.5).to_array()}),
        ),
        w.push(
            "nodes",
            json!({"name": "chrome torus", "mesh": torus, "translation": [0.2, 0.12, 0.2]}),
        ),
    ];
    let lamp = w.light(json!({"name": "ceiling lamp", "type": "point", "color": [1.0, 0.85, 0.7], "intensity": 30.0, "range": 20.0}));
    let spot = w.light(
        json!({"name": "spot", "type": "spot", "color": [0.8, 0.9, 1.0], "intensity": 120.0,
                              "spot": {"innerConeAngle": 0.25, "outerConeAngle": 0.5}}),
    );
    roots.push(w.push(
        "nodes",
        json!({"name": "ceiling lamp", "translation": [0.0, 2.7, -0.5], "extensions": {"KHR_lights_punctual": {"light": lamp}}}),
    ));
    let spot_pos = Vec3::new(-2.0, 2.7, 1.5);
    let aim = Mat4::look_at_rh(spot_pos, Vec3::new(1.1, 0.45, -1.6), Vec3::Y).inverse();
    let (_, spot_rot, _) = aim.to_scale_rotation_translation();
    roots.push(w.push(
        "nodes",
        json!({"name": "spot", "translation": spot_pos.to_array(), "rotation": spot_rot.normalize().to_array(),
               "extensions": {"KHR_lights_punctual": {"light": spot}}}),
    ));
    let camera = w.push(
        "cameras",
        json!({"name": "doorway", "type": "perspective", "perspective": {"yfov": 1.0, "znear": 0.05, "zfar": 50.0}}),
    );
    let eye = Vec3::new(0.3, 1.6, 2.7);
    let look = Mat4::look_at_rh(eye, Vec3::new(0.0, 0.7, -1.2), Vec3::Y).inverse();
    let (_, cam_rot, _) = look.to_scale_rotation_translation();
    roots.push(w.push(
        "nodes",
        json!({"name": "camera", "camera": camera, "translation": eye.to_array(), "rotation": cam_rot.normalize().to_array()}),
    ));
    w.scene("room", &roots);
    w.to_glb()
}
