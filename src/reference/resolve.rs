//! CPU twins of `*_resolve` and `*_reproject` (src/passes/amortise.rs, shaders/amortise.comp):
//! an amortised technique's reprojection, disocclusion test and blend, texel for texel.

use glam::{Vec2, Vec3, Vec4};

use crate::passes::amortise::{
    RECORD_BLOCK, RESOLVE_ALPHA, RecordSignal, changed, refreshed, same_surface, slice_offset,
};
use crate::study::runner::f16_to_f32;

/// The images `hvl_resolve` reads, row-major.
pub struct ResolveInputs<'a> {
    /// Receiver extent.
    pub extent: [u32; 2],
    /// Full-resolution extent (of `motion`).
    pub full_extent: [u32; 2],
    /// Receiver positions (w: linear depth, 0 on the background).
    pub position: &'a [Vec4],
    /// Receiver normals.
    pub normal: &'a [Vec3],
    /// This frame's gathers (valid at the slice's receivers and at those whose history is
    /// rejected).
    pub fresh: &'a [Vec4],
    /// Full-resolution motion (uv now minus uv then).
    pub motion: &'a [Vec2],
    /// The previous frame's resolved light.
    pub history_light: &'a [Vec4],
    /// The previous frame's (normal, linear depth).
    pub history_geometry: &'a [Vec4],
    /// 0: every receiver gathered; 1 + k: the refreshed receiver of each 2×2 cell.
    pub slice: u32,
    /// Whether the history holds the previous frame.
    pub has_history: bool,
}

/// Where pixel (x, y) at `depth` with normal `n` finds its history, if it shows its surface
/// (`history_at` in the shader): the history's index.
fn history_at(inp: &ResolveInputs<'_>, x: u32, y: u32, depth: f32, n: Vec3) -> Option<usize> {
    let [w, h] = inp.extent;
    let [fw, fh] = inp.full_extent;
    let full_x = (((x as f32 + 0.5) * fw as f32 / w as f32) as u32).min(fw - 1);
    let full_y = (((y as f32 + 0.5) * fh as f32 / h as f32) as u32).min(fh - 1);
    let uv = Vec2::new((x as f32 + 0.5) / w as f32, (y as f32 + 0.5) / h as f32);
    let then = uv - inp.motion[(full_y * fw + full_x) as usize];
    let q = (then * Vec2::new(w as f32, h as f32)).floor();
    if !inp.has_history || q.x < 0.0 || q.y < 0.0 || q.x >= w as f32 || q.y >= h as f32 {
        return None;
    }
    let j = (q.y as u32 * w + q.x as u32) as usize;
    let g = inp.history_geometry[j];
    same_surface(depth, n, g.w, g.truncate()).then_some(j)
}

/// Refreshed pixel (cx, cy) and its history's index, where it has history
/// (`refreshed_value` in the shader).
fn refreshed_history(inp: &ResolveInputs<'_>, cx: u32, cy: u32) -> Option<(usize, usize)> {
    if !refreshed(inp.slice, cx, cy) {
        return None;
    }
    let c = (cy * inp.extent[0] + cx) as usize;
    let (cd, cn) = (inp.position[c].w, inp.normal[c].normalize());
    history_at(inp, cx, cy, cd, cn).map(|cj| (c, cj))
}

/// What `cell_changed` in the shader says of (x, y)'s cell, which shows the surface at `depth`
/// with normal `n`, for values (now, then) of a refreshed pixel and its history `value(c, cj)`:
/// whether it changed beyond the limit, and the cell's refreshed pixel and its history's
/// index where it shows that surface (whose change the pixel may share or take).
fn cell_changed(
    inp: &ResolveInputs<'_>,
    (x, y): (u32, u32),
    (depth, n): (f32, Vec3),
    value: impl Fn(usize, usize) -> (Vec3, Vec3),
) -> (bool, Option<(usize, usize)>) {
    let [w, h] = inp.extent;
    let [kx, ky] = slice_offset(inp.slice);
    // The cell's refreshed pixel, clamped where an odd edge cuts the cell (it is then not
    // refreshed; the cells beside its unclamped place decide).
    let (ox, oy) = ((x / 2) * 2 + kx, (y / 2) * 2 + ky);
    let moved = |(c, cj): (usize, usize)| {
        let (now, then) = value(c, cj);
        changed(now, then)
    };
    if let Some(own) = refreshed_history(inp, ox.min(w - 1), oy.min(h - 1)) {
        let c = own.0;
        let on_surface = same_surface(depth, n, inp.position[c].w, inp.normal[c].normalize());
        let changed = moved(own);
        if on_surface || changed {
            return (changed, on_surface.then_some(own));
        }
    }
    let (ox, oy) = (i64::from(ox), i64::from(oy));
    let beside = [(-2, 0), (2, 0), (0, -2), (0, 2)]
        .into_iter()
        .any(|(dx, dy)| {
            let (sx, sy) = (ox + dx, oy + dy);
            (0..i64::from(w)).contains(&sx)
                && (0..i64::from(h)).contains(&sy)
                && refreshed_history(inp, sx as u32, sy as u32).is_some_and(moved)
        });
    (beside, None)
}

