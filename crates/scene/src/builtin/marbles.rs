//! `marbles`: a field of 96 balls of many sizes on a wide ground under a low sun and an
//! evening sky (issue 18, item 4).
//!
//! It exists for two reasons. It carries [`BALLS`] proxies, far more than `spheres`, spread
//! over [`FIELD`] metres, so a receiver lies inside the sphere of influence of only some of them:
//! the scene the proxies' neighbour lists are measured on. And nothing in shine was tuned on
//! it: other proportions (a 24 m field seen from 9 m away), another light (a directional sun,
//! where the other scenes have spots and points) and other materials (gold, a near-mirror
//! chrome, rough clay) than the scenes the techniques were developed on.
//!
//! Balls sit on a jittered 12 × 8 grid with radii from 0.15 to 0.45 m; one ball in eight
//! bounces (cubic spline), the rest stand still. Each ball's proxy is its bounding sphere, in
//! its node's `extras`. One mesh per material, shared by the balls of that material (glTF
//! instancing through nodes), keeps the file small.

use glam::{Mat4, Vec3};
use serde_json::json;

use super::shapes;
use super::textures;
use super::tracks::Tracks;
use crate::environment::{self, Environment};
use crate::glb_writer::GlbWriter;
use crate::proxies;

/// Number of balls, each with one proxy sphere.
pub const BALLS: usize = 96;
/// Balls along x and along z.
const GRID: (usize, usize) = (12, 8);
/// Extent of the grid of balls along x and z, metres.
const FIELD: (f32, f32) = (24.0, 16.0);
/// Smallest and largest ball radius, metres.
const RADII: (f32, f32) = (0.15, 0.45);
/// Every `BOUNCE_EVERY`-th ball bounces.
const BOUNCE_EVERY: usize = 8;

/// The sky lighting the scene: a warm horizon and a deep zenith, dimmer than `spheres`' sky.
pub fn sky() -> Environment {
    Environment {
        zenith: Vec3::new(0.12, 0.22, 0.55),
        horizon: Vec3::new(0.95, 0.7, 0.5),
        ground: Vec3::new(0.2, 0.17, 0.14),
        intensity: 0.6,
        map: None,
    }
}

/// Deterministic pseudo-random numbers in [0, 1) from an integer (a 32-bit integer hash),
/// so the generator writes the same bytes every time.
fn hash01(mut x: u32) -> f32 {
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Builds the scene as GLB bytes.
pub fn build() -> Vec<u8> {
    let mut w = GlbWriter::new();
    let checker = w.png_texture(
        "ground checker",
        &textures::checker(64, Vec3::new(0.55, 0.5, 0.42), Vec3::new(0.4, 0.36, 0.3)),
    );
    let ground_mat = w.push(
        "materials",
        json!({"name": "sand", "pbrMetallicRoughness": {"baseColorTexture": {"index": checker}, "metallicFactor": 0.0, "roughnessFactor": 1.0}}),
    );
    let materials = [
        ("red clay", [0.7, 0.15, 0.1], 0.0, 0.95),
        ("teal plastic", [0.1, 0.55, 0.5], 0.0, 0.3),
        ("gold", [1.0, 0.77, 0.34], 1.0, 0.25),
        ("white plastic", [0.85, 0.85, 0.82], 0.0, 0.5),
        ("chrome", [0.95, 0.95, 0.95], 1.0, 0.05),
        ("violet rubber", [0.35, 0.15, 0.6], 0.0, 0.8),
    ];
    let unit_ball = shapes::uv_sphere(1.0, 24, 12);
    let meshes: Vec<usize> = materials
        .iter()
        .map(|&(name, c, metallic, roughness)| {
            let m = w.push(
                "materials",
                json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0], "metallicFactor": metallic, "roughnessFactor": roughness}}),
            );
            w.mesh(&format!("{name} ball"), &[(&unit_ball, m)])
        })
        .collect();

    let ground = shapes::ground(60.0, 2.0);
    let g = w.mesh("ground", &[(&ground, ground_mat)]);
    let mut roots = vec![w.push("nodes", json!({"name": "ground", "mesh": g}))];

    let mut tracks = Tracks::default();
    let cell = Vec3::new(FIELD.0 / GRID.0 as f32, 0.0, FIELD.1 / GRID.1 as f32);
    for i in 0..BALLS {
        let (gx, gz) = (i % GRID.0, i / GRID.0);
        let k = i as u32 * 3;
        let radius = RADII.0 + (RADII.1 - RADII.0) * hash01(k);
        let jitter = Vec3::new(hash01(k + 1) - 0.5, 0.0, hash01(k + 2) - 0.5) * 0.6;
        let at = Vec3::new(
            (gx as f32 + 0.5 + jitter.x) * cell.x - FIELD.0 * 0.5,
            radius,
            (gz as f32 + 0.5 + jitter.z) * cell.z - FIELD.1 * 0.5,
        );
        let node = w.push(
            "nodes",
            json!({"name": format!("ball {i}"), "mesh": meshes[i % meshes.len()],
            "translation": at.to_array(), "scale": [radius, radius, radius],
            "extras": {proxies::EXTRAS_KEY: proxies::to_json(&[proxies::ProxySphere {
                center: [0.0; 3],
                radius: 1.0,
            }])}}),
        );
        if i % BOUNCE_EVERY == 3 {
            // A bounce to 4 radii every second, offset per ball, as a cubic spline.
            let (low, high, v) = (radius, radius * 4.0, 8.0 * radius);
            let phase = hash01(BALLS as u32 * 3 + i as u32) * 0.5;
            let times: Vec<f32> = (0..5).map(|j| j as f32 * 0.5 + phase).collect();
            let keys: Vec<f32> = (0..5)
                .flat_map(|j| {
                    let (y, slope) = if j % 2 == 0 { (low, v) } else { (high, 0.0) };
                    [0., -slope, 0., at.x, y, at.z, 0., slope, 0.]
                })
                .collect();
            tracks.add(&mut w, node, "translation", "CUBICSPLINE", &times, &keys);
        }
        roots.push(node);
    }
    tracks.write(&mut w, "bounce");

    let sun = w.light(
        json!({"name": "sun", "type": "directional", "color": [1.0, 0.85, 0.65], "intensity": 3.0}),
    );
    let aim = Mat4::look_at_rh(Vec3::ZERO, Vec3::new(-0.6, -0.45, -0.35), Vec3::Y).inverse();
    let (_, sun_rot, _) = aim.to_scale_rotation_translation();
    roots.push(w.push(
        "nodes",
        json!({"name": "sun", "rotation": sun_rot.normalize().to_array(),
               "extensions": {"KHR_lights_punctual": {"light": sun}}}),
    ));

    let camera = w.push(
        "cameras",
        json!({"name": "overlook", "type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.05, "zfar": 200.0}}),
    );
    let eye = Vec3::new(3.0, 4.5, 15.0);
    let look = Mat4::look_at_rh(eye, Vec3::new(0.0, 0.0, 0.0), Vec3::Y).inverse();
    let (_, rotation, _) = look.to_scale_rotation_translation();
    roots.push(w.push(
        "nodes",
        json!({"name": "camera", "camera": camera, "translation": eye.to_array(), "rotation": rotation.normalize().to_array()}),
    ));
    w.set_extras(json!({environment::EXTRAS_KEY: sky().to_json()}));
    w.scene("marbles", &roots);
    w.to_glb()
}
