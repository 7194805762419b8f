//! CPU twin of `shaders/hvl_flux.comp`: the HVL cache of [`Distribution::Flux`], M RSM texels
//! drawn in proportion to their flux by the Hammersley set warped through the flux's running
//! sums. The draws use the shader's f32 sums and products in the same order, so both pick the
//! same texels; fluxes and radii agree to float rounding.
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

/// The running sums of the `rows` stage: `S²` per-row running sums, then the `S` row totals.
pub fn running_sums(rsm: &RsmData) -> Vec<f32> {
    let s = rsm.size as usize;
    let mut cdf = vec![0.0f32; s * s + s];
    for y in 0..s {
        let mut sum = 0.0f32;
        for x in 0..s {
            sum += texel_weight(rsm, y * s + x);
            cdf[y * s + x] = sum;
        }
        cdf[s * s + y] = sum;
    }
    cdf
}

/// The base-2 radical inverse of `m` to 24 bits, exact in f32: the second Hammersley
/// coordinate of HVL `m`.
pub fn radical_inverse(m: u32) -> f32 {
    (m.reverse_bits() >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The texel `(x, y)` HVL `m` of `count` takes, given the running sums; `None` when the RSM
/// holds no flux.
pub fn sample_texel(cdf: &[f32], size: u32, m: u32, count: u32) -> Option<(u32, u32)> {
    let s = size as usize;
    let rows = &cdf[s * s..];
    let total = rows.iter().fold(0.0f32, |a, &b| a + b);
    if total.is_nan() || total <= 0.0 {
        return None;
    }
    let goal = (2 * m + 1) as f32 * total;
    let twice_count = (2 * count) as f32;
    let mut running = 0.0f32;
    let mut y = s - 1;
    for (j, &row) in rows.iter().enumerate() {
        running += row;
        if running * twice_count > goal {
            y = j;
            break;
        }
    }
    let row_total = rows[y];
    let target = radical_inverse(m) * row_total;
    let at_total = target >= row_total;
    let row = &cdf[y * s..(y + 1) * s];
    let (mut lo, mut hi) = (0usize, s - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        let c = row[mid];
        let passed = if at_total { c >= row_total } else { c > target };
        if passed {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    Some((lo as u32, y as u32))
}

/// The HVL cache of [`crate::passes::hvl::Distribution::Flux`] built from `rsm` as
/// `shaders/hvl_flux.comp` does.
pub fn build_flux_cache(rsm: &RsmData, params: &HvlParams) -> Result<Vec<Hvl>, HvlError> {
    let s = rsm.size;
    let cdf = running_sums(rsm);
    let total = cdf[(s * s) as usize..].iter().fold(0.0f32, |a, &b| a + b);
    let footprint = match rsm.projection {
        RsmProjection::Perspective { fov } => RsmFootprint::Perspective { fov },
        RsmProjection::Orthographic { width } => RsmFootprint::Orthographic { width },
    };
    let ortho = matches!(rsm.projection, RsmProjection::Orthographic { .. });
    let axis = rsm.light_direction.normalize_or(Vec3::NEG_Y);
    let mut emission = [0.0f32; 8];
    emission[..EMISSION_MAX_BANDS].copy_from_slice(&sender_emission_zh(EMISSION_MAX_BANDS)?);
    let count = params.count;
    let hvls = (0..count)
        .map(|m| match sample_texel(&cdf, s, m, count) {
            None => Hvl {
                position_radius: [0.0; 4],
                normal_distance: [0.0; 4],
                flux: [0.0; 4],
                emission: [0.0; 8],
            },
            Some((x, y)) => {
                let t = (y * s + x) as usize;
                let w = texel_weight(rsm, t);
                let p = rsm.position[t].truncate();
                let n = rsm.normal[t].truncate().normalize();
                let from_light = p - rsm.light_position;
                let d = if ortho {
                    from_light.dot(axis)
                } else {
                    from_light.length()
                };
                let to_surface = if ortho { axis } else { from_light / d };
                let area =
                    rsm_texel_area(footprint, s, d, to_surface.dot(axis), n.dot(-to_surface));
                let r = radius_spacing(area, w, total, count) * params.radius_scale;
                let flux = rsm.flux[t].truncate() * (total / (count as f32 * w));
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
