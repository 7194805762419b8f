//! CPU twin of `shaders/hvl_flux.comp` and `shaders/include/sample_identity.glsl`: the HVL
//! cache of [`Distribution::Flux`] over the RSM faces of every light, with samples that keep
//! their identity (issue 43). Light k owns the progressive Sobol (0, 2)-sequence
//! `(u_j, v_j)` ([`shine_sh::sequence::sobol_02`]), j = 0, 1, …, warped through its own flux; the budget M' = M − (N − 1) is
//! split by flux, `s_k = M' Φ_k / Φ`, light k keeping `⌈s_k⌉` samples, the last faded by the
//! fractional part of `s_k`; each sample sits where its targets fall within its texel's share
//! of the running sums (the continuous inverse), blended with the neighbours it leans to on
//! its own surface.
//! The draws use the shader's f32 sums and products in the same order, so both pick the same
//! texels; positions, fluxes and radii agree to float rounding.
//!
//! [`Distribution::Flux`]: crate::passes::hvl::Distribution::Flux

use glam::{Vec3, Vec4};
use shine_sh::hvl::{RsmFootprint, radius_spacing, rsm_texel_area};
use shine_sh::sequence::sobol_02;

use super::hvl::{RsmData, sender_emission_zh};
use crate::passes::hvl::flux::sequence_ids;
use crate::passes::hvl::{EMISSION_MAX_BANDS, Hvl, HvlError, HvlParams};
use crate::passes::rsm::RsmProjection;

/// Smallest cosine between a texel's normal and a neighbour's that a sample blends across
/// (GLSL `HVL_FLUX_BLEND_NORMAL_COS`).
pub const BLEND_NORMAL_COS: f32 = 0.9;
/// Largest component along a texel's normal of the step to a neighbour it blends with, as a
/// fraction of the step (GLSL `HVL_FLUX_BLEND_PLANE`): beyond it the neighbour is across a
/// depth step.
pub const BLEND_PLANE: f32 = 0.25;
/// The digital shift of the flux samples' Sobol points (GLSL `HVL_FLUX_SOBOL_SHIFT`): a half
/// in both dimensions, so a light's first sample sits at the middle of its flux.
pub const SOBOL_SHIFT: u32 = 1 << 31;
/// Base-5 digits of a sample's set key (GLSL `IGI_SET_DIGITS`): 5⁹ times the most sets (64)
/// fits a u32.
const SET_DIGITS: u32 = 9;
/// 5⁹ (GLSL `IGI_SET_SCALE`).
const SET_SCALE: u32 = 1_953_125;

/// The flux weight of a texel: `r + g + b` of its flux, 0 when it is empty (GLSL
/// `texel_weight`).
pub fn texel_weight(rsm: &RsmData, texel: usize) -> f32 {
    if rsm.position[texel].w == 0.0 {
        return 0.0;
    }
    let f = rsm.flux[texel];
    (f.x + f.y + f.z).max(0.0)
}

/// The base-`b` radical inverse of `j` to `digits` digits, as the integer numerator over
/// `b^digits` (GLSL `radical_inverse_digits`).
pub fn radical_inverse_digits(mut j: u32, b: u32, digits: u32) -> u32 {
    let mut r = 0;
    for _ in 0..digits {
        r = r * b + j % b;
        j /= b;
    }
    r
}

/// The samples M' split between `lights` lights: `M − (N − 1)`, at least 1, so that the
/// rounded-up counts sum to at most M (GLSL `hvl_flux_budget`).
pub fn budget(count: u32, lights: u32) -> u32 {
    if count > lights {
        count - (lights - 1)
    } else {
        1
    }
}

