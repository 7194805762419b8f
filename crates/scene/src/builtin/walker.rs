//! The skinned walking figure of `animated`: one mesh of eleven tapered tubes (pelvis,
//! torso, head, upper arms, forearms, thighs, shins), about 1.72 m tall, bound to an
//! eleven-joint skeleton, with a looping walk cycle.
//!
//! Bind pose: standing at the origin facing +Z, arms down, every joint without rotation, so
//! each inverse bind matrix is the inverse of the joint's bind translation. Each tube
//! follows one joint; near a joint its vertices blend two joints (half and half at the
//! joint, fading over a few centimetres), so elbows, knees, hips and shoulders bend
//! smoothly. Weights are multiples of 1/64 so every vertex's four sum to exactly 1.
//! Each joint node carries one proxy sphere for its body part (paper 002).

use std::f32::consts::TAU;

use glam::{Mat4, Quat, Vec2, Vec3, Vec4};
use serde_json::json;

use super::shapes::MeshData;
use super::tracks::Tracks;
use crate::error::Result;
use crate::glb_writer::{DeformingPrimitive, GlbWriter};
use crate::proxies::{self, ProxySphere};

/// Period of one walk cycle (two steps), in seconds.
pub(super) const CYCLE: f32 = 1.0;
/// Key frames per walk cycle.
const KEYS_PER_CYCLE: usize = 16;
/// Sides of every tube's cross-section.
const SIDES: usize = 8;

/// A joint of the skeleton: name, parent (index in [`JOINTS`]) and bind translation
/// relative to the parent (the hips' is relative to the figure's feet).
struct Joint {
    name: &'static str,
    parent: Option<usize>,
    offset: [f32; 3],
}

const HIPS: usize = 0;
const SPINE: usize = 1;
const HEAD: usize = 2;
const UPPER_ARM_L: usize = 3;
const FOREARM_L: usize = 4;
const UPPER_ARM_R: usize = 5;
const FOREARM_R: usize = 6;
const THIGH_L: usize = 7;
const SHIN_L: usize = 8;
const THIGH_R: usize = 9;
const SHIN_R: usize = 10;

/// The skeleton; the figure's left is +X (it faces +Z).
#[rustfmt::skip]
const JOINTS: [Joint; 11] = [
    Joint { name: "hips", parent: None, offset: [0.0, 0.95, 0.0] },
    Joint { name: "spine", parent: Some(HIPS), offset: [0.0, 0.10, 0.0] },
    Joint { name: "head", parent: Some(SPINE), offset: [0.0, 0.40, 0.0] },
    Joint { name: "upper arm L", parent: Some(SPINE), offset: [0.25, 0.33, 0.0] },
    Joint { name: "forearm L", parent: Some(UPPER_ARM_L), offset: [0.0, -0.29, 0.0] },
    Joint { name: "upper arm R", parent: Some(SPINE), offset: [-0.25, 0.33, 0.0] },
    Joint { name: "forearm R", parent: Some(UPPER_ARM_R), offset: [0.0, -0.29, 0.0] },
    Joint { name: "thigh L", parent: Some(HIPS), offset: [0.10, -0.05, 0.0] },
    Joint { name: "shin L", parent: Some(THIGH_L), offset: [0.0, -0.44, 0.0] },
    Joint { name: "thigh R", parent: Some(HIPS), offset: [-0.10, -0.05, 0.0] },
    Joint { name: "shin R", parent: Some(THIGH_R), offset: [0.0, -0.44, 0.0] },
];

/// One body part: a tube along ±Y from its joint, with rings `(distance from the joint,
/// half width in x, half depth in z)`, blending with `parent` near its start and `child`
/// near its end over the given distances.
struct Part {
    joint: usize,
    up: bool,
    rings: &'static [(f32, f32, f32)],
    parent: Option<(usize, f32)>,
    child: Option<(usize, f32)>,
}

/// Rings of an upper arm (shoulder to elbow).
const ARM: &[(f32, f32, f32)] = &[
    (0.0, 0.05, 0.05),
    (0.06, 0.055, 0.055),
    (0.23, 0.045, 0.045),
    (0.29, 0.045, 0.045),
];
/// Rings of a forearm with a flat hand.
const FOREARM: &[(f32, f32, f32)] = &[
    (0.0, 0.045, 0.045),
    (0.22, 0.035, 0.035),
    (0.26, 0.04, 0.025),
    (0.32, 0.035, 0.02),
];
/// Rings of a thigh (hip to knee).
const THIGH: &[(f32, f32, f32)] = &[
    (0.0, 0.08, 0.08),
    (0.08, 0.08, 0.085),
    (0.38, 0.06, 0.06),
    (0.44, 0.055, 0.055),
];
/// Rings of a shin ending in a foot reaching the floor.
#[rustfmt::skip]
const SHIN: &[(f32, f32, f32)] =
    &[(0.0, 0.055, 0.055), (0.1, 0.055, 0.06), (0.38, 0.04, 0.04), (0.42, 0.045, 0.1), (0.46, 0.045, 0.1)];

