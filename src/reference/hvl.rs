//! CPU reference of the HVL passes (paper 003): the cache construction and the gather exactly
//! as `shaders/hvl_cache.comp` and `shaders/hvl_gather.comp` compute them (f32, same order of
//! operations where it matters), plus a numerical integration of eq. 3 with eq. 19–21 for one
//! HVL, the ground truth the SH gather approximates. Used by `tests/hvl.rs`.
//!
//! New formulas of the HVL passes with a GLSL twin in `shaders/include/hvl.glsl`:
//! [`zh_eval`] (a rotated ZH vector evaluated at a direction) and [`zh_dot`] (dot product of two
//! rotated ZH vectors, the O(n) zonal path). Everything else calls shine-sh.

use bytemuck::Zeroable;
use glam::{DVec3, Vec3, Vec4};
use shine_sh::brdf_table::BrdfModel;
use shine_sh::hvl::{
    HvlNeighbour, cap_half_angle, disc_falloff, geometric_factor, geometric_factor_of, radius_r1,
    radius_r2, radius_r2_orthographic,
};
use shine_sh::kernels::clamped_cosine_zh;
use shine_sh::legendre::{legendre_all, legendre_monomials};
use shine_sh::quadrature::SphereQuadrature;
use shine_sh::zonal::{cap_sh, cap_zh};

use crate::passes::brdf_tables::{GatherBrdf, indirect_weights, table_fresnel_weight};
use crate::passes::hvl::{
    Distribution, EMISSION_MAX_BANDS, Falloff, GatherHvl, GatherPath, Hvl, HvlError, HvlParams,
    RadiusHeuristic,
};
use crate::passes::rsm::RsmProjection;

/// ε of the r1 weights `w_n = 1 / (|d - d_n| + ε)`, metres (eq. 23, paper 003); the GLSL
/// constant `HVL_R1_EPSILON` has the same value.
pub const R1_EPSILON: f32 = 1e-3;

/// Receivers closer than this to an HVL centre get nothing from it (metres), as the GLSL
/// constant `HVL_MIN_DISTANCE`.
pub const MIN_DISTANCE: f32 = 1e-6;

/// The shadow ray of the `_vis` gather aims at the HVL centre lifted along its normal by this
/// fraction of its radius plus 0.1 mm (GLSL `HVL_VISIBILITY_LIFT`).
pub const VISIBILITY_LIFT: f32 = 0.01;

/// Whether the segment from a receiver (`origin`, already offset off its surface) to an HVL's
/// lifted centre (`target`) is unoccluded: the shadow ray of [`HvlParams::visibility`].
pub type Visibility<'a> = &'a dyn Fn(Vec3, Vec3) -> bool;

/// The shadow ray's end points for receiver `x` (normal `n`) and `hvl`, as `hvl_gather.comp`
/// computes them (`trace_offset` of `shaders/include/trace.glsl`, then the lifted centre).
pub fn visibility_ray(x: Vec3, n: Vec3, hvl: &Hvl) -> (Vec3, Vec3) {
    let scale = 1.0 + x.abs().max_element();
    let origin = x + n * (1e-4 * scale);
    let r = hvl.position_radius[3];
    let hvl_n = Vec4::from(hvl.normal_distance).truncate().normalize();
    let target = Vec4::from(hvl.position_radius).truncate() + hvl_n * (VISIBILITY_LIFT * r + 1e-4);
    (origin, target)
}

/// An RSM on the CPU: `size²` texels, row-major, in the units of docs/frame.md.
#[derive(Debug, Clone, PartialEq)]
pub struct RsmData {
    /// Side S.
    pub size: u32,
    /// The index in the scene of the light this face belongs to (a point light's six faces
    /// share one, consecutive in a face list): the flux distribution's sample identity.
    pub light: u32,
    /// `rsm_position` texels (w = 1 valid, 0 empty).
    pub position: Vec<Vec4>,
    /// `rsm_normal` texels.
    pub normal: Vec<Vec4>,
    /// `rsm_flux` texels.
    pub flux: Vec<Vec4>,
    /// Primary light position (perspective) or the RSM's eye (orthographic).
    pub light_position: Vec3,
    /// Unit axis of the RSM's view.
    pub light_direction: Vec3,
    /// How the RSM was projected.
    pub projection: RsmProjection,
}

