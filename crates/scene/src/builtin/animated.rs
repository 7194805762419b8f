//! `animated`: a 5 m × 3 m × 4 m room with a large window in its +X wall, for issue 15
//! ("frames that move"): everything in it that can move does, for 16 s (a whole number of
//! walk cycles and curtain gusts, so the animation loops; 300 frames at 24 fps stay in
//! motion).
//!
//! - A skinned figure ([`super::walker`]) walking two laps of an ellipse across the room,
//!   with one proxy sphere per bone (paper 002).
//! - A curtain beside the window with two morph targets (a billow and a sideways sway) whose
//!   weights follow cubic-spline gusts; normal deltas included.
//! - A spot light on a ceiling node whose rotation sweeps its beam across the room and back,
//!   and a dim warm point light.
//! - Sky light through the window: a procedural sky in the root `extras`.
//! - Materials unlike the other built-ins: a rough terracotta wall, a glossy varnished floor,
//!   a copper sphere of roughness 0.3, a linen curtain, a clay-blue figure.
//! - A camera in the room's (-X, +Z) corner looking at the window wall.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use serde_json::json;

use super::shapes::{self, MeshData};
use super::tracks::{Tracks, aim};
use super::walker::{self, Path};
use crate::environment::{self, Environment};
use crate::error::Result;
use crate::glb_writer::{DeformingPrimitive, GlbWriter};
use crate::types::MorphTarget;

/// Width (x), height and depth (z) of the room, in metres.
const W: f32 = 5.0;
const H: f32 = 3.0;
const D: f32 = 4.0;
/// Length of the animation, in seconds.
const DURATION: f32 = 16.0;
/// The window in the +X wall: z from `-WINDOW` to `WINDOW`, y from `SILL` to `LINTEL`.
const WINDOW: f32 = 1.4;
const SILL: f32 = 0.6;
const LINTEL: f32 = 2.5;

/// The late-afternoon sky seen through the window.
pub fn sky() -> Environment {
    Environment {
        zenith: Vec3::new(0.3, 0.45, 0.9),
        horizon: Vec3::new(1.0, 0.82, 0.6),
        ground: Vec3::new(0.3, 0.27, 0.22),
        intensity: 1.5,
        map: None,
    }
}

/// The room's surfaces, seen from inside: floor, ceiling, the coloured back wall (-Z) and
/// the other walls with the window cut out of the +X one.
fn room() -> [MeshData; 4] {
    let (x, z) = (W * 0.5, D * 0.5);
    let c = Vec3::new;
    let (floor, ceiling) = shapes::floor_and_ceiling(W, D, H, Vec2::ONE);
    let mut back = MeshData::default();
    back.quad(
        [c(-x, 0., -z), c(x, 0., -z), c(x, H, -z), c(-x, H, -z)],
        Vec2::new(W, H),
    );
    let mut walls = MeshData::default();
    walls
        .quad(
            [c(-x, 0., z), c(-x, 0., -z), c(-x, H, -z), c(-x, H, z)],
            Vec2::new(D, H),
        ) // left (-X), faces +X
        .quad(
            [c(x, 0., z), c(-x, 0., z), c(-x, H, z), c(x, H, z)],
            Vec2::new(W, H),
        ); // front (+Z), faces -Z
    // The +X wall (faces -X) around the window: below, above, and the two sides.
    let (wz, lo, hi) = (WINDOW, SILL, LINTEL);
    for (z0, z1, y0, y1) in [
        (-z, z, 0.0, lo),
        (-z, z, hi, H),
        (-z, -wz, lo, hi),
        (wz, z, lo, hi),
    ] {
        walls.quad(
            [c(x, y0, z0), c(x, y0, z1), c(x, y1, z1), c(x, y1, z0)],
            Vec2::new(z1 - z0, y1 - y0),
        );
    }
    [floor, ceiling, back, walls]
}

/// Curtain grid resolution (columns along z, rows along y).
const CURTAIN_COLUMNS: usize = 10;
const CURTAIN_ROWS: usize = 16;