/// `n_k = ⌈M' Φ_k / Φ⌉`, decided by products: the least n with `n Φ ≥ M' Φ_k`, at most M';
/// 0 unless `0 < Φ_k` and Φ is finite (GLSL `hvl_flux_light_count`).
pub fn light_count(budget: u32, light_total: f32, total: f32) -> u32 {
    let goal = budget as f32 * light_total;
    if !(light_total > 0.0 && total > 0.0) || total.is_infinite() || goal.is_infinite() {
        return 0;
    }
    let mut n = ((goal / total).ceil() as u32).min(budget);
    while n > 0 && (n - 1) as f32 * total >= goal {
        n -= 1;
    }
    while n < budget && (n as f32) * total < goal {
        n += 1;
    }
    n
}

/// The interleaved set (of `sets`) of sample `j`: `⌊φ₅(j) sets⌋` (GLSL `igi_sample_set`).
/// Each light's samples spread evenly over the sets, and a VPL keeps its set wherever its
/// record lands.
pub fn sample_set(j: u32, sets: u32) -> u32 {
    radical_inverse_digits(j, 5, SET_DIGITS) * sets / SET_SCALE
}

/// One RSM face's sample sequence: its identity ([`sequence_ids`]) and its rows.
#[derive(Clone, Debug, PartialEq)]
pub struct LightFaces {
    /// The sequence's identity, the samples' first part ([`Hvl::light`]).
    pub light: u32,
    /// Its first row in the global row order.
    pub row_offset: usize,
    /// Its rows (the face's side).
    pub rows: usize,
}

/// The faces' sequences, in order, one per face: a point light's six consecutive cube faces
/// are faces 0–5 of its light.
pub fn light_faces(faces: &[RsmData]) -> Vec<LightFaces> {
    let ids = sequence_ids(faces.iter().map(|face| face.light));
    let mut groups: Vec<LightFaces> = Vec::with_capacity(faces.len());
    let mut row = 0;
    for (face, id) in faces.iter().zip(ids) {
        groups.push(LightFaces {
            light: id,
            row_offset: row,
            rows: face.size as usize,
        });
        row += face.size as usize;
    }
    groups
}

/// The `cdf` buffer of the shader: every face's per-row running sums (face by face), the row
/// totals in global row order, their running sums restarted at each light, then the light
/// table: `[Φ, M', 0, 0]` and per light `[Φ_k, s_k, n_k, offset_k]`.
pub fn running_sums(faces: &[RsmData], count: u32) -> Vec<f32> {
    let texels: usize = faces.iter().map(|f| (f.size * f.size) as usize).sum();
    let rows: usize = faces.iter().map(|f| f.size as usize).sum();
    let groups = light_faces(faces);
    let table = texels + 2 * rows;
    let mut cdf = vec![0.0f32; table + 4 * (groups.len() + 1)];
    let (mut texel_offset, mut row) = (0, 0);
    for face in faces {
        let s = face.size as usize;
        for y in 0..s {
            let mut sum = 0.0f32;
            for x in 0..s {
                sum += texel_weight(face, y * s + x);
                cdf[texel_offset + y * s + x] = sum;
            }
            cdf[texels + row] = sum;
            row += 1;
        }
        texel_offset += s * s;
    }
    for (k, g) in groups.iter().enumerate() {
        let mut sum = 0.0f32;
        for r in g.row_offset..g.row_offset + g.rows {
            sum += cdf[texels + r];
            cdf[texels + rows + r] = sum;
        }
        cdf[table + 4 * (k + 1)] = sum;
    }
    let total: f32 = (0..groups.len()).map(|k| cdf[table + 4 * (k + 1)]).sum();
    let m = budget(count, groups.len() as u32);
    cdf[table] = total;
    cdf[table + 1] = m as f32;
    let mut offset = 0;
    for k in 0..groups.len() {
        let e = table + 4 * (k + 1);
        let light_total = cdf[e];
        let n = if total > 0.0 {
            light_count(m, light_total, total).min(count - offset)
        } else {
            0
        };
        cdf[e + 1] = if total > 0.0 {
            m as f32 * light_total / total
        } else {
            0.0
        };
        cdf[e + 2] = n as f32;
        cdf[e + 3] = offset as f32;
        offset += n;
    }
    cdf
}

