//! Temporal coherence of the flux distribution (issue 23, item 1): HVLs and VPLs come from a
//! fixed Hammersley pattern in the RSM's texel space, warped through the current flux, so a
//! small turn of the light moves every one of them a little instead of redrawing them.
//! Checked on the CPU twin of `hvl_flux` (tests/hvl.rs ties it to the GPU texel for texel).

use glam::{Mat3, Vec3, Vec4};
use shine::passes::hvl::{Distribution, HvlParams};
use shine::passes::rsm::RsmProjection;
use shine::reference::hvl::RsmData;
use shine::reference::hvl_flux::{running_sums, sample_texel};

/// RSM side.
const SIZE: u32 = 64;
/// The spot's height over the floor, metres.
const HEIGHT: f32 = 2.5;
/// The wall's plane x = WALL_X, facing +x.
const WALL_X: f32 = -1.5;
/// Where the floor's albedo steps from 0.8 to 0.3 (x, metres): an edge the flux crosses.
const ALBEDO_EDGE_X: f32 = 0.4;

/// The RSM of a spot at (0, HEIGHT, 0), turned by `angle` about z from straight down, over a
/// floor (y = 0) with an albedo edge and a wall (x = WALL_X): a crease and an edge in its flux.
/// Flux: albedo × the texel's solid angle × a smooth spot falloff, as an RSM holds it.
fn turned_spot(angle: f32) -> RsmData {
    let turn = Mat3::from_rotation_z(angle);
    let eye = Vec3::new(0.0, HEIGHT, 0.0);
    let mut rsm = RsmData {
        size: SIZE,
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
            let flux = albedo * solid_angle * falloff * n.dot(-d).max(0.0);
            rsm.position.push((eye + t * d).extend(1.0));
            rsm.normal.push(n.extend(0.0));
            rsm.flux.push(Vec4::new(flux, 0.9 * flux, 0.8 * flux, 0.0));
        }
    }
    rsm
}

/// An HVL's place: its texel, world position, and the texel's footprint (the largest
/// distance to the positions of its eight neighbours).
type Place = ((u32, u32), Vec3, f32);

/// Where each of `count` HVLs sits.
fn draw(rsm: &RsmData, count: u32) -> Vec<Place> {
    let faces = std::slice::from_ref(rsm);
    let cdf = running_sums(faces);
    let at = |x: i64, y: i64| {
        let inside = (0..i64::from(SIZE)).contains(&x) && (0..i64::from(SIZE)).contains(&y);
        inside
            .then(|| rsm.position[(y * i64::from(SIZE) + x) as usize])
            .filter(|p| p.w > 0.0)
            .map(Vec4::truncate)
    };
    (0..count)
        .map(|m| {
            let (_, x, y) = sample_texel(faces, &cdf, m, count).expect("flux");
            let (x, y) = (i64::from(x), i64::from(y));
            let p = at(x, y).expect("a drawn texel holds a surface");
            let footprint = (-1..=1)
                .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
                .filter_map(|(nx, ny)| at(nx, ny))
                .map(|q| q.distance(p))
                .fold(0.0, f32::max);
            ((x as u32, y as u32), p, footprint)
        })
        .collect()
}

/// A turn of 0.1° (about a tenth of a texel's angle) moves every one of 1024 HVLs by at most
/// one texel in each direction, and in the world by at most the footprint of the texel it
/// leaves, across the crease and the albedo edge, over a sweep of 40 such turns (4°): the
/// HVLs travel with the light instead of being redrawn.
#[test]
fn a_small_turn_of_the_light_moves_every_hvl_a_little() {
    assert_eq!(HvlParams::default().distribution, Distribution::Flux);
    let count = 1024;
    let step = 0.1f32.to_radians();
    let mut before = draw(&turned_spot(0.3), count);
    let (mut worst_texels, mut worst_metres) = (0u32, 0.0f32);
    for k in 1..=40 {
        let after = draw(&turned_spot(0.3 + k as f32 * step), count);
        for (m, (a, b)) in before.iter().zip(&after).enumerate() {
            let texels = a.0.0.abs_diff(b.0.0).max(a.0.1.abs_diff(b.0.1));
            let metres = a.1.distance(b.1);
            assert!(
                texels <= 1 && metres <= a.2 * 1.01,
                "turn {k}: HVL {m} moved {texels} texels, {metres} m ({a:?} -> {b:?})"
            );
            worst_texels = worst_texels.max(texels);
            worst_metres = worst_metres.max(metres);
        }
        before = after;
    }
    eprintln!("largest move per 0.1° turn: {worst_texels} texels, {worst_metres} m");
}