/// The receiver buffer on the CPU: row-major texels, unorm channels already as floats.
#[derive(Debug, Clone, PartialEq)]
pub struct ReceiverData {
    /// Width and height.
    pub extent: [u32; 2],
    /// `recv_position` (w = 0: background).
    pub position: Vec<Vec4>,
    /// `recv_normal`.
    pub normal: Vec<Vec4>,
    /// `recv_albedo`.
    pub albedo: Vec<Vec4>,
    /// `recv_material` (r = roughness, g = metallic).
    pub material: Vec<Vec4>,
}

/// One receiver: what the gather reads at a pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Receiver {
    /// World position x.
    pub position: Vec3,
    /// Unit normal `n_x`.
    pub normal: Vec3,
    /// Linear albedo.
    pub albedo: Vec3,
    /// Metallic in [0, 1].
    pub metallic: f32,
    /// Perceptual roughness in [0, 1] (selects the glossy tables).
    pub roughness: f32,
}

impl Receiver {
    /// `(kd, ks)` seen from `camera`: [`indirect_weights`] at n·v, the glossy weight through
    /// [`table_fresnel_weight`] (the gather's GGX tables hold the dielectric Fresnel).
    pub fn weights(&self, camera: Vec3) -> (Vec3, Vec3) {
        let n_dot_v = self
            .normal
            .normalize()
            .dot((camera - self.position).normalize());
        let (kd, ks) = indirect_weights(self.albedo, self.metallic, n_dot_v);
        (kd, table_fresnel_weight(ks, n_dot_v))
    }
}

/// ZH coefficients (about the HVL normal) of the Lambert sender's `F'` (eq. 20): the BRDF
/// without its cosine, `1/π` in every direction (the albedo is in the flux, the cosine and the
/// back hemisphere are in `G`, eq. 21), so band 0 only, `√(4π)/π`, as the paper says of
/// isotropic HVLs ("only use band 0 coefficient"); `bands` ≤ 5 coefficients, the rest 0.
///
/// shine first projected the hemisphere-cap indicator over `π` instead (zero behind the
/// sender): that emits `1/(2π)` with one band and, with three, a lobe of `1.25/π` along the
/// normal and `0.5/π` at grazing angles, while `G` already applies the cosine.
pub fn sender_emission_zh(bands: usize) -> Result<Vec<f32>, HvlError> {
    if !(1..=EMISSION_MAX_BANDS).contains(&bands) {
        return Err(HvlError::OutOfRange {
            name: "emission bands",
            value: bands as f64,
            expected: format!("1..={EMISSION_MAX_BANDS}"),
        });
    }
    let mut zh = vec![0.0; bands];
    zh[0] = (4.0 * std::f32::consts::PI).sqrt() / std::f32::consts::PI;
    Ok(zh)
}

/// `Σ_l zh_l √((2l+1)/4π) P_l(cos_angle)`: the ZH vector `zh` about axis `a`, rotated to `a`
/// (eq. 15) and evaluated at a direction `b` with `a·b = cos_angle` (GLSL: as a polynomial, `hvl_zh_poly`).
pub fn zh_eval(zh: &[f32], cos_angle: f32) -> f32 {
    let mut p = vec![0.0f64; zh.len() + 1];
    legendre_all(f64::from(cos_angle.clamp(-1.0, 1.0)), &mut p);
    zh.iter()
        .enumerate()
        .map(|(l, &z)| {
            f64::from(z) * ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI)).sqrt() * p[l]
        })
        .sum::<f64>() as f32
}

/// [`zh_eval`] of the first `bands` bands of `zh` as a polynomial in `cos_angle`: `a[k]` is
/// the coefficient of `cos_angle^k` (GLSL `hvl_zh_poly`: `hvl_gather_prep.comp` writes it once
/// per HVL, so the gather evaluates a sender's emission with four multiply-adds).
pub fn zh_poly(zh: &[f32], bands: usize) -> [f32; EMISSION_MAX_BANDS] {
    let rows = legendre_monomials(EMISSION_MAX_BANDS);
    let mut a = [0.0f64; EMISSION_MAX_BANDS];
    for (l, (&z, row)) in zh.iter().zip(&rows).take(bands).enumerate() {
        let w = f64::from(z) * ((2 * l + 1) as f64 / (4.0 * std::f64::consts::PI)).sqrt();
        for (ak, c) in a.iter_mut().zip(row) {
            *ak += w * c;
        }
    }
    a.map(|v| v as f32)
}