/// The curtain hanging from a rail at `top` between `z0` and `z1` at `x`, facing -X, and its
/// two morph targets: the position at weight 1 is `f(u, v)` of the flat one, `u` across and
/// `v` down from the rail (which stays put).
fn curtain(x: f32, z0: f32, z1: f32, top: f32, bottom: f32) -> (MeshData, [MorphTarget; 2]) {
    let point = |u: f32, v: f32| Vec3::new(x, top + (bottom - top) * v, z0 + (z1 - z0) * u);
    let billow = |u: f32, v: f32| {
        let amp = 0.22 * v.powf(1.5);
        Vec3::new(-amp * (0.6 + 0.4 * (3.0 * PI * u).sin()), 0.0, 0.0)
    };
    let sway = |u: f32, v: f32| {
        let amp = 0.18 * v * v;
        Vec3::new(-0.5 * amp * (4.0 * PI * u).cos(), 0.02 * amp, -amp)
    };
    let (nu, nv) = (CURTAIN_COLUMNS, CURTAIN_ROWS);
    let grid = |f: &dyn Fn(f32, f32) -> Vec3| -> Vec<Vec3> {
        (0..=nv)
            .flat_map(|j| (0..=nu).map(move |i| (i as f32 / nu as f32, j as f32 / nv as f32)))
            .map(|(u, v)| point(u, v) + f(u, v))
            .collect()
    };
    // Unit normals of a displaced grid, from central differences (facing -X when flat).
    let normals = |p: &[Vec3]| -> Vec<Vec3> {
        let at = |i: usize, j: usize| p[j.min(nv) * (nu + 1) + i.min(nu)];
        (0..=nv)
            .flat_map(|j| (0..=nu).map(move |i| (i, j)))
            .map(|(i, j)| {
                let du = at(i + 1, j) - at(i.saturating_sub(1), j);
                let dv = at(i, j + 1) - at(i, j.saturating_sub(1));
                dv.cross(du).normalize_or(Vec3::NEG_X)
            })
            .collect()
    };
    let flat = grid(&|_, _| Vec3::ZERO);
    let flat_normals = normals(&flat);
    let mut mesh = MeshData {
        positions: flat.clone(),
        normals: flat_normals.clone(),
        uvs: (0..=nv)
            .flat_map(|j| {
                (0..=nu).map(move |i| Vec2::new(i as f32 / nu as f32, j as f32 / nv as f32))
            })
            .collect(),
        indices: Vec::new(),
    };
    for j in 0..nv as u32 {
        for i in 0..nu as u32 {
            let a = j * (nu as u32 + 1) + i;
            let (b, c, d) = (a + 1, a + nu as u32 + 2, a + nu as u32 + 1);
            // Counter-clockwise seen from -X.
            mesh.indices.extend([a, d, c, a, c, b]);
        }
    }
    let target = |f: &dyn Fn(f32, f32) -> Vec3| {
        let p = grid(f);
        let n = normals(&p);
        MorphTarget {
            positions: p.iter().zip(&flat).map(|(a, b)| *a - *b).collect(),
            normals: n.iter().zip(&flat_normals).map(|(a, b)| *a - *b).collect(),
        }
    };
    let targets = [target(&billow), target(&sway)];
    (mesh, targets)
}

