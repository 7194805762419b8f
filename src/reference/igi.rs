//! CPU twin of the IGI passes (paper 000, [`crate::passes::igi`]): the same formulas as
//! `shaders/include/igi.glsl`, `shaders/vpl_sh.comp` and `shaders/sh_filter.comp`, with the SH
//! math of shine-sh (basis, Lambert and Phong `r_l`, ZH rotation), and the brute-force VPL
//! shading that IGI with one set and no filter must reproduce. Used by `tests/igi.rs`.

use glam::{Mat3, Vec3, Vec4};
use shine_sh::rotation::ShRotation;
use shine_sh::{ShError, basis, kernels, zonal};

use super::hvl_flux::sample_set;
use crate::passes::brdf_tables::{GatherBrdf, indirect_weights, table_fresnel_weight};
use crate::passes::hvl::Hvl;
use crate::passes::igi::{FilterMode, GeometryTest, Glossy, IgiParams, pixel_set};
use crate::passes::specular::trace_weight;

/// `IGI_MIN_DISTANCE` of igi.glsl (metres).
pub const MIN_DISTANCE: f32 = 1e-4;
/// `IGI_PHONG_MAX` of igi.glsl.
pub const PHONG_MAX: f32 = 1e4;
/// `IGI_SHADOW_END` of vpl_sh.comp: a shadow ray stops this fraction short of its VPL.
pub const SHADOW_END: f32 = 0.999;

/// The full-resolution G-buffer as the IGI passes read it (row-major texels).
#[derive(Debug, Clone, PartialEq)]
pub struct GBufferData {
    /// Width and height.
    pub extent: [u32; 2],
    /// xyz world position, w linear depth (0: background).
    pub position: Vec<Vec4>,
    /// xyz shading normal.
    pub normal: Vec<Vec4>,
    /// xyz geometric normal.
    pub geometric_normal: Vec<Vec4>,
    /// rgb albedo.
    pub albedo: Vec<Vec4>,
    /// r roughness, g metallic.
    pub material: Vec<Vec4>,
}

/// `igi_vpl_irradiance`: E_j = Φ max(0, n_j·−ω) / (π max(d, d_min, ρ)²), ρ the VPL's
/// footprint (0: paper 000's clamp alone).
pub fn vpl_irradiance(
    flux: Vec3,
    vpl_normal: Vec3,
    w: Vec3,
    dist: f32,
    clamp: f32,
    footprint: f32,
) -> Vec3 {
    let cos_sender = (-vpl_normal.dot(w)).max(0.0);
    let d = dist.max(clamp).max(footprint).max(MIN_DISTANCE);
    flux * (cos_sender / (std::f32::consts::PI * d * d))
}

/// `igi_phong_exponent`: 0.5/α² − 0.5 with α = max(roughness², 1e-3), clamped to 1..=1e4.
pub fn phong_exponent(roughness: f32) -> f32 {
    let a = crate::passes::brdf_tables::alpha(roughness);
    (0.5 / (a * a) - 0.5).clamp(1.0, PHONG_MAX)
}

/// `igi_brdf_lambert` and `igi_brdf_phong` with k_d = k_s = 1: paper 000 §3.3
/// `B_lm = sqrt(4π/(2l+1)) r_l Y_lm(w_c)` from shine-sh's [`kernels::lambert_r`] about `n` and
/// [`kernels::phong_r`] about `r`.
pub fn brdf_sh(n: Vec3, r: Vec3, exponent: f32, bands: usize) -> Result<[Vec<f32>; 2], ShError> {
    let lambert = zonal::rotate_zh(&kernels::lambert_r(1.0, bands)?, n)?;
    let phong = zonal::rotate_zh(&kernels::phong_r(1.0, exponent, bands)?, r)?;
    Ok([lambert, phong])
}

