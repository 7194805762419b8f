//! CPU twins of `*_resolve` and `*_reproject` (src/passes/amortise.rs, shaders/amortise.comp):
//! an amortised technique's reprojection, disocclusion test and blend, texel for texel.

use glam::{Vec2, Vec3, Vec4};

use crate::passes::amortise::{RESOLVE_ALPHA, same_surface};

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

/// Whether pixel (x, y) is the refreshed one of its cell in slice 1 + k (`amortise_refreshed`).
fn refreshed(slice: u32, x: u32, y: u32) -> bool {
    let k = slice.saturating_sub(1);
    (x & 1) == (k & 1) && (y & 1) == (k >> 1)
}

/// The resolved light and geometry, as the pass writes them.
pub fn resolve_cpu(inp: &ResolveInputs<'_>) -> (Vec<Vec4>, Vec<Vec4>) {
    let [w, h] = inp.extent;
    let at = |x: u32, y: u32| (y * w + x) as usize;
    let k = inp.slice.saturating_sub(1);
    let refreshed = |x, y| refreshed(inp.slice, x, y);
    let history_at = |x, y, depth, n| history_at(inp, x, y, depth, n);
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
            light[i] = match history_at(x, y, position.w, n) {
                // Regathered this frame (`hvl_regather`).
                None => inp.fresh[i],
                Some(j) if refreshed(x, y) => {
                    inp.history_light[j].lerp(inp.fresh[i], RESOLVE_ALPHA)
                }
                Some(j) => {
                    // The change of the cell's refreshed receiver, where it shows this
                    // surface.
                    let held = inp.history_light[j];
                    let (cx, cy) = (
                        ((x / 2) * 2 + (k & 1)).min(w - 1),
                        ((y / 2) * 2 + (k >> 1)).min(h - 1),
                    );
                    let c = at(cx, cy);
                    let (cd, cn) = (inp.position[c].w, inp.normal[c].normalize());
                    let shared = (refreshed(cx, cy) && same_surface(position.w, n, cd, cn))
                        .then(|| history_at(cx, cy, cd, cn))
                        .flatten();
                    match shared {
                        Some(cj) => (held + RESOLVE_ALPHA * (inp.fresh[c] - inp.history_light[cj]))
                            .max(Vec4::ZERO),
                        None => held,
                    }
                }
            };
        }
    }
    (light, geometry)
}

/// CPU twin of `*_reproject` (variant `records` of shaders/amortise.comp): `records` (`words`
/// u32 per pixel, the refreshed pixels' gathered already) with every other pixel's records
/// copied from `history_records` where its history shows its surface; and which pixels the
/// pass marks for the regather. `inp.fresh` and `inp.history_light` are not read.
pub fn reproject_cpu(
    inp: &ResolveInputs<'_>,
    history_records: &[u32],
    records: &[u32],
    words: usize,
) -> (Vec<u32>, Vec<bool>) {
    let [w, h] = inp.extent;
    let refreshed = |x, y| refreshed(inp.slice, x, y);
    let mut out = records.to_vec();
    let mut marks = vec![false; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let depth = inp.position[i].w;
            if inp.slice == 0 || refreshed(x, y) || depth == 0.0 {
                continue;
            }
            match history_at(inp, x, y, depth, inp.normal[i].normalize()) {
                Some(j) => out[i * words..(i + 1) * words]
                    .copy_from_slice(&history_records[j * words..(j + 1) * words]),
                None => marks[i] = true,
            }
        }
    }
    (out, marks)
}