/// The gather's records of the first `count` HVLs (`hvl_gather_prep.comp`): unit normal,
/// `1 / (π r²)` and the emission polynomial of `emission_bands` bands, and its identity; an
/// empty cell (radius ≤ 0) gives a zero record but for its flux and identity.
pub fn gather_records(hvls: &[Hvl], count: usize, emission_bands: usize) -> Vec<GatherHvl> {
    hvls.iter()
        .take(count)
        .map(|h| {
            let r = h.position_radius[3];
            let a = zh_poly(&h.emission, emission_bands);
            let valid = r > 0.0;
            let normal = Vec4::from(h.normal_distance).truncate().normalize_or_zero();
            GatherHvl {
                position_radius: if valid { h.position_radius } else { [0.0; 4] },
                normal_area: if valid {
                    normal.extend(geometric_factor_of(1.0, 1.0, r)).to_array()
                } else {
                    [0.0; 4]
                },
                flux_e0: [h.flux[0], h.flux[1], h.flux[2], a[0]],
                emission: [a[1], a[2], a[3], a[4]],
                identity: [
                    h.light as f32,
                    h.sample_index as f32,
                    h.light_samples as f32,
                    0.0,
                ],
            }
        })
        .collect()
}

/// `Σ_k a[k] x^k` by Horner's rule (GLSL `hvl_poly_eval`).
pub fn poly_eval(a: &[f32], x: f32) -> f32 {
    a.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

/// `Σ_l f_l g_l P_l(cos_angle)`: the SH dot product of two ZH vectors rotated (eq. 15) to axes
/// at `cos_angle` from each other (GLSL `hvl_zh_dot`; the O(n) path of paper 003 §6.3).
pub fn zh_dot(f: &[f32], g: &[f32], cos_angle: f32) -> f32 {
    let mut p = vec![0.0f64; f.len() + 1];
    legendre_all(f64::from(cos_angle.clamp(-1.0, 1.0)), &mut p);
    f.iter()
        .zip(g)
        .enumerate()
        .map(|(l, (&a, &b))| f64::from(a) * f64::from(b) * p[l])
        .sum::<f64>() as f32
}

/// The HVL cache built from `rsm` as `hvl_cache` does (see [`crate::passes::hvl`]), on the
/// grid or by flux ([`super::hvl_flux`]).
pub fn build_cache(rsm: &RsmData, params: &HvlParams) -> Result<Vec<Hvl>, HvlError> {
    let grid = params.validate_cache(rsm.size)?;
    let s = rsm.size;
    let texels = (s * s) as usize;
    if rsm.position.len() != texels || rsm.normal.len() != texels || rsm.flux.len() != texels {
        return Err(HvlError::Size {
            name: "RsmData",
            actual: format!("{} texels", rsm.position.len()),
            expected: format!("{texels} texels in each image"),
        });
    }
    if params.distribution == Distribution::Flux {
        return super::hvl_flux::build_flux_cache(std::slice::from_ref(rsm), params);
    }
    let count = params.count;
    let r2 = |d: f32| match rsm.projection {
        RsmProjection::Perspective { fov } => radius_r2(d, fov, count),
        RsmProjection::Orthographic { width } => radius_r2_orthographic(width, count),
    };
    let direction = rsm.light_direction.normalize_or(Vec3::NEG_Y);
    let light_distance = |p: Vec3| match rsm.projection {
        RsmProjection::Perspective { .. } => p.distance(rsm.light_position),
        RsmProjection::Orthographic { .. } => (p - rsm.light_position).dot(direction),
    };
    let mut emission = [0.0f32; EMISSION_MAX_BANDS];
    emission.copy_from_slice(&sender_emission_zh(EMISSION_MAX_BANDS)?);
    let mut hvls = Vec::with_capacity(count as usize);
    for m in 0..count {
        let (lo, hi) = grid.cell(m);
        let centre = [0.5 * (lo[0] + hi[0]) as f32, 0.5 * (lo[1] + hi[1]) as f32];
        let mut best = f32::MAX;
        let mut rep = None;
        let mut flux = Vec3::ZERO;
        for y in lo[1]..hi[1] {
            for x in lo[0]..hi[0] {
                let t = (y * s + x) as usize;
                if rsm.position[t].w == 0.0 {
                    continue;
                }
                flux += rsm.flux[t].truncate();
                let off = [x as f32 + 0.5 - centre[0], y as f32 + 0.5 - centre[1]];
                let d2 = off[0] * off[0] + off[1] * off[1];
                if d2 < best {
                    best = d2;
                    rep = Some(t);
                }
            }
        }
        let hvl = match rep {
            None => Hvl {
                sample_index: m,
                light_samples: count,
                ..Hvl::zeroed()
            },
            Some(t) => {
                let p = rsm.position[t].truncate();
                let n = rsm.normal[t].truncate().normalize();
                let d = light_distance(p);
                let r = match params.radius {
                    RadiusHeuristic::R2 => r2(d)? * params.radius_scale,
                    RadiusHeuristic::R1 => 0.0,
                };
                Hvl {
                    position_radius: p.extend(r).to_array(),
                    normal_distance: n.extend(d).to_array(),
                    flux: flux.extend(1.0).to_array(),
                    emission,
                    light: 0,
                    sample_index: m,
                    light_samples: count,
                }
            }
        };
        hvls.push(hvl);
    }
    if params.radius == RadiusHeuristic::R1 {
        let source = hvls.clone();
        for (m, h) in hvls.iter_mut().enumerate() {
            if !h.is_valid() {
                continue;
            }
            let neighbours: Vec<HvlNeighbour> = grid
                .neighbours(m as u32)
                .into_iter()
                .map(|q| &source[q as usize])
                .filter(|n| n.is_valid())
                .map(|n| HvlNeighbour {
                    position: Vec4::from(n.position_radius).truncate(),
                    light_distance: n.normal_distance[3],
                })
                .collect();
            let p = Vec4::from(h.position_radius).truncate();
            let d = h.normal_distance[3];
            let r = match radius_r1(p, d, &neighbours, R1_EPSILON) {
                Ok(r) if r > 0.0 => r,
                _ => r2(d)?,
            };
            h.position_radius[3] = r * params.radius_scale;
        }
    }
    Ok(hvls)
}

/// The receiver frame of the BRDF tables: tangent `t` with `ω_o` in the xz half-plane
/// (φ_o = 0, eq. 17), bitangent `n × t`, and θ_o; `None` when the camera is below the surface.
pub fn receiver_frame(normal: Vec3, wo: Vec3) -> Option<(Vec3, Vec3, f32)> {
    let cos_o = normal.dot(wo);
    if cos_o <= 0.0 {
        return None;
    }
    let mut t = wo - normal * cos_o;
    if t.dot(t) < 1e-12 {
        t = if normal.x.abs() < 0.9 {
            Vec3::X
        } else {
            Vec3::Y
        };
        t -= normal * normal.dot(t);
    }
    let t = t.normalize();
    Some((t, normal.cross(t), cos_o.min(1.0).acos()))
}

/// How the reference evaluates the HVL's emission `F'·Y(-ω_j)` of eq. 20.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Emission {
    /// The exact Lambert sender: `1/π` (the HVL's albedo is in its flux).
    Exact,
    /// The stored ZH, reconstructed to this many bands and clamped at 0, as the GPU does.
    Sh(usize),
}