/// The GGX path of `sh_filter` for one pixel: `sh` (world-frame rgb SH, already filtered)
/// rotated into the receiver frame of the BRDF SH tables (z = `n`, `wo` in the xz half-plane)
/// with shine-sh's rotation, dotted with the Lambert and the roughness-blended GGX rows, weighted
/// by [`indirect_weights`] (the glossy one through [`table_fresnel_weight`] and times
/// `glossy_share`, the part the frame's specular pass leaves); `material` is the albedo,
/// roughness and metallic.
pub fn ggx_resolve(
    sh: &[Vec3],
    n: Vec3,
    wo: Vec3,
    material: (Vec3, f32, f32),
    glossy_share: f32,
    tables: &GatherBrdf,
) -> Result<Vec3, ShError> {
    let (albedo, roughness, metallic) = material;
    let bands = basis_bands(sh.len());
    let (kd, ks) = indirect_weights(albedo, metallic, n.dot(wo));
    let ks = table_fresnel_weight(ks, n.dot(wo)) * glossy_share;
    let cos_o = n.dot(wo).clamp(1e-4, 1.0);
    let mut t = wo - n * n.dot(wo);
    if t.length_squared() < 1e-12 {
        t = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
        t -= n * n.dot(t);
    }
    let t = t.normalize();
    let b = n.cross(t);
    let rotation = ShRotation::from_mat3(Mat3::from_cols(t, b, n).transpose(), bands)?;
    let theta_o = cos_o.acos();
    let lambert = tables.lambert.lookup_f(theta_o);
    let glossy = tables.glossy_f(roughness, theta_o);
    let mut out = Vec3::ZERO;
    for c in 0..3 {
        let world: Vec<f32> = sh.iter().map(|v| v[c]).collect();
        let local = rotation.apply(&world)?;
        out[c] = kd[c] * shine_sh::dot(&local, &lambert)? + ks[c] * shine_sh::dot(&local, &glossy)?;
    }
    Ok(out)
}

/// Bands of an SH vector of `len` coefficients.
fn basis_bands(len: usize) -> usize {
    (len as f64).sqrt().round() as usize
}

/// `trace_offset` of trace.glsl.
pub fn trace_offset(p: Vec3, n: Vec3) -> Vec3 {
    let scale = 1.0 + p.abs().max_element();
    p + n * (1e-4 * scale)
}

/// One VPL's contribution at a receiver: `(ω, E_j)` before visibility, or `None` when it is
/// invalid, at the receiver, or below the geometric surface. `scale` is n·m (the filter counts
/// every set equally).
fn contribution(
    vpl: &Hvl,
    x: Vec3,
    ng: Vec3,
    params: &IgiParams,
    scale: f32,
) -> Option<(Vec3, Vec3)> {
    let footprint = params.footprint * vpl.position_radius[3];
    if vpl.flux[3] == 0.0 {
        return None;
    }
    let v = Vec4::from(vpl.position_radius).truncate() - x;
    let dist = v.length();
    if dist <= 0.0 {
        return None;
    }
    let w = v / dist;
    if w.dot(ng) <= 0.0 {
        return None;
    }
    let normal = Vec4::from(vpl.normal_distance).truncate();
    let flux = Vec4::from(vpl.flux).truncate();
    let far = shine_sh::hvl::far_weight(dist, params.near_radius);
    let e = vpl_irradiance(flux, normal, w, dist, params.clamp_distance, footprint) * (scale * far);
    (e != Vec3::ZERO).then_some((w, e))
}

