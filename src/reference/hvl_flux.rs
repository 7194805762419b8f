//! CPU twin of `shaders/hvl_flux.comp`: the HVL cache of [`Distribution::Flux`] over the RSM
//! faces of every light, M texels drawn in proportion to their flux by the Hammersley set
//! warped through the faces' running sums. The draws use the shader's f32 sums and products in
//! the same order, so both pick the same texels; fluxes and radii agree to float rounding.
//!
//! [`Distribution::Flux`]: crate::passes::hvl::Distribution::Flux

use glam::{Vec3, Vec4};
use shine_sh::hvl::{RsmFootprint, radius_spacing, rsm_texel_area};

use super::hvl::{RsmData, sender_emission_zh};
use crate::passes::hvl::{EMISSION_MAX_BANDS, Hvl, HvlError, HvlParams};
use crate::passes::rsm::RsmProjection;

/// The flux weight of a texel: `r + g + b` of its flux, 0 when it is empty (GLSL
/// `texel_weight`).
pub fn texel_weight(rsm: &RsmData, texel: usize) -> f32 {
    if rsm.position[texel].w == 0.0 {
        return 0.0;
    }
    let f = rsm.flux[texel];
    (f.x + f.y + f.z).max(0.0)
}

/// The `cdf` buffer of the shader: every face's per-row running sums (face by face), the row
/// totals in global row order, then their running sums.
pub fn running_sums(faces: &[RsmData]) -> Vec<f32> {
    let texels: usize = faces.iter().map(|f| (f.size * f.size) as usize).sum();
    let rows: usize = faces.iter().map(|f| f.size as usize).sum();
    let mut cdf = vec![0.0f32; texels + 2 * rows];
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
    let mut sum = 0.0f32;
    for r in 0..rows {
        sum += cdf[texels + r];
        cdf[texels + rows + r] = sum;
    }
    cdf
}

/// The base-2 radical inverse of `m` to 24 bits, exact in f32: the second Hammersley
/// coordinate of HVL `m`.
pub fn radical_inverse(m: u32) -> f32 {
    (m.reverse_bits() >> 8) as f32 * (1.0 / 16_777_216.0)
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

/// The face and texel `(face, x, y)` HVL `m` of `count` takes, given the faces and their
/// running sums; `None` when the faces hold no flux.
pub fn sample_texel(
    faces: &[RsmData],
    cdf: &[f32],
    m: u32,
    count: u32,
) -> Option<(usize, u32, u32)> {
    let rows: usize = faces.iter().map(|f| f.size as usize).sum();
    let texels = cdf.len() - 2 * rows;
    let marginal = &cdf[texels + rows..];
    let total = marginal[rows - 1];
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let goal = (2 * m + 1) as f32 * total;
    let twice_count = (2 * count) as f32;
    let row = first_passing(rows, |r| marginal[r] * twice_count > goal);
    let (mut face, mut row_offset, mut texel_offset) = (0, 0, 0);
    while row >= row_offset + faces[face].size as usize {
        row_offset += faces[face].size as usize;
        texel_offset += (faces[face].size * faces[face].size) as usize;
        face += 1;
    }
    let s = faces[face].size as usize;
    let y = row - row_offset;
    let row_total = cdf[texels + row];
    let target = radical_inverse(m) * row_total;
    let at_total = target >= row_total;
    let sums = &cdf[texel_offset + y * s..texel_offset + (y + 1) * s];
    let x = first_passing(s, |x| {
        if at_total {
            sums[x] >= row_total
        } else {
            sums[x] > target
        }
    });
    Some((face, x as u32, y as u32))
}

/// The HVL cache of [`crate::passes::hvl::Distribution::Flux`] built from the RSM faces of
/// every light as `shaders/hvl_flux.comp` does.
pub fn build_flux_cache(faces: &[RsmData], params: &HvlParams) -> Result<Vec<Hvl>, HvlError> {
    if faces.is_empty() {
        return Err(HvlError::NoFaces);
    }
    let cdf = running_sums(faces);
    let total = cdf[cdf.len() - 1];
    let mut emission = [0.0f32; 8];
    emission[..EMISSION_MAX_BANDS].copy_from_slice(&sender_emission_zh(EMISSION_MAX_BANDS)?);
    let count = params.count;
    // Per face: its footprint, whether it is orthographic, its unit axis.
    let geometry: Vec<(RsmFootprint, bool, Vec3)> = faces
        .iter()
        .map(|face| match face.projection {
            RsmProjection::Perspective { fov } => (RsmFootprint::Perspective { fov }, false),
            RsmProjection::Orthographic { width } => (RsmFootprint::Orthographic { width }, true),
        })
        .zip(faces)
        .map(|((footprint, ortho), face)| {
            let axis = face.light_direction.normalize_or(Vec3::NEG_Y);
            (footprint, ortho, axis)
        })
        .collect();
    let hvls = (0..count)
        .map(|m| match sample_texel(faces, &cdf, m, count) {
            None => Hvl {
                position_radius: [0.0; 4],
                normal_distance: [0.0; 4],
                flux: [0.0; 4],
                emission: [0.0; 8],
            },
            Some((f, x, y)) => {
                let face = &faces[f];
                let s = face.size;
                let (footprint, ortho, axis) = geometry[f];
                let t = (y * s + x) as usize;
                let w = texel_weight(face, t);
                let p = face.position[t].truncate();
                let n = face.normal[t].truncate().normalize();
                let from_light = p - face.light_position;
                let d = if ortho {
                    from_light.dot(axis)
                } else {
                    from_light.length()
                };
                let to_surface = if ortho { axis } else { from_light / d };
                let area =
                    rsm_texel_area(footprint, s, d, to_surface.dot(axis), n.dot(-to_surface));
                let r = radius_spacing(area, w, total, count) * params.radius_scale;
                let flux = face.flux[t].truncate() * (total / (count as f32 * w));
                Hvl {
                    position_radius: p.extend(r).to_array(),
                    normal_distance: n.extend(d).to_array(),
                    flux: Vec4::from((flux, 1.0)).to_array(),
                    emission,
                }
            }
        })
        .collect();
    Ok(hvls)
}