/// The body, one part per joint (same order as [`JOINTS`]).
#[rustfmt::skip]
const PARTS: [Part; 11] = [
    Part { joint: HIPS, up: true, rings: &[(-0.11, 0.14, 0.1), (0.0, 0.16, 0.11), (0.1, 0.16, 0.11)],
           parent: None, child: Some((SPINE, 0.05)) },
    Part { joint: SPINE, up: true, rings: &[(0.0, 0.16, 0.11), (0.2, 0.18, 0.12), (0.35, 0.2, 0.12), (0.42, 0.1, 0.07)],
           parent: Some((HIPS, 0.06)), child: None },
    Part { joint: HEAD, up: true,
           rings: &[(0.0, 0.05, 0.05), (0.06, 0.05, 0.05), (0.09, 0.09, 0.1), (0.22, 0.1, 0.11), (0.28, 0.06, 0.07)],
           parent: Some((SPINE, 0.05)), child: None },
    Part { joint: UPPER_ARM_L, up: false, rings: ARM, parent: Some((SPINE, 0.06)), child: Some((FOREARM_L, 0.05)) },
    Part { joint: FOREARM_L, up: false, rings: FOREARM, parent: Some((UPPER_ARM_L, 0.05)), child: None },
    Part { joint: UPPER_ARM_R, up: false, rings: ARM, parent: Some((SPINE, 0.06)), child: Some((FOREARM_R, 0.05)) },
    Part { joint: FOREARM_R, up: false, rings: FOREARM, parent: Some((UPPER_ARM_R, 0.05)), child: None },
    Part { joint: THIGH_L, up: false, rings: THIGH, parent: Some((HIPS, 0.08)), child: Some((SHIN_L, 0.06)) },
    Part { joint: SHIN_L, up: false, rings: SHIN, parent: Some((THIGH_L, 0.06)), child: None },
    Part { joint: THIGH_R, up: false, rings: THIGH, parent: Some((HIPS, 0.08)), child: Some((SHIN_R, 0.06)) },
    Part { joint: SHIN_R, up: false, rings: SHIN, parent: Some((THIGH_R, 0.06)), child: None },
];

/// Bind-pose position of every joint (figure space, feet at the origin).
fn bind_positions() -> [Vec3; 11] {
    let mut out = [Vec3::ZERO; 11];
    for (i, j) in JOINTS.iter().enumerate() {
        let parent = j.parent.map_or(Vec3::ZERO, |p| out[p]);
        out[i] = parent + Vec3::from(j.offset);
    }
    out
}

/// The skinned figure mesh: geometry, `JOINTS_0` and `WEIGHTS_0`.
struct Body {
    mesh: MeshData,
    joints: Vec<[u32; 4]>,
    weights: Vec<Vec4>,
}

impl Body {
    /// Appends a vertex with up to three joint influences `(joint, weight)` (weights
    /// summing to 1; zero ones dropped, unused slots are joint 0 with weight 0 as the
    /// Khronos validator prefers).
    fn vertex(&mut self, p: Vec3, n: Vec3, uv: Vec2, influences: &[(usize, f32)]) {
        let mut joints = [0u32; 4];
        let mut weights = [0.0f32; 4];
        let mut k = 0;
        for &(j, w) in influences {
            if w > 0.0 && k < 4 {
                joints[k] = j as u32;
                weights[k] = w;
                k += 1;
            }
        }
        self.mesh.positions.push(p);
        self.mesh.normals.push(n);
        self.mesh.uvs.push(uv);
        self.joints.push(joints);
        self.weights.push(Vec4::from_array(weights));
    }

    /// Appends a triangle, wound counter-clockwise around `outward`.
    fn triangle(&mut self, [a, b, c]: [u32; 3], outward: Vec3) {
        let p = |i: u32| self.mesh.positions[i as usize];
        let face = (p(b) - p(a)).cross(p(c) - p(a));
        let tri = if face.dot(outward) >= 0.0 {
            [a, b, c]
        } else {
            [a, c, b]
        };
        self.mesh.indices.extend(tri);
    }

