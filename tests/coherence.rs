//! Temporal coherence of the flux distribution (issues 23 and 43): each light owns a
//! progressive Sobol (0, 2)-sequence in its RSM, warped through its current flux by a continuous
//! inverse, so a small turn of the light moves every sample a little and keeps every sample's
//! identity, and a change in one light's share leaves the other lights' samples in place.
//! Checked on the CPU twin of `hvl_flux` (tests/hvl.rs ties it to the GPU sample for sample).

mod common;

use std::collections::BTreeMap;

use common::spot_rsm::{HEIGHT, turned_spot};
use glam::{Vec3, Vec4};
use shine::passes::hvl::flux::sequence_id;
use shine::passes::hvl::{Distribution, Hvl, HvlParams};
use shine::reference::hvl::RsmData;
use shine::reference::hvl_flux::build_flux_cache;

/// The samples of a cache by identity (light, sample index): position and flux weight.
fn by_identity(hvls: &[Hvl]) -> BTreeMap<(u32, u32), (Vec3, f32)> {
    hvls.iter()
        .filter(|h| h.is_valid())
        .map(|h| {
            let p = Vec4::from(h.position_radius).truncate();
            (
                (h.light, h.sample_index),
                (p, h.flux[0] + h.flux[1] + h.flux[2]),
            )
        })
        .collect()
}

/// The flux cache of `count` samples over `faces`.
fn cache(faces: &[RsmData], count: u32) -> Vec<Hvl> {
    let params = HvlParams {
        count,
        distribution: Distribution::Flux,
        ..HvlParams::default()
    };
    build_flux_cache(faces, &params).expect("flux cache")
}

/// The largest distance between the positions of neighbouring texels of `rsm`: a texel's
/// footprint on its surface, at its widest.
fn widest_footprint(rsm: &RsmData) -> f32 {
    let s = rsm.size as usize;
    let mut widest = 0.0f32;
    for y in 0..s {
        for x in 0..s {
            let p = rsm.position[y * s + x];
            for (nx, ny) in [(x + 1, y), (x, y + 1)] {
                if nx < s && ny < s {
                    let q = rsm.position[ny * s + nx];
                    if p.w > 0.0 && q.w > 0.0 {
                        widest = widest.max(p.truncate().distance(q.truncate()));
                    }
                }
            }
        }
    }
    widest
}

/// A turn of 0.1° (about a tenth of a texel's angle), 40 times over (4°), across the crease
/// and the albedo edge: every one of 1024 samples keeps its identity and moves by less than
/// half the widest texel footprint per turn (the continuous inverse slides it; a redrawn or
/// texel-stepping sample would jump by whole footprints), and the HVLs carry the light's whole
/// flux each time.
#[test]
fn a_small_turn_of_the_light_moves_every_sample_a_little_and_keeps_its_identity() {
    assert_eq!(HvlParams::default().distribution, Distribution::Flux);
    let count = 1024;
    let step = 0.1f32.to_radians();
    let first = turned_spot(0.3, 1.0);
    let footprint = widest_footprint(&first);
    let mut before = by_identity(&cache(std::slice::from_ref(&first), count));
    assert_eq!(before.len(), count as usize);
    let mut worst = 0.0f32;
    for k in 1..=40 {
        let after = by_identity(&cache(&[turned_spot(0.3 + k as f32 * step, 1.0)], count));
        assert!(
            before.keys().eq(after.keys()),
            "turn {k}: the samples' identities changed"
        );
        for (id, (a, b)) in before.values().zip(after.values()).enumerate() {
            let moved = a.0.distance(b.0);
            assert!(
                moved < 0.5 * footprint,
                "turn {k}: sample {id} moved {moved} m (footprint {footprint} m): {a:?} -> {b:?}"
            );
            worst = worst.max(moved);
        }
        before = after;
    }
    eprintln!("largest move per 0.1° turn: {worst} m, widest texel footprint {footprint} m");
}

/// Two lights: the spot turns, a second light (another RSM, light 1) holds still. The spot's
/// flux, and so the lights' shares, change with every turn; every sample of the still light
/// that both frames keep stays exactly where it was. Its weights all scale by one factor (each
/// sample carries Φ/M' of the total, which the spot changes), except its newest, which fades by
/// the fractional part of the share.
#[test]
fn a_change_in_one_lights_share_leaves_the_other_lights_samples_in_place() {
    let count = 512;
    // The still light's sequence (its one face).
    let id = sequence_id(1, 0);
    let still = RsmData {
        light: 1,
        light_position: Vec3::new(1.0, HEIGHT, 0.5),
        ..turned_spot(-0.2, 1.0)
    };
    let mut before = by_identity(&cache(&[turned_spot(0.0, 1.0), still.clone()], count));
    let mut counts = Vec::new();
    for k in 1..=12 {
        let after = by_identity(&cache(
            &[turned_spot(k as f32 * 0.005, 1.0), still.clone()],
            count,
        ));
        let kept = |m: &BTreeMap<(u32, u32), (Vec3, f32)>| {
            m.keys().filter(|(light, _)| *light == id).count() as u32
        };
        let (n0, n1) = (kept(&before), kept(&after));
        counts.push(n1);
        let newest = n0.min(n1) - 1;
        let scale = after[&(id, 0)].1 / before[&(id, 0)].1;
        for j in 0..newest {
            let (a, b) = (before[&(id, j)], after[&(id, j)]);
            assert_eq!(a.0, b.0, "turn {k}: still light's sample {j} moved");
            assert!(
                (b.1 / a.1 - scale).abs() <= 1e-5 * scale,
                "turn {k}: still light's sample {j} reweighted by {} against {scale}",
                b.1 / a.1
            );
        }
        before = after;
    }
    assert!(
        counts.windows(2).any(|w| w[0] != w[1]),
        "the shares never changed: {counts:?}"
    );
}