/// Builds the scene as GLB bytes.
pub fn build() -> Result<Vec<u8>> {
    let mut w = GlbWriter::new();
    let pbr = |name: &str, c: [f32; 3], metallic: f32, roughness: f32| {
        json!({"name": name, "pbrMetallicRoughness": {"baseColorFactor": [c[0], c[1], c[2], 1.0],
               "metallicFactor": metallic, "roughnessFactor": roughness}})
    };
    let m_floor = w.push(
        "materials",
        pbr("varnished floor", [0.32, 0.2, 0.11], 0.0, 0.12),
    );
    let m_ceiling = w.push(
        "materials",
        pbr("white ceiling", [0.88, 0.88, 0.86], 0.0, 1.0),
    );
    let m_terracotta = w.push(
        "materials",
        pbr("terracotta wall", [0.72, 0.34, 0.2], 0.0, 0.85),
    );
    let m_walls = w.push(
        "materials",
        pbr("pale green walls", [0.7, 0.76, 0.68], 0.0, 0.9),
    );
    let m_copper = w.push("materials", pbr("copper", [0.95, 0.64, 0.54], 1.0, 0.3));
    let m_clay = w.push("materials", pbr("clay blue", [0.45, 0.55, 0.72], 0.0, 0.6));
    let mut linen = pbr("linen curtain", [0.86, 0.82, 0.7], 0.0, 0.95);
    linen["doubleSided"] = json!(true);
    let m_linen = w.push("materials", linen);

    let [floor, ceiling, back, walls] = room();
    let room = w.mesh(
        "room",
        &[
            (&floor, m_floor),
            (&ceiling, m_ceiling),
            (&back, m_terracotta),
            (&walls, m_walls),
        ],
    );
    let mut roots = vec![w.push("nodes", json!({"name": "room", "mesh": room}))];
    let sphere = w.mesh(
        "copper sphere",
        &[(&shapes::uv_sphere(0.35, 32, 16), m_copper)],
    );
    roots.push(w.push(
        "nodes",
        json!({"name": "copper sphere", "mesh": sphere, "translation": [-1.75, 0.35, -1.45]}),
    ));

    let mut tracks = Tracks::default();
    let path = Path {
        centre: Vec2::new(-0.3, 0.05),
        radii: Vec2::new(1.35, 0.9),
        laps: 2.0,
        duration: DURATION,
    };
    roots.extend(walker::add(&mut w, m_clay, &path, &mut tracks)?);

    // Curtain beside the window, gusting: cubic-spline weights every 2 s, flat tangents.
    let (mesh, targets) = curtain(W * 0.5 - 0.12, 0.2, 1.5, LINTEL + 0.1, 0.15);
    let curtain_mesh = w.deforming_mesh(
        "curtain",
        &[DeformingPrimitive {
            geometry: &mesh,
            material: m_linen,
            joints: &[],
            weights: &[],
            targets: &targets,
        }],
        &[0.0, 0.0],
    )?;
    let curtain_node = w.push("nodes", json!({"name": "curtain", "mesh": curtain_mesh}));
    roots.push(curtain_node);
    let billow = [0.0, 0.8, 0.3, 1.0, 0.2, 0.9, 0.4, 0.7, 0.0];
    let sway = [0.0, 0.3, 0.9, 0.2, 0.7, 0.1, 0.8, 0.3, 0.0];
    let times: Vec<f32> = (0..billow.len()).map(|k| k as f32 * 2.0).collect();
    let values: Vec<f32> = billow
        .iter()
        .zip(&sway)
        .flat_map(|(b, s)| [0.0, 0.0, *b, *s, 0.0, 0.0])
        .collect();
    tracks.add(
        &mut w,
        curtain_node,
        "weights",
        "CUBICSPLINE",
        &times,
        &values,
    );

    // Lights: a spot sweeping across the room and back, a dim warm lamp.
    let spot = w.light(json!({"name": "sweeping spot", "type": "spot", "color": [1.0, 0.95, 0.85],
                              "intensity": 90.0, "spot": {"innerConeAngle": 0.18, "outerConeAngle": 0.35}}));
    let lamp = w.light(
        json!({"name": "dim lamp", "type": "point", "color": [1.0, 0.7, 0.45],
                              "intensity": 4.0, "range": 12.0}),
    );
    let spot_at = Vec3::new(-0.5, H - 0.1, D * 0.5 - 0.2);
    let times: Vec<f32> = (0..=8).map(|k| k as f32 * DURATION / 8.0).collect();
    let rotations: Vec<f32> = times
        .iter()
        .flat_map(|t| {
            let s = (t / DURATION * 2.0 * PI).sin();
            aim(spot_at, Vec3::new(1.9 * s, 0.0, -1.2)).to_array()
        })
        .collect();
    let spot_node = w.push(
        "nodes",
        json!({"name": "sweeping spot", "translation": spot_at.to_array(),
               "rotation": aim(spot_at, Vec3::new(0.0, 0.0, -1.2)).to_array(),
               "extensions": {"KHR_lights_punctual": {"light": spot}}}),
    );
    tracks.add(&mut w, spot_node, "rotation", "LINEAR", &times, &rotations);
    roots.push(spot_node);
    roots.push(w.push(
        "nodes",
        json!({"name": "dim lamp", "translation": [-1.8, 2.6, -1.3],
               "extensions": {"KHR_lights_punctual": {"light": lamp}}}),
    ));
    tracks.write(&mut w, "walk");

    let camera = w.push(
        "cameras",
        json!({"name": "corner", "type": "perspective", "perspective": {"yfov": 1.05, "znear": 0.05, "zfar": 40.0}}),
    );
    let eye = Vec3::new(-2.25, 1.9, 1.8);
    roots.push(w.push(
        "nodes",
        json!({"name": "camera", "camera": camera, "translation": eye.to_array(),
               "rotation": aim(eye, Vec3::new(0.7, 0.8, -0.6)).to_array()}),
    ));
    w.set_extras(json!({environment::EXTRAS_KEY: sky().to_json()}));
    w.scene("animated", &roots);
    Ok(w.to_glb())
}