/// `vpl_sh`: per pixel, `params.coefficients()` rgb values (SH projections of the incident
/// radiance, or irradiance and glossy radiance), from the VPLs of the pixel's set.
/// `occluded(origin, dir, t_max)` is the shadow ray.
pub fn vpl_sh(
    g: &GBufferData,
    vpls: &[Hvl],
    camera: Vec3,
    params: &IgiParams,
    occluded: impl Fn(Vec3, Vec3, f32) -> bool,
) -> Result<Vec<Vec<Vec3>>, ShError> {
    let count = params.vpl_count;
    let sets = params.n * params.m;
    let bands = params.sh_order as usize;
    let coefficients = params.coefficients() as usize;
    let [w, _] = g.extent;
    let mut out = Vec::with_capacity(g.position.len());
    for (p, position) in g.position.iter().enumerate() {
        let mut acc = vec![Vec3::ZERO; coefficients];
        if position.w != 0.0 {
            let x = position.truncate();
            let ng = g.geometric_normal[p].truncate().normalize();
            let origin = trace_offset(x, ng);
            let n = g.normal[p].truncate().normalize();
            let wo = (camera - x).normalize();
            let r = (-wo).reflect(n);
            let exponent = phong_exponent(g.material[p].x);
            let lobe_norm = (exponent + 1.0) / std::f32::consts::TAU;
            let s = pixel_set(p as u32 % w, p as u32 / w, params.pattern());
            // n m times each set's sum: the filter counts every set equally.
            let scale = sets as f32;
            for vpl in vpls
                .iter()
                .take(count as usize)
                .filter(|v| sample_set(v.sample_index, sets) == s)
            {
                let Some((dir, e)) = contribution(vpl, x, ng, params, scale) else {
                    continue;
                };
                let target = Vec4::from(vpl.position_radius).truncate();
                if occluded(origin, dir, (target - origin).length() * SHADOW_END) {
                    continue;
                }
                match params.mode {
                    FilterMode::Irradiance => {
                        acc[0] += e * n.dot(dir).max(0.0);
                        acc[1] += e * (lobe_norm * r.dot(dir).max(0.0).powf(exponent));
                    }
                    FilterMode::Sh => {
                        let y = basis::eval_basis(dir, bands)?;
                        for (a, yk) in acc.iter_mut().zip(y) {
                            *a += e * yk;
                        }
                    }
                }
            }
        }
        out.push(acc);
    }
    Ok(out)
}

/// `sh_filter`: the discontinuity filter over `coefficients` (from [`vpl_sh`]) and the BRDF;
/// returns the outgoing radiance per pixel (clamped at 0), 0 on background. `tables`: the BRDF
/// SH tables at `sh_order` bands, needed by the GGX path only.
pub fn sh_filter(
    g: &GBufferData,
    coefficients: &[Vec<Vec3>],
    tables: Option<&GatherBrdf>,
    camera: Vec3,
    params: &IgiParams,
) -> Result<Vec<Vec3>, ShError> {
    let [w, h] = g.extent;
    let bands = params.sh_order as usize;
    let size = if params.filter_radius == 0 {
        [1, 1]
    } else {
        params.pattern().map(|k| k * params.filter_radius)
    };
    let lo = size.map(|s| -((s / 2) as i64));
    let mut out = Vec::with_capacity(g.position.len());
    for (p, position) in g.position.iter().enumerate() {
        if position.w == 0.0 {
            out.push(Vec3::ZERO);
            continue;
        }
        let (px, py) = (i64::from(p as u32 % w), i64::from(p as u32 / w));
        let z = position.w;
        let ng = g.geometric_normal[p].truncate().normalize();
        let mut sum = vec![Vec3::ZERO; coefficients[p].len()];
        let mut count = 0.0f32;
        for dy in lo[1]..lo[1] + i64::from(size[1]) {
            for dx in lo[0]..lo[0] + i64::from(size[0]) {
                let (qx, qy) = (px + dx, py + dy);
                if qx < 0 || qy < 0 || qx >= i64::from(w) || qy >= i64::from(h) {
                    continue;
                }
                let q = (qy * i64::from(w) + qx) as usize;
                if dx != 0 || dy != 0 {
                    let pq = g.position[q];
                    let offset = match params.geometry_test {
                        GeometryTest::Plane => ng.dot(pq.truncate() - position.truncate()),
                        GeometryTest::Depth => pq.w - z,
                    };
                    if pq.w == 0.0 || offset.abs() > params.depth_tolerance * z {
                        continue;
                    }
                    let nq = g.geometric_normal[q].truncate().normalize();
                    if ng.dot(nq) < params.normal_threshold {
                        continue;
                    }
                }
                for (s, c) in sum.iter_mut().zip(&coefficients[q]) {
                    *s += *c;
                }
                count += 1.0;
            }
        }
        let x = position.truncate();
        let n = g.normal[p].truncate().normalize();
        let albedo = g.albedo[p].truncate();
        let (roughness, metallic) = (g.material[p].x, g.material[p].y);
        let wo = (camera - x).normalize();
        // the glossy share the frame's specular pass leaves to the filter
        let glossy_share = 1.0 - trace_weight(roughness, params.specular_limit);
        let (kd, ks) = indirect_weights(albedo, metallic, n.dot(wo));
        let ks = ks * glossy_share;
        let result = match params.mode {
            FilterMode::Irradiance => {
                kd / std::f32::consts::PI * (sum[0] / count) + ks * (sum[1] / count)
            }
            FilterMode::Sh if params.glossy == Glossy::Ggx => {
                let tables = tables.ok_or(ShError::OutOfRange {
                    name: "BRDF tables",
                    value: 0.0,
                    expected: "GatherBrdf tables for the GGX path",
                })?;
                let filtered: Vec<Vec3> = sum.iter().map(|s| *s / count).collect();
                ggx_resolve(
                    &filtered,
                    n,
                    wo,
                    (albedo, roughness, metallic),
                    glossy_share,
                    tables,
                )?
            }
            FilterMode::Sh => {
                let [lambert, phong] =
                    brdf_sh(n, (-wo).reflect(n), phong_exponent(roughness), bands)?;
                let mut diffuse = Vec3::ZERO;
                let mut glossy = Vec3::ZERO;
                for ((s, bl), bp) in sum.iter().zip(&lambert).zip(&phong) {
                    diffuse += *s / count * *bl;
                    glossy += *s / count * *bp;
                }
                kd * diffuse + ks * glossy
            }
        };
        out.push(result.max(Vec3::ZERO));
    }
    Ok(out)
}