/// What one HVL sends to a receiver: the incoming radiance `L_j(x, ω_j)` (eq. 20–22, times the
/// disc's near-field factor with [`Falloff::Disc`]), the unit direction `ω_j` and the
/// half-angle `a`; `None` when it sends nothing.
pub fn hvl_incoming(
    hvl: &Hvl,
    x: Vec3,
    n: Vec3,
    emission: Emission,
    falloff: Falloff,
) -> Option<(Vec3, Vec3, f32)> {
    let r = hvl.position_radius[3];
    if r.is_nan() || r <= 0.0 {
        return None;
    }
    let v = Vec4::from(hvl.position_radius).truncate() - x;
    let dist = v.length();
    if dist < MIN_DISTANCE {
        return None;
    }
    let wj = v / dist;
    let a = cap_half_angle(dist, r).ok()?;
    let hvl_n = Vec4::from(hvl.normal_distance).truncate();
    let g = geometric_factor(wj, hvl_n, n, r, a).ok()?;
    if g.is_nan() || g <= 0.0 {
        return None;
    }
    let mut e = match emission {
        Emission::Exact => std::f32::consts::FRAC_1_PI,
        Emission::Sh(bands) => zh_eval(&hvl.emission[..bands], hvl_n.normalize().dot(-wj)).max(0.0),
    };
    if falloff == Falloff::Disc {
        e *= disc_falloff(dist, r);
    }
    Some((Vec4::from(hvl.flux).truncate() * (e * g), wj, a))
}

