//! CPU twin of `shaders/sample_history.comp` ([`crate::passes::sample_history`]): each sample's
//! flux and normal blended with its identity's record of the last frame unless a stated change
//! starts it over; same rule, same order of operations.

use glam::{Vec3, Vec4};

use crate::passes::hvl::Hvl;
use crate::passes::sample_history::SampleHistoryPush;

/// The flux's size: r + g + b.
fn flux_sum(h: &Hvl) -> f32 {
    h.flux[0] + h.flux[1] + h.flux[2]
}

/// Whether `now` continues `last` (both valid): moved at most `jump` radii, flux within
/// `ratio` either way, normal within acos `min_cos`.
pub fn continues(now: &Hvl, last: &Hvl, push: &SampleHistoryPush) -> bool {
    let p = Vec4::from(now.position_radius);
    let q = Vec4::from(last.position_radius);
    let moved = p.truncate().distance(q.truncate());
    let reach = push.jump * p.w.max(q.w);
    let (a, b) = (flux_sum(now), flux_sum(last));
    let n = Vec4::from(now.normal_distance).truncate();
    let m = Vec4::from(last.normal_distance).truncate();
    moved <= reach && a <= push.ratio * b && b <= push.ratio * a && n.dot(m) >= push.min_cos
}

/// `x + (y − x)·t` per component, as GLSL's `mix`.
fn mix(x: Vec3, y: Vec3, t: f32) -> Vec3 {
    x * (1.0 - t) + y * t
}

/// Filters `cache` in place against `previous` (the history of the last frame, `push.lights ×
/// push.count` records by identity; ignored without `push.has_history`); returns this frame's
/// history: each identity's position, normal and flux (empty records where no sample of that
/// identity exists).
pub fn filter(cache: &mut [Hvl], previous: &[Hvl], push: &SampleHistoryPush) -> Vec<Hvl> {
    let count = push.count as usize;
    let mut current: Vec<Hvl> =
        vec![bytemuck::Zeroable::zeroed(); count * push.lights.max(1) as usize];
    for now in cache.iter_mut().take(count) {
        if !now.is_valid() || now.light >= push.lights || now.sample_index >= push.count {
            continue;
        }
        let id = (now.light * push.count + now.sample_index) as usize;
        if push.has_history != 0 {
            let last = &previous[id];
            if last.is_valid() && continues(now, last, push) {
                let flux = mix(
                    Vec4::from(last.flux).truncate(),
                    Vec4::from(now.flux).truncate(),
                    push.weight,
                );
                now.flux = flux.extend(now.flux[3]).to_array();
                let n = mix(
                    Vec4::from(last.normal_distance).truncate(),
                    Vec4::from(now.normal_distance).truncate(),
                    push.weight,
                )
                .normalize();
                now.normal_distance = n.extend(now.normal_distance[3]).to_array();
            }
        }
        // What the next frame's rule reads; the identity is the record's index.
        let kept = &mut current[id];
        kept.position_radius = now.position_radius;
        kept.normal_distance = now.normal_distance;
        kept.flux = now.flux;
    }
    current
}
