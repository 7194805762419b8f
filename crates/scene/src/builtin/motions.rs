//! `motion-*`: one static room, five motions (issue 43, "light that holds still under every
//! motion"). Each scene moves one thing for [`DURATION`] seconds, looped, and keeps every
//! other thing still, so that any change of the indirect light on the walls is the motion's
//! and not another's:
//!
//! - `motion-sweep`: a spot light sweeping ±25° about the vertical, beside a static lamp;
//! - `motion-orbit`: a point light circling the room (its cube RSM moves), beside a static spot;
//! - `motion-sun`: a roofless room under a directional sun whose azimuth swings ±20°;
//! - `motion-crossing`: a box sliding across the floor through a fixed spot's beam (an object
//!   crossing the RSM under a fixed light);
//! - `motion-dolly`: the camera moving through the room, every light still.
//!
//! The room is unlike the other built-ins in its proportions (4 m × 2.6 m × 5 m) and materials
//! (teal and plum walls, an oak floor, a grey plinth): the motion studies are not tuned on it.

use std::f32::consts::PI;

use glam::{Quat, Vec2, Vec3};
use serde_json::json;

use super::shapes::{self, MeshData};
use super::tracks::{Tracks, aim};
use crate::glb_writer::GlbWriter;

/// Names of the motion scenes, in the order the module doc lists them.
pub const NAMES: [&str; 5] = [
    "motion-sweep",
    "motion-orbit",
    "motion-sun",
    "motion-crossing",
    "motion-dolly",
];

/// Width (x), height and depth (z) of the room, in metres.
const W: f32 = 4.0;
const H: f32 = 2.6;
const D: f32 = 5.0;
/// Length of each motion's loop, in seconds.
const DURATION: f32 = 4.0;
/// Keys per loop: linear keys this dense follow the sine motions to within a few mm.
const KEYS: usize = 32;
/// Half-angle of the spot's sweep (the issue's ±25°).
const SWEEP: f32 = 25.0 * PI / 180.0;
/// Half-angle of the sun's azimuth swing.
const SUN_SWING: f32 = 20.0 * PI / 180.0;

/// What moves in a motion scene.
#[derive(Clone, Copy, PartialEq)]
enum Motion {
    Sweep,
    Orbit,
    Sun,
    Crossing,
    Dolly,
}

/// The key times of one loop: `KEYS + 1` keys from 0 to [`DURATION`].
fn key_times() -> Vec<f32> {
    (0..=KEYS)
        .map(|k| k as f32 * DURATION / KEYS as f32)
        .collect()
}

/// `sin(2π t / DURATION)`: every motion swings once per loop and ends where it began.
fn swing(t: f32) -> f32 {
    (2.0 * PI * t / DURATION).sin()
}

/// The room's surfaces seen from inside, by material: floor, ceiling (none when roofless),
/// the left (-X) and right (+X) walls, and the back (-Z) and front (+Z) walls.
fn room(roofless: bool) -> [MeshData; 5] {
    let (x, z) = (W * 0.5, D * 0.5);
    let c = Vec3::new;
    let (floor, ceiling) = shapes::floor_and_ceiling(W, D, H, Vec2::ONE);
    let ceiling = if roofless {
        MeshData::default()
    } else {
        ceiling
    };
    let mut left = MeshData::default();
    left.quad(
        [c(-x, 0., z), c(-x, 0., -z), c(-x, H, -z), c(-x, H, z)],
        Vec2::new(D, H),
    );
    let mut right = MeshData::default();
    right.quad(
        [c(x, 0., -z), c(x, 0., z), c(x, H, z), c(x, H, -z)],
        Vec2::new(D, H),
    );
    let mut ends = MeshData::default();
    ends.quad(
        [c(-x, 0., -z), c(x, 0., -z), c(x, H, -z), c(-x, H, -z)],
        Vec2::new(W, H),
    )
    .quad(
        [c(x, 0., z), c(-x, 0., z), c(-x, H, z), c(x, H, z)],
        Vec2::new(W, H),
    );
    [floor, ceiling, left, right, ends]
}