    /// Appends one body part.
    fn part(&mut self, part: &Part, origin: Vec3) {
        let dir = if part.up { Vec3::Y } else { Vec3::NEG_Y };
        let length = part.rings.last().map_or(0.0, |r| r.0);
        let quantise = |w: f32| (w.clamp(0.0, 0.5) * 64.0).round() / 64.0;
        let influences = |s: f32| {
            let wp = part
                .parent
                .map_or(0.0, |(_, d)| quantise(0.5 * (1.0 - s / d)));
            let wc = part
                .child
                .map_or(0.0, |(_, d)| quantise(0.5 * (1.0 - (length - s) / d)));
            [
                (part.joint, 1.0 - wp - wc),
                (part.parent.map_or(0, |p| p.0), wp),
                (part.child.map_or(0, |c| c.0), wc),
            ]
        };
        let ring_point = |(s, rx, rz): (f32, f32, f32), k: usize| {
            let a = k as f32 / SIDES as f32 * TAU;
            let (sin, cos) = a.sin_cos();
            let p = origin + dir * s + Vec3::new(rx * cos, 0.0, rz * sin);
            let n = Vec3::new(cos / rx.max(1e-3), 0.0, sin / rz.max(1e-3)).normalize_or(Vec3::X);
            (p, n)
        };
        // Sides: one vertex per ring corner (smooth around), SIDES + 1 columns for UVs.
        let base = self.mesh.positions.len() as u32;
        for (r, &ring) in part.rings.iter().enumerate() {
            for k in 0..=SIDES {
                let (p, n) = ring_point(ring, k);
                let uv = Vec2::new(k as f32 / SIDES as f32, r as f32 / part.rings.len() as f32);
                self.vertex(p, n, uv, &influences(ring.0));
            }
        }
        let row = SIDES as u32 + 1;
        for r in 0..part.rings.len() as u32 - 1 {
            for k in 0..SIDES as u32 {
                let a = base + r * row + k;
                let (b, c, d) = (a + 1, a + row + 1, a + row);
                let outward = self.mesh.normals[a as usize] + self.mesh.normals[b as usize];
                self.triangle([a, b, c], outward);
                self.triangle([a, c, d], outward);
            }
        }
        // Flat caps at both ends.
        let ends = [part.rings.first(), part.rings.last()];
        for (end, ring) in ends.into_iter().enumerate() {
            let Some(&ring) = ring else { continue };
            let n = if end == 0 { -dir } else { dir };
            let centre = self.mesh.positions.len() as u32;
            let inf = influences(ring.0);
            self.vertex(origin + dir * ring.0, n, Vec2::splat(0.5), &inf);
            for k in 0..SIDES {
                let (p, _) = ring_point(ring, k);
                self.vertex(p, n, Vec2::ZERO, &inf);
            }
            for k in 0..SIDES as u32 {
                let next = (k + 1) % SIDES as u32;
                self.triangle([centre, centre + 1 + k, centre + 1 + next], n);
            }
        }
    }
}

/// The walk at time `t`: the local rotation of each joint (the hips' without heading).
fn joint_rotation(joint: usize, t: f32) -> Quat {
    let phase = t / CYCLE * TAU;
    let (s, c) = phase.sin_cos();
    // +X rotations swing a downward limb backwards: negative angles bring it forward.
    match joint {
        HIPS => Quat::from_rotation_y(0.08 * s),
        SPINE => Quat::from_rotation_y(-0.12 * s) * Quat::from_rotation_x(0.05),
        HEAD => Quat::from_rotation_y(0.05 * s) * Quat::from_rotation_x(-0.04),
        THIGH_L => Quat::from_rotation_x(-0.42 * s),
        THIGH_R => Quat::from_rotation_x(0.42 * s),
        SHIN_L => Quat::from_rotation_x(0.05 + 0.65 * c.max(0.0)),
        SHIN_R => Quat::from_rotation_x(0.05 + 0.65 * (-c).max(0.0)),
        UPPER_ARM_L => Quat::from_rotation_x(0.32 * s) * Quat::from_rotation_z(0.06),
        UPPER_ARM_R => Quat::from_rotation_x(-0.32 * s) * Quat::from_rotation_z(-0.06),
        FOREARM_L => Quat::from_rotation_x(-0.25 - 0.2 * (-s).max(0.0)),
        FOREARM_R => Quat::from_rotation_x(-0.25 - 0.2 * s.max(0.0)),
        _ => Quat::IDENTITY,
    }
}