/// The first index in `0..len` where `passed` holds, `len - 1` when none does (`passed` is
/// monotone: false then true), as the shader's binary searches.
fn first_passing(len: usize, passed: impl Fn(usize) -> bool) -> usize {
    let (mut lo, mut hi) = (0, len - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if passed(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
}

/// Where a sample falls: its record, face and texel, and the fractions `f` (across the row)
/// and `g` (down the rows) of its texel's share at which its targets fall.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Draw {
    /// The record it is written to: the light's offset plus its index.
    pub slot: u32,
    /// Its face in the face list.
    pub face: usize,
    /// Its texel.
    pub texel: (u32, u32),
    /// Where within the texel: `(f, g)` in [0, 1]².
    pub within: (f32, f32),
    /// Its weight: 1, or the fractional part of the light's share for its newest sample.
    pub fade: f32,
    /// The samples its light keeps (`n_k`).
    pub light_samples: u32,
}

/// Sample `j` of light group `k`, given the faces and their [`running_sums`]; `None` when the
/// light keeps fewer than `j + 1` samples.
pub fn draw(faces: &[RsmData], cdf: &[f32], k: usize, j: u32) -> Option<Draw> {
    let rows: usize = faces.iter().map(|f| f.size as usize).sum();
    let groups = light_faces(faces);
    let texels = cdf.len() - 2 * rows - 4 * (groups.len() + 1);
    let group = &groups[k];
    let e = texels + 2 * rows + 4 * (k + 1);
    let (light_total, share, n, offset) = (cdf[e], cdf[e + 1], cdf[e + 2], cdf[e + 3]);
    if j >= n as u32 {
        return None;
    }
    let marginal = &cdf[texels + rows + group.row_offset..][..group.rows];
    let [u, v] = sobol_02(j, [SOBOL_SHIFT; 2]);
    let row_goal = u * light_total;
    let lo = first_passing(group.rows, |r| marginal[r] > row_goal);
    let row = group.row_offset + lo;
    let (mut face, mut row_offset, mut texel_offset) = (0, 0, 0);
    while row >= row_offset + faces[face].size as usize {
        row_offset += faces[face].size as usize;
        texel_offset += (faces[face].size * faces[face].size) as usize;
        face += 1;
    }
    let s = faces[face].size as usize;
    let y = row - row_offset;
    let row_total = cdf[texels + row];
    let target = v * row_total;
    let at_total = target >= row_total;
    let sums = &cdf[texel_offset + y * s..texel_offset + (y + 1) * s];
    let x = first_passing(s, |x| {
        if at_total {
            sums[x] >= row_total
        } else {
            sums[x] > target
        }
    });
    let w = texel_weight(&faces[face], y * s + x);
    let before_x = if x > 0 { sums[x - 1] } else { 0.0 };
    let before_y = if lo > 0 { marginal[lo - 1] } else { 0.0 };
    Some(Draw {
        slot: offset as u32 + j,
        face,
        texel: (x as u32, y as u32),
        within: (
            ((target - before_x) / w).clamp(0.0, 1.0),
            ((row_goal - before_y) / row_total).clamp(0.0, 1.0),
        ),
        fade: (share - j as f32).clamp(0.0, 1.0),
        light_samples: n as u32,
    })
}

/// A sample's surface blended from its texel and the neighbours it leans to on its own
/// surface ([`BLEND_NORMAL_COS`], [`BLEND_PLANE`]; GLSL `hvl_flux_blend`): position, unit
/// normal, chroma (flux over weight) and the bilinear flux weight.
fn blend(face: &RsmData, (x, y): (u32, u32), (f, g): (f32, f32)) -> (Vec3, Vec3, Vec3, f32) {
    let s = face.size as i64;
    let dir = (if f < 0.5 { -1 } else { 1 }, if g < 0.5 { -1 } else { 1 });
    let lean = ((f - 0.5).abs(), (g - 0.5).abs());
    let (mut position, mut normal, mut flux) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    let (mut weight, mut total) = (0.0f32, 0.0f32);
    let own = (i64::from(y) * s + i64::from(x)) as usize;
    let (own_position, own_normal) = (
        face.position[own].truncate(),
        face.normal[own].truncate().normalize(),
    );
    for b in 0..2 {
        for a in 0..2 {
            let q = (i64::from(x) + a * dir.0, i64::from(y) + b * dir.1);
            if q.0 < 0 || q.1 < 0 || q.0 >= s || q.1 >= s {
                continue;
            }
            let t = (q.1 * s + q.0) as usize;
            let step = face.position[t].truncate() - own_position;
            let same_surface = face.normal[t].truncate().normalize().dot(own_normal)
                >= BLEND_NORMAL_COS
                && step.dot(own_normal).abs() <= BLEND_PLANE * step.length();
            if face.position[t].w == 0.0 || !same_surface {
                continue;
            }
            let k = if a == 1 { lean.0 } else { 1.0 - lean.0 }
                * if b == 1 { lean.1 } else { 1.0 - lean.1 };
            position += k * face.position[t].truncate();
            normal += k * face.normal[t].truncate().normalize();
            flux += k * face.flux[t].truncate();
            weight += k * texel_weight(face, t);
            total += k;
        }
    }
    (
        position / total,
        normal.normalize(),
        flux / weight,
        weight / total,
    )
}

/// The HVL cache of [`crate::passes::hvl::Distribution::Flux`] built from the RSM faces of
/// every light as `shaders/hvl_flux.comp` does; slots no light keeps are zero.
pub fn build_flux_cache(faces: &[RsmData], params: &HvlParams) -> Result<Vec<Hvl>, HvlError> {
    if faces.is_empty() {
        return Err(HvlError::NoFaces);
    }
    let count = params.count;
    let cdf = running_sums(faces, count);
    let groups = light_faces(faces);
    let table = cdf.len() - 4 * (groups.len() + 1);
    let (total, m) = (cdf[table], cdf[table + 1]);
    let mut emission = [0.0f32; EMISSION_MAX_BANDS];
    emission.copy_from_slice(&sender_emission_zh(EMISSION_MAX_BANDS)?);
    let mut hvls = vec![<Hvl as bytemuck::Zeroable>::zeroed(); count as usize];
    for (k, group) in groups.iter().enumerate() {
        for j in 0..count {
            let Some(d) = draw(faces, &cdf, k, j) else {
                break;
            };
            let face = &faces[d.face];
            let (footprint, ortho) = match face.projection {
                RsmProjection::Perspective { fov } => (RsmFootprint::Perspective { fov }, false),
                RsmProjection::Orthographic { width } => {
                    (RsmFootprint::Orthographic { width }, true)
                }
            };
            let axis = face.light_direction.normalize_or(Vec3::NEG_Y);
            let (p, n, chroma, w) = blend(face, d.texel, d.within);
            let from_light = p - face.light_position;
            let dist = if ortho {
                from_light.dot(axis)
            } else {
                from_light.length()
            };
            let to_surface = if ortho { axis } else { from_light / dist };
            let area = rsm_texel_area(
                footprint,
                face.size,
                dist,
                to_surface.dot(axis),
                n.dot(-to_surface),
            );
            let r = radius_spacing(area, w, total, m as u32) * params.radius_scale;
            let flux = chroma * (total * d.fade / m);
            hvls[d.slot as usize] = Hvl {
                position_radius: p.extend(r).to_array(),
                normal_distance: n.extend(dist).to_array(),
                flux: Vec4::from((flux, 1.0)).to_array(),
                emission,
                light: group.light,
                sample_index: j,
                light_samples: d.light_samples,
            };
        }
    }
    Ok(hvls)
}