/// Brute-force VPL shading: every valid VPL (all sets, no interleaving, no filter), shadowed,
/// through the exact BRDF of the irradiance mode: `Σ_j V_j E_j (kd/π max(0, n·ω_j) + ks
/// phong(r·ω_j))`, ks times the glossy share the specular pass leaves (`params.specular_limit`).
pub fn brute_force(
    g: &GBufferData,
    vpls: &[Hvl],
    camera: Vec3,
    params: &IgiParams,
    occluded: impl Fn(Vec3, Vec3, f32) -> bool,
) -> Vec<Vec3> {
    g.position
        .iter()
        .enumerate()
        .map(|(p, position)| {
            if position.w == 0.0 {
                return Vec3::ZERO;
            }
            let x = position.truncate();
            let ng = g.geometric_normal[p].truncate().normalize();
            let origin = trace_offset(x, ng);
            let n = g.normal[p].truncate().normalize();
            let wo = (camera - x).normalize();
            let r = (-wo).reflect(n);
            let exponent = phong_exponent(g.material[p].x);
            let (kd, ks) = indirect_weights(g.albedo[p].truncate(), g.material[p].y, n.dot(wo));
            let ks = ks * (1.0 - trace_weight(g.material[p].x, params.specular_limit));
            let mut sum = Vec3::ZERO;
            for vpl in &vpls[..params.vpl_count as usize] {
                let Some((dir, e)) = contribution(vpl, x, ng, params, 1.0) else {
                    continue;
                };
                let target = Vec4::from(vpl.position_radius).truncate();
                if occluded(origin, dir, (target - origin).length() * SHADOW_END) {
                    continue;
                }
                let glossy =
                    (exponent + 1.0) / std::f32::consts::TAU * r.dot(dir).max(0.0).powf(exponent);
                sum += e * (kd / std::f32::consts::PI * n.dot(dir).max(0.0) + ks * glossy);
            }
            sum.max(Vec3::ZERO)
        })
        .collect()
}