/// What `block_changed` in the shader says of (x, y)'s block: whether the summed values
/// `value(c, cj)` of its refreshed pixels with history changed beyond the limit.
fn block_changed(
    inp: &ResolveInputs<'_>,
    (x, y): (u32, u32),
    value: impl Fn(usize, usize) -> (Vec3, Vec3),
) -> bool {
    let [w, h] = inp.extent;
    let [kx, ky] = slice_offset(inp.slice);
    // Blocks cut by the image's edge moved inside it.
    let origin = |v: u32, side: u32| {
        (v / RECORD_BLOCK * RECORD_BLOCK).min(side.saturating_sub(RECORD_BLOCK))
    };
    let (ox, oy) = (origin(x, w), origin(y, h));
    let (mut now, mut then) = (Vec3::ZERO, Vec3::ZERO);
    for j in (0..RECORD_BLOCK).step_by(2) {
        for i in (0..RECORD_BLOCK).step_by(2) {
            let (cx, cy) = (ox + i + kx, oy + j + ky);
            if cx >= w || cy >= h {
                continue;
            }
            if let Some((c, cj)) = refreshed_history(inp, cx, cy) {
                let (a, b) = value(c, cj);
                now += a;
                then += b;
            }
        }
    }
    changed(now, then)
}

/// The change test of the light: the light now and in the history.
fn light_change<'a>(inp: &'a ResolveInputs<'a>) -> impl Fn(usize, usize) -> (Vec3, Vec3) + 'a {
    |c, cj| (inp.fresh[c].truncate(), inp.history_light[cj].truncate())
}

/// The resolved light and geometry, as the pass writes them.
pub fn resolve_cpu(inp: &ResolveInputs<'_>) -> (Vec<Vec4>, Vec<Vec4>) {
    let [w, h] = inp.extent;
    let at = |x: u32, y: u32| (y * w + x) as usize;
    let mut light = vec![Vec4::ZERO; (w * h) as usize];
    let mut geometry = vec![Vec4::ZERO; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = at(x, y);
            let position = inp.position[i];
            if position.w == 0.0 {
                continue;
            }
            let n = inp.normal[i].normalize();
            geometry[i] = n.extend(position.w);
            if inp.slice == 0 {
                light[i] = inp.fresh[i];
                continue;
            }
            let (fresh, valid) = (inp.fresh[i], history_at(inp, x, y, position.w, n));
            light[i] = match valid {
                // Regathered this frame (`hvl_regather`).
                None => fresh,
                Some(j) if refreshed(inp.slice, x, y) => {
                    let history = inp.history_light[j];
                    if changed(fresh.truncate(), history.truncate()) {
                        fresh
                    } else {
                        history.lerp(fresh, RESOLVE_ALPHA)
                    }
                }
                Some(j) => match cell_changed(inp, (x, y), (position.w, n), light_change(inp)) {
                    // Its cell changed beyond the limit: the refreshed receiver's light where
                    // it shows this surface, regathered this frame otherwise.
                    (true, Some((c, _))) => inp.fresh[c],
                    (true, None) => fresh,
                    // The change of the cell's refreshed receiver, where it shows this
                    // surface.
                    (false, Some((c, cj))) => (inp.history_light[j]
                        + RESOLVE_ALPHA * (inp.fresh[c] - inp.history_light[cj]))
                        .max(Vec4::ZERO),
                    (false, None) => inp.history_light[j],
                },
            };
        }
    }
    (light, geometry)
}

/// The rgb value the change test reads of a record (`record_signal`).
fn record_signal(signal: RecordSignal, record: &[u32]) -> Vec3 {
    let half = |word: u32, high: bool| f16_to_f32(if high { word >> 16 } else { word } as u16);
    match signal {
        RecordSignal::None => Vec3::ZERO,
        RecordSignal::PackedRgb => Vec3::new(
            half(record[0], false),
            half(record[0], true),
            half(record[1], false),
        ),
        RecordSignal::MeanRgb => {
            let sum = Vec4::from_array([0, 1, 2, 3].map(|k| f32::from_bits(record[k])));
            if sum.w > 0.0 {
                sum.truncate() / sum.w
            } else {
                Vec3::ZERO
            }
        }
    }
}

/// CPU twin of `*_reproject` (variant `records` of shaders/amortise.comp): `records` (`words`
/// u32 per pixel, the refreshed pixels' gathered already) with every other pixel's records
/// copied from `history_records` where its history shows its surface and, with `signal`, its
/// block's refreshed records' summed signal did not change beyond the limit; and which pixels
/// the pass marks for the regather. `inp.fresh` and `inp.history_light` are not read.
pub fn reproject_cpu(
    inp: &ResolveInputs<'_>,
    history_records: &[u32],
    records: &[u32],
    words: usize,
    signal: RecordSignal,
) -> (Vec<u32>, Vec<bool>) {
    let [w, h] = inp.extent;
    let mut out = records.to_vec();
    let mut marks = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let depth = inp.position[i].w;
            if inp.slice == 0 || refreshed(inp.slice, x, y) || depth == 0.0 {
                continue;
            }
            let changed = block_changed(inp, (x, y), |c, cj| {
                (
                    record_signal(signal, &records[c * words..]),
                    record_signal(signal, &history_records[cj * words..]),
                )
            });
            let n = inp.normal[i].normalize();
            match history_at(inp, x, y, depth, n).filter(|_| !changed) {
                Some(j) => out[i * words..(i + 1) * words]
                    .copy_from_slice(&history_records[j * words..(j + 1) * words]),
                None => marks[i] = true,
            }
        }
    }
    (out, marks)
}