/// Outgoing radiance towards `camera` at one receiver from all `hvls`, as `hvl_gather` computes
/// it (`brdf` is used by the full path only); each HVL's contribution is clamped at 0 per
/// channel (band-limited ringing).
pub fn shade(
    receiver: &Receiver,
    hvls: &[Hvl],
    brdf: &GatherBrdf,
    camera: Vec3,
    params: &HvlParams,
    visible: Option<Visibility<'_>>,
) -> Result<Vec3, HvlError> {
    let bands = params.conv_bands as usize;
    // With visibility, an HVL whose lifted centre is hidden from the receiver (outside its
    // sphere) sends nothing.
    let hidden = |hvl: &Hvl, x: Vec3, n: Vec3| match visible {
        Some(visible) if params.visibility => {
            let centre = Vec4::from(hvl.position_radius).truncate();
            let (origin, target) = visibility_ray(x, n, hvl);
            centre.distance(x) > hvl.position_radius[3] && !visible(origin, target)
        }
        _ => false,
    };
    let emission = Emission::Sh(params.emission_bands as usize);
    // The window's factor per band (hvl_gather.comp's `win`).
    let window = shine_sh::kernels::Window::Sinc {
        width: bands as f32,
    };
    let win: Vec<f32> = (0..bands)
        .map(|l| match params.window {
            crate::passes::hvl::Window::None => Ok(1.0),
            crate::passes::hvl::Window::Sinc => window.factor(l),
        })
        .collect::<Result<_, _>>()?;
    let (x, n) = (receiver.position, receiver.normal.normalize());
    // The diffuse share the traced near field leaves to the HVL.
    let far = |hvl: &Hvl| {
        let centre = Vec4::from(hvl.position_radius).truncate();
        shine_sh::hvl::far_weight(centre.distance(x), params.near_radius)
    };
    let (kd, ks) = receiver.weights(camera);
    // the glossy share the frame's specular pass leaves to the gather
    let ks = ks
        * (1.0 - crate::passes::specular::trace_weight(receiver.roughness, params.specular_limit));
    let mut sum = Vec3::ZERO;
    match params.path {
        GatherPath::Full => {
            let Some((t, b, theta_o)) = receiver_frame(n, (camera - x).normalize()) else {
                return Ok(Vec3::ZERO);
            };
            let f_lambert = brdf.lambert.lookup_f(theta_o);
            let f_glossy = brdf.glossy_f(receiver.roughness, theta_o);
            for hvl in hvls {
                let Some((lj, wj, a)) = hvl_incoming(hvl, x, n, emission, params.falloff) else {
                    continue;
                };
                if hidden(hvl, x, n) {
                    continue;
                }
                let local = Vec3::new(wj.dot(t), wj.dot(b), wj.dot(n)).normalize();
                let mut cap = cap_sh(local, a, bands)?;
                for (i, c) in cap.iter_mut().enumerate() {
                    *c *= win[i.isqrt()];
                }
                let diffuse = shine_sh::dot(&cap, &f_lambert)? * far(hvl);
                let glossy = shine_sh::dot(&cap, &f_glossy)?;
                sum += (lj * (kd * diffuse + ks * glossy)).max(Vec3::ZERO);
            }
        }
        GatherPath::Zonal => {
            let cc: Vec<f32> = clamped_cosine_zh(bands)?
                .iter()
                .map(|c| c / std::f32::consts::PI)
                .collect();
            for hvl in hvls {
                let Some((lj, wj, a)) = hvl_incoming(hvl, x, n, emission, params.falloff) else {
                    continue;
                };
                if hidden(hvl, x, n) {
                    continue;
                }
                let mut cap = cap_zh(a, bands)?;
                for (c, w) in cap.iter_mut().zip(&win) {
                    *c *= w;
                }
                sum += (lj * kd * (far(hvl) * zh_dot(&cap, &cc, n.dot(wj)))).max(Vec3::ZERO);
            }
        }
    }
    Ok(sum)
}