/// The path of the hips: an ellipse around `centre` with `radii` (x, z), walked `laps`
/// times over `duration` seconds. Returns the position on the floor and the heading (yaw
/// about +Y turning the figure's +Z along the path).
pub(super) struct Path {
    /// Centre of the ellipse on the floor.
    pub(super) centre: Vec2,
    /// Half axes along x and z.
    pub(super) radii: Vec2,
    /// Number of laps.
    pub(super) laps: f32,
    /// Time for all laps, in seconds (a whole number of walk cycles).
    pub(super) duration: f32,
}

impl Path {
    fn at(&self, t: f32) -> (Vec2, f32) {
        let a = t / self.duration * self.laps * TAU;
        let (s, c) = a.sin_cos();
        let p = self.centre + Vec2::new(self.radii.x * s, self.radii.y * c);
        let d = Vec2::new(self.radii.x * c, -self.radii.y * s);
        (p, d.x.atan2(d.y))
    }
}

/// Adds the figure: the skeleton (a root node, returned first), the skinned mesh node (a
/// root, returned second) and the walk channels along `path` to `tracks`.
pub(super) fn add(
    w: &mut GlbWriter,
    material: usize,
    path: &Path,
    tracks: &mut Tracks,
) -> Result<[usize; 2]> {
    let bind = bind_positions();
    let mut body = Body {
        mesh: MeshData::default(),
        joints: Vec::new(),
        weights: Vec::new(),
    };
    for part in &PARTS {
        body.part(part, bind[part.joint]);
    }
    let mesh = w.deforming_mesh(
        "walker",
        &[DeformingPrimitive {
            geometry: &body.mesh,
            material,
            joints: &body.joints,
            weights: &body.weights,
            targets: &[],
        }],
        &[],
    )?;

    // Joint nodes; children pushed first so their indices are known.
    let mut nodes = [0usize; 11];
    for i in (0..JOINTS.len()).rev() {
        let j = &JOINTS[i];
        let children: Vec<usize> = (0..JOINTS.len())
            .filter(|&c| JOINTS[c].parent == Some(i))
            .map(|c| nodes[c])
            .collect();
        let part = &PARTS[i];
        let sign = if part.up { 1.0 } else { -1.0 };
        let (s0, s1) = (part.rings[0].0, part.rings.last().map_or(0.0, |r| r.0));
        let widest = part.rings.iter().map(|r| r.1.max(r.2)).fold(0.0, f32::max);
        let sphere = ProxySphere {
            center: [0.0, sign * 0.5 * (s0 + s1), 0.0],
            radius: (0.5 * (s1 - s0)).max(widest),
        };
        let mut node = json!({"name": j.name, "translation": j.offset,
                              "extras": {proxies::EXTRAS_KEY: proxies::to_json(&[sphere])}});
        if !children.is_empty() {
            node["children"] = json!(children);
        }
        nodes[i] = w.push("nodes", node);
    }
    let inverse_bind: Vec<Mat4> = bind.iter().map(|p| Mat4::from_translation(-*p)).collect();
    let skin = w.skin("walker skeleton", &nodes, &inverse_bind, Some(nodes[HIPS]));
    let body_node = w.push(
        "nodes",
        json!({"name": "walker", "mesh": mesh, "skin": skin}),
    );

    let keys = (path.duration / CYCLE).round() as usize * KEYS_PER_CYCLE;
    let times: Vec<f32> = (0..=keys)
        .map(|k| k as f32 * path.duration / keys as f32)
        .collect();
    let mut hips_t = Vec::new();
    let mut hips_r = Vec::new();
    for &t in &times {
        let (p, heading) = path.at(t);
        // Lowest with both feet down (twice a cycle), at rest height when the legs pass.
        let bob = 0.93 + 0.02 * (2.0 * t / CYCLE * TAU).cos();
        hips_t.extend([p.x, bob, p.y]);
        let q = Quat::from_rotation_y(heading) * joint_rotation(HIPS, t);
        hips_r.extend(q.normalize().to_array());
    }
    tracks.add(w, nodes[HIPS], "translation", "LINEAR", &times, &hips_t);
    tracks.add(w, nodes[HIPS], "rotation", "LINEAR", &times, &hips_r);
    for (joint, &node) in nodes.iter().enumerate().skip(1) {
        let values: Vec<f32> = times
            .iter()
            .flat_map(|&t| joint_rotation(joint, t).normalize().to_array())
            .collect();
        tracks.add(w, node, "rotation", "LINEAR", &times, &values);
    }
    Ok([nodes[HIPS], body_node])
}
