//! `spheres`: a ground plane and four animated objects under a procedural sky (paper 002).
//!
//! Each object carries its proxy spheres in its node `extras` (`shine_proxies`): the ball
//! its exact bounding sphere, the others spheres fitted by [`crate::proxies::fit`] when the
//! scene is generated. The animations use all three glTF interpolations: the ball bounces
//! (cubic spline), the box spins and the torus orbits (linear), the pill pulses (step).

use std::f32::consts::{FRAC_PI_2, TAU};

use glam::{Mat4, Quat, Vec3};
use serde_json::json;

use super::shapes::{self, MeshData};
use super::textures;
use super::tracks::Tracks;
use crate::environment::{self, Environment};
use crate::glb_writer::GlbWriter;
use crate::proxies;

/// The sky lighting the scene.
pub fn sky() -> Environment {
    Environment {
        zenith: Vec3::new(0.25, 0.45, 0.95),
        horizon: Vec3::new(0.95, 0.95, 1.0),
        ground: Vec3::new(0.35, 0.30, 0.25),
        intensity: 1.0,
        map: None,
    }
}

fn object(
    w: &mut GlbWriter,
    name: &str,
    mesh: &MeshData,
    material: usize,
    at: Vec3,
    spheres: &[proxies::ProxySphere],
) -> usize {
    let m = w.mesh(name, &[(mesh, material)]);
    w.push(
        "nodes",
        json!({"name": name, "mesh": m, "translation": at.to_array(),
               "extras": {proxies::EXTRAS_KEY: proxies::to_json(spheres)}}),
    )
}

fn fitted(mesh: &MeshData, k: usize) -> Vec<proxies::ProxySphere> {
    proxies::fit(&mesh.clone().into_mesh("fit", 0), k).spheres
}

/// Builds the scene as GLB bytes.
pub fn build() -> Vec<u8> {
    let mut w = GlbWriter::new();
    let checker = w.png_texture(
        "ground checker",
        &textures::checker(64, Vec3::splat(0.8), Vec3::splat(0.55)),
    );
    let ground_mat = w.push(
        "materials",
        json!({"name": "ground", "pbrMetallicRoughness": {"baseColorTexture": {"index": checker}, "metallicFactor": 0.0, "roughnessFactor": 0.9}}),
    );
    let plastic = |name: &str, c: [f32; 3], r: f32| json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": 0.0, "roughnessFactor": r}});
    let m_ball = w.push(
        "materials",
        plastic("orange plastic", [0.9, 0.35, 0.08], 0.4),
    );
    let m_box = w.push("materials", plastic("blue plastic", [0.1, 0.25, 0.8], 0.5));
    let m_torus = w.push(
        "materials",
        json!({"name": "brushed metal", "pbrMetallicRoughness": {"baseColorFactor": [0.9, 0.9, 0.92, 1.0], "metallicFactor": 1.0, "roughnessFactor": 0.35}}),
    );
    let m_pill = w.push(
        "materials",
        plastic("green plastic", [0.15, 0.7, 0.25], 0.6),
    );

    let ground = shapes::ground(20.0, 2.5);
    let g = w.mesh("ground", &[(&ground, ground_mat)]);
    let ground_node = w.push("nodes", json!({"name": "ground", "mesh": g}));

    let ball = shapes::uv_sphere(0.5, 32, 16);
    let ball_node = object(
        &mut w,
        "bouncing ball",
        &ball,
        m_ball,
        Vec3::new(0.0, 0.5, 0.0),
        &[proxies::ProxySphere {
            center: [0.0; 3],
            radius: 0.5,
        }],
    );
    let cube = shapes::cuboid(Vec3::splat(0.8));
    let cube_node = object(
        &mut w,
        "spinning box",
        &cube,
        m_box,
        Vec3::new(-1.8, 0.4, 0.6),
        &fitted(&cube, 4),
    );
    let torus = shapes::torus(0.5, 0.15, 32, 12).transformed(Mat4::from_rotation_x(FRAC_PI_2));
    let torus_node = object(
        &mut w,
        "orbiting torus",
        &torus,
        m_torus,
        Vec3::new(1.6, 0.8, 0.0),
        &fitted(&torus, 6),
    );
    let pill =
        shapes::uv_sphere(0.3, 24, 12).transformed(Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)));
    let pill_node = object(
        &mut w,
        "pulsing pill",
        &pill,
        m_pill,
        Vec3::new(0.3, 0.6, -1.6),
        &fitted(&pill, 3),
    );

    let mut tracks = Tracks::default();
    // Ball: a parabolic bounce every second, as a cubic spline with contact speed 5.2 m/s.
    let (low, high, v) = (0.5, 1.8, 5.2);
    tracks.add(
        &mut w,
        ball_node,
        "translation",
        "CUBICSPLINE",
        &[0.0, 0.5, 1.0, 1.5, 2.0],
        &[
            0., -v, 0., 0., low, 0., 0., v, 0., //
            0., 0., 0., 0., high, 0., 0., 0., 0., //
            0., -v, 0., 0., low, 0., 0., v, 0., //
            0., 0., 0., 0., high, 0., 0., 0., 0., //
            0., -v, 0., 0., low, 0., 0., v, 0.,
        ],
    );
    // Box: a full turn about +Y every 4 s, quarter-turn keys, linear (slerp).
    let times: Vec<f32> = (0..=4).map(|i| i as f32 * 0.5).collect();
    let rotations: Vec<f32> = (0..=4)
        .flat_map(|i| Quat::from_rotation_y(i as f32 * FRAC_PI_2 * 0.5).to_array())
        .collect();
    tracks.add(&mut w, cube_node, "rotation", "LINEAR", &times, &rotations);
    // Torus: a circle of radius 1.6 m around the origin in 2 s, 16 linear keys.
    let times: Vec<f32> = (0..=16).map(|i| i as f32 / 8.0).collect();
    let path: Vec<f32> = (0..=16)
        .flat_map(|i| {
            let a = i as f32 / 16.0 * TAU;
            [1.6 * a.cos(), 0.8, -1.6 * a.sin()]
        })
        .collect();
    tracks.add(&mut w, torus_node, "translation", "LINEAR", &times, &path);
    // Pill: scale steps between 1 and 1.25 every half second.
    let s = 1.25;
    tracks.add(
        &mut w,
        pill_node,
        "scale",
        "STEP",
        &[0.0, 0.5, 1.0, 1.5, 2.0],
        &[1., 1., 1., s, s, s, 1., 1., 1., s, s, s, 1., 1., 1.],
    );
    tracks.write(&mut w, "motion");

    let camera = w.push(
        "cameras",
        json!({"name": "overview", "type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.05, "zfar": 100.0}}),
    );
    let eye = Vec3::new(0.0, 2.5, 6.0);
    let look = Mat4::look_at_rh(eye, Vec3::new(0.0, 0.6, 0.0), Vec3::Y).inverse();
    let (_, rotation, _) = look.to_scale_rotation_translation();
    let cam_node = w.push("nodes", json!({"name": "camera", "camera": camera, "translation": eye.to_array(), "rotation": rotation.normalize().to_array()}));
    w.set_extras(json!({environment::EXTRAS_KEY: sky().to_json()}));
    w.scene(
        "spheres",
        &[
            ground_node,
            ball_node,
            cube_node,
            torus_node,
            pill_node,
            cam_node,
        ],
    );
    w.to_glb()
}
