//! A spot's RSM built in code: a spot turned about z over a floor with an albedo edge and a
//! wall, as an RSM holds it (the coherence and sample-history tests turn it frame by frame).

use glam::{Mat3, Vec3, Vec4};
use shine::passes::rsm::RsmProjection;
use shine::reference::hvl::RsmData;

/// RSM side.
pub const SIZE: u32 = 64;
/// The spot's height over the floor, metres.
pub const HEIGHT: f32 = 2.5;
/// The wall's plane x = WALL_X, facing +x.
pub const WALL_X: f32 = -1.5;
/// Where the floor's albedo steps from 0.8 to 0.3 (x, metres): an edge the flux crosses.
pub const ALBEDO_EDGE_X: f32 = 0.4;

/// The RSM of a spot at (0, HEIGHT, 0), turned by `angle` about z from straight down, over a
/// floor (y = 0) with an albedo edge and a wall (x = WALL_X): a crease and an edge in its flux.
/// Flux: `power` × albedo × the texel's solid angle × a smooth spot falloff, as an RSM holds
/// it.
pub fn turned_spot(angle: f32, power: f32) -> RsmData {
    let turn = Mat3::from_rotation_z(angle);
    let eye = Vec3::new(0.0, HEIGHT, 0.0);
    let mut rsm = RsmData {
        size: SIZE,
        light: 0,
        position: Vec::new(),
        normal: Vec::new(),
        flux: Vec::new(),
        light_position: eye,
        light_direction: turn * Vec3::NEG_Y,
        projection: RsmProjection::Perspective {
            fov: std::f32::consts::FRAC_PI_2,
        },
    };
    for j in 0..SIZE {
        for i in 0..SIZE {
            let u = (i as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0;
            let v = (j as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0;
            let local = Vec3::new(u, -1.0, v);
            let d = turn * local.normalize();
            let floor = (d.y < 0.0).then(|| eye.y / -d.y);
            let wall = (d.x < 0.0).then(|| (WALL_X - eye.x) / d.x);
            let (t, n, albedo) = match (floor, wall) {
                (Some(f), Some(w)) if w < f => (w, Vec3::X, 0.6),
                (Some(f), _) => {
                    let x = eye.x + f * d.x;
                    (f, Vec3::Y, if x < ALBEDO_EDGE_X { 0.8 } else { 0.3 })
                }
                (None, Some(w)) => (w, Vec3::X, 0.6),
                (None, None) => {
                    rsm.position.push(Vec4::ZERO);
                    rsm.normal.push(Vec4::ZERO);
                    rsm.flux.push(Vec4::ZERO);
                    continue;
                }
            };
            let solid_angle = 1.0 / local.length().powi(3);
            let falloff = (1.0 - (u * u + v * v) / 2.0).max(0.0);
            let flux = power * albedo * solid_angle * falloff * n.dot(-d).max(0.0);
            rsm.position.push((eye + t * d).extend(1.0));
            rsm.normal.push(n.extend(0.0));
            rsm.flux.push(Vec4::new(flux, 0.9 * flux, 0.8 * flux, 0.0));
        }
    }
    rsm
}