/// Builds the motion scene `name` as GLB bytes; `None` for a name not in [`NAMES`].
pub fn build(name: &str) -> Option<Vec<u8>> {
    let motion = match name {
        "motion-sweep" => Motion::Sweep,
        "motion-orbit" => Motion::Orbit,
        "motion-sun" => Motion::Sun,
        "motion-crossing" => Motion::Crossing,
        "motion-dolly" => Motion::Dolly,
        _ => return None,
    };
    let mut w = GlbWriter::new();
    let pbr = |name: &str, c: [f32; 3], roughness: f32| {
        json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0],
               "metallicFactor": 0.0, "roughnessFactor": roughness}})
    };
    let materials = [
        ("oak floor", [0.55, 0.4, 0.28], 0.7),
        ("white ceiling", [0.85, 0.85, 0.85], 1.0),
        ("teal wall", [0.2, 0.55, 0.5], 0.9),
        ("plum wall", [0.55, 0.25, 0.45], 0.9),
        ("sand walls", [0.8, 0.75, 0.6], 0.95),
    ]
    .map(|(n, c, r)| w.push("materials", pbr(n, c, r)));
    let m_grey = w.push("materials", pbr("grey plinth", [0.6, 0.6, 0.6], 0.8));
    let parts = room(motion == Motion::Sun);
    let room = w.mesh(
        "room",
        &parts
            .iter()
            .zip(materials)
            .filter(|(m, _)| !m.indices.is_empty())
            .collect::<Vec<_>>(),
    );
    let mut roots = vec![w.push("nodes", json!({"name": "room", "mesh": room}))];
    let plinth = w.mesh(
        "plinth",
        &[(&shapes::cuboid(Vec3::new(0.6, 0.9, 0.6)), m_grey)],
    );
    roots.push(w.push(
        "nodes",
        json!({"name": "plinth", "mesh": plinth, "translation": [1.0, 0.45, -1.3],
               "rotation": Quat::from_rotation_y(0.4).to_array()}),
    ));

    let mut tracks = Tracks::default();
    let times = key_times();
    lights(&mut w, motion, &times, &mut tracks, &mut roots);
    if motion == Motion::Crossing {
        let block = w.mesh("block", &[(&shapes::cuboid(Vec3::splat(0.5)), m_grey)]);
        let node = w.push(
            "nodes",
            json!({"name": "crossing block", "mesh": block, "translation": [0.0, 0.25, 0.3]}),
        );
        let values: Vec<f32> = times
            .iter()
            .flat_map(|&t| [1.4 * swing(t), 0.25, 0.3])
            .collect();
        tracks.add(&mut w, node, "translation", "LINEAR", &times, &values);
        roots.push(node);
    }

    let camera = w.push(
        "cameras",
        json!({"name": "end wall", "type": "perspective", "perspective": {"yfov": 1.1, "znear": 0.05, "zfar": 30.0}}),
    );
    let eye = Vec3::new(0.0, 1.5, 2.2);
    let target = Vec3::new(0.0, 0.9, -1.5);
    let node = w.push(
        "nodes",
        json!({"name": "camera", "camera": camera, "translation": eye.to_array(),
               "rotation": aim(eye, target).to_array()}),
    );
    if motion == Motion::Dolly {
        // Forward 1.2 m and sideways ±0.6 m, always looking at the same point.
        let at = |t: f32| {
            let along = 0.5 - 0.5 * (2.0 * PI * t / DURATION).cos();
            eye + Vec3::new(0.6 * swing(t), 0.0, -1.2 * along)
        };
        let translations: Vec<f32> = times.iter().flat_map(|&t| at(t).to_array()).collect();
        let rotations: Vec<f32> = times
            .iter()
            .flat_map(|&t| aim(at(t), target).to_array())
            .collect();
        tracks.add(&mut w, node, "translation", "LINEAR", &times, &translations);
        tracks.add(&mut w, node, "rotation", "LINEAR", &times, &rotations);
    }
    roots.push(node);
    tracks.write(&mut w, "motion");
    w.scene(name, &roots);
    Some(w.to_glb())
}