/// The gather over a whole receiver buffer (row-major RGBA, a = 0; background black); `visible`
/// answers the shadow rays when `params.visibility` is set.
pub fn gather(
    receivers: &ReceiverData,
    hvls: &[Hvl],
    brdf: &GatherBrdf,
    camera: Vec3,
    params: &HvlParams,
    visible: Option<Visibility<'_>>,
) -> Result<Vec<Vec4>, HvlError> {
    params.validate_gather()?;
    let texels = (receivers.extent[0] * receivers.extent[1]) as usize;
    let mut out = Vec::with_capacity(texels);
    for i in 0..texels {
        let p = receivers.position[i];
        if p.w == 0.0 {
            out.push(Vec4::ZERO);
            continue;
        }
        let receiver = Receiver {
            position: p.truncate(),
            normal: receivers.normal[i].truncate(),
            albedo: receivers.albedo[i].truncate(),
            metallic: receivers.material[i].y,
            roughness: receivers.material[i].x,
        };
        let count = (params.count as usize).min(hvls.len());
        out.push(shade(&receiver, &hvls[..count], brdf, camera, params, visible)?.extend(0.0));
    }
    Ok(out)
}

/// Numerical integration of eq. 3 for one HVL: `L_j(x, ω_j) ∫_{Q_j} (kd/π + ks f_glossy)
/// cos θ_i dω_i`, with `L_j` from eq. 20–22 (`emission` exact or band-limited) and the BRDF
/// evaluated exactly (no SH) over the cap `Q_j` by a Gauss–Legendre × uniform-φ rule of
/// `n_z × n_phi` nodes. This is what the gather's SH convolution approximates.
pub fn integrate_hvl(
    hvl: &Hvl,
    receiver: &Receiver,
    camera: Vec3,
    glossy: BrdfModel,
    emission: Emission,
    falloff: Falloff,
    nodes: [usize; 2],
) -> Vec3 {
    let (x, n) = (receiver.position, receiver.normal.normalize());
    let Some((lj, wj, a)) = hvl_incoming(hvl, x, n, emission, falloff) else {
        return Vec3::ZERO;
    };
    let Some((t, b, _)) = receiver_frame(n, (camera - x).normalize()) else {
        return Vec3::ZERO;
    };
    let to_local = |w: DVec3| {
        DVec3::new(
            w.dot(t.as_dvec3()),
            w.dot(b.as_dvec3()),
            w.dot(n.as_dvec3()),
        )
    };
    let wo = to_local((camera - x).normalize().as_dvec3());
    let q = SphereQuadrature::cap(wj.as_dvec3(), f64::from(a).cos(), nodes[0], nodes[1]);
    let lambert = BrdfModel::Lambert { albedo: 1.0 };
    let diffuse = q.integrate(|w| {
        let wi = to_local(w);
        lambert.eval(wi, wo) * wi.z.max(0.0)
    });
    let specular = q.integrate(|w| {
        let wi = to_local(w);
        glossy.eval(wi, wo) * wi.z.max(0.0)
    });
    let (kd, ks) = receiver.weights(camera);
    lj * (kd * diffuse as f32 + ks * specular as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shine_sh::basis::evaluate;
    use shine_sh::zonal::rotate_zh;

    #[test]
    fn zonal_helpers_match_rotation_and_the_full_dot_product() {
        let f = [0.7f32, -0.3, 0.25, 0.1, -0.05];
        let g = [0.2f32, 0.4, -0.1, 0.3, 0.02];
        let a = Vec3::new(0.3, -0.5, 0.8).normalize();
        let b = Vec3::new(-0.6, 0.2, 0.4).normalize();
        let fa = rotate_zh(&f, a).unwrap();
        let gb = rotate_zh(&g, b).unwrap();
        let full = shine_sh::dot(&fa, &gb).unwrap();
        assert!((zh_dot(&f, &g, a.dot(b)) - full).abs() < 1e-5);
        assert!((zh_eval(&f, a.dot(b)) - evaluate(&fa, b).unwrap()).abs() < 1e-5);
    }

    /// The emission's polynomial form gives what the Legendre sum gives, band by band.
    #[test]
    fn emission_polynomial_matches_the_zonal_sum() {
        let zh = [1.1f32, 0.6, -0.3, 0.2, -0.05];
        for bands in 1..=EMISSION_MAX_BANDS {
            let a = zh_poly(&zh, bands);
            for i in 0..=20 {
                let c = -1.0 + 0.1 * i as f32;
                let want = zh_eval(&zh[..bands], c);
                assert!(
                    (poly_eval(&a, c) - want).abs() < 1e-5,
                    "bands {bands} cos {c}"
                );
            }
        }
    }

    /// A receiver crossing an HVL's rim (d = r) sees no jump, in both gather paths: the
    /// light at d = r(1 ± 10⁻⁵) agrees to 1 %, for receivers facing the centre and tilted
    /// 60° from it (where a full-sphere cap inside made it jump by 2/(1 + cos 60°) = 1.33).
    /// Outside, the cap closes as asin(r/d), √(2ε) from π/2 at d = r(1 + ε): continuous but
    /// steep, hence the small ε.
    #[test]
    fn the_gather_is_continuous_across_an_hvls_rim() {
        let bands = 3;
        let brdf =
            GatherBrdf::build(bands, shine_sh::brdf_table::HemisphereSampling::default()).unwrap();
        let r = 0.4;
        let hvl = Hvl {
            position_radius: [0.0, 0.0, 0.0, r],
            normal_distance: [0.0, 1.0, 0.0, 2.0],
            flux: [1.0, 1.0, 1.0, 1.0],
            emission: {
                let mut e = [0.0; EMISSION_MAX_BANDS];
                e.copy_from_slice(&sender_emission_zh(EMISSION_MAX_BANDS).unwrap());
                e
            },
            ..Hvl::zeroed()
        };
        // Receivers straight above the HVL (facing away from its surface normal would send
        // nothing), their normals towards the centre or tilted by 60°.
        let to_centre = Vec3::NEG_Y;
        let tilted = Vec3::new(60f32.to_radians().sin(), -60f32.to_radians().cos(), 0.0);
        for path in [GatherPath::Full, GatherPath::Zonal] {
            let params = HvlParams {
                path,
                conv_bands: bands,
                ..HvlParams::default()
            };
            for normal in [to_centre, tilted] {
                let light = |d: f32| {
                    let receiver = Receiver {
                        position: Vec3::new(0.0, d, 0.0),
                        normal,
                        albedo: Vec3::splat(0.5),
                        metallic: 0.0,
                        roughness: 1.0,
                    };
                    let camera = receiver.position + normal * 2.0;
                    shade(&receiver, &[hvl], &brdf, camera, &params, None)
                        .unwrap()
                        .x
                };
                let (inside, outside) = (light(r * (1.0 - 1e-5)), light(r * (1.0 + 1e-5)));
                assert!(outside > 0.0, "{path:?}, {normal}: no light");
                assert!(
                    (inside / outside - 1.0).abs() < 0.01,
                    "{path:?}, normal {normal}: {inside} inside vs {outside} outside"
                );
            }
        }
    }

    /// The Lambert sender's `F'` reconstructs to `1/π` in every direction at every band count
    /// (band 0 only, eq. 20), so with `G`'s cosine an HVL emits its flux like a Lambert
    /// surface.
    #[test]
    fn lambert_sender_emission_is_isotropic() {
        for bands in 1..=EMISSION_MAX_BANDS {
            let zh = sender_emission_zh(bands).unwrap();
            for cos in [-1.0, -0.3, 0.0, 0.5, 1.0] {
                let e = zh_eval(&zh, cos);
                assert!(
                    (e - std::f32::consts::FRAC_1_PI).abs() < 1e-6,
                    "{bands}, {cos}: {e}"
                );
            }
        }
        assert!(sender_emission_zh(0).is_err());
        assert!(sender_emission_zh(EMISSION_MAX_BANDS + 1).is_err());
    }
}