/// The lights of `motion`'s scene, with their tracks.
fn lights(
    w: &mut GlbWriter,
    motion: Motion,
    times: &[f32],
    tracks: &mut Tracks,
    roots: &mut Vec<usize>,
) {
    let spot = |w: &mut GlbWriter, name: &str, intensity: f32| {
        w.light(
            json!({"name": name, "type": "spot", "color": [1.0, 0.93, 0.82], "intensity": intensity,
                       "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}}),
        )
    };
    let lamp = |w: &mut GlbWriter, intensity: f32| {
        w.light(
            json!({"name": "lamp", "type": "point", "color": [0.75, 0.85, 1.0],
                       "intensity": intensity, "range": 15.0}),
        )
    };
    let node = |w: &mut GlbWriter, name: &str, light: usize, at: Vec3, rotation: Quat| {
        w.push(
            "nodes",
            json!({"name": name, "translation": at.to_array(), "rotation": rotation.to_array(),
                   "extensions": {"KHR_lights_punctual": {"light": light}}}),
        )
    };
    let spot_at = Vec3::new(-0.6, H - 0.1, 1.6);
    let spot_target = Vec3::new(0.4, 0.3, -1.6);
    match motion {
        Motion::Sun => {
            let sun = w.light(json!({"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 3.0}));
            let towards = |t: f32| {
                let (elevation, azimuth) = (0.75f32, 0.5 + SUN_SWING * swing(t));
                Vec3::new(
                    elevation.cos() * azimuth.sin(),
                    -elevation.sin(),
                    -elevation.cos() * azimuth.cos(),
                )
            };
            let rotation = |t: f32| aim(Vec3::ZERO, towards(t));
            let n = node(w, "sun", sun, Vec3::new(0.0, 10.0, 0.0), rotation(0.0));
            let values: Vec<f32> = times.iter().flat_map(|&t| rotation(t).to_array()).collect();
            tracks.add(w, n, "rotation", "LINEAR", times, &values);
            roots.push(n);
        }
        Motion::Orbit => {
            let l = lamp(w, 8.0);
            let at = |t: f32| {
                let a = 2.0 * PI * t / DURATION;
                Vec3::new(1.1 * a.cos(), 1.8, -0.6 + 1.3 * a.sin())
            };
            let n = node(w, "orbiting lamp", l, at(0.0), Quat::IDENTITY);
            let values: Vec<f32> = times.iter().flat_map(|&t| at(t).to_array()).collect();
            tracks.add(w, n, "translation", "LINEAR", times, &values);
            roots.push(n);
            let s = spot(w, "still spot", 60.0);
            roots.push(node(w, "still spot", s, spot_at, aim(spot_at, spot_target)));
        }
        Motion::Sweep => {
            let s = spot(w, "sweeping spot", 90.0);
            let rotation = |t: f32| {
                let turn = Quat::from_rotation_y(SWEEP * swing(t));
                aim(spot_at, spot_at + turn * (spot_target - spot_at))
            };
            let n = node(w, "sweeping spot", s, spot_at, rotation(0.0));
            let values: Vec<f32> = times.iter().flat_map(|&t| rotation(t).to_array()).collect();
            tracks.add(w, n, "rotation", "LINEAR", times, &values);
            roots.push(n);
            let l = lamp(w, 3.0);
            roots.push(node(
                w,
                "still lamp",
                l,
                Vec3::new(1.3, 2.2, 0.8),
                Quat::IDENTITY,
            ));
        }
        Motion::Crossing | Motion::Dolly => {
            let down = Vec3::new(-0.2, 0.0, 0.3);
            let s = spot(w, "still spot", 90.0);
            roots.push(node(w, "still spot", s, spot_at, aim(spot_at, down)));
            let l = lamp(w, 3.0);
            roots.push(node(
                w,
                "still lamp",
                l,
                Vec3::new(1.3, 2.2, 0.8),
                Quat::IDENTITY,
            ));
        }
    }
}
