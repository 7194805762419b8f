//! CPU twin of the proxy passes (paper 002, `src/passes/proxy/`): [`accumulate_cpu`] and
//! [`shade_cpu`] compose the shine-sh functions exactly as `proxy_accumulate.comp` and
//! `proxy_shade.comp` compose their GLSL twins; `tests/proxy.rs` ties the two.

use glam::{Mat3, Vec3};
use shine_sh::exp_log::ShExp;
use shine_sh::kernels::clamped_cosine_zh;
use shine_sh::proxy_indirect::{averaged_operator_fit, overlap_normalisation};
use shine_sh::rotation::ShRotation;
use shine_sh::sphere_blocker::{BlockerSubstitute, self_shadow_substitute};
use shine_sh::zonal::rotate_zh;

use crate::gpu_scene::environment_sh::EnvironmentSh;
use crate::passes::brdf_tables::{GatherBrdf, indirect_weights, table_fresnel_weight};
use crate::passes::proxy::{
    Accumulation, ExpMethod, GpuProxy, INDIRECT_BANDS, ProxyError, ProxyParams, ProxyTables,
};
use crate::passes::specular::trace_weight;
use crate::reference::hvl::receiver_frame;

/// √(4π): the DC coefficient of the constant function 1 (the unoccluded visibility).
const SQRT_4PI: f32 = 3.544_907_7;

fn check_exp(params: &ProxyParams, exp: &ShExp) -> Result<usize, ProxyError> {
    let bands = params.check()?;
    if exp.bands() != bands {
        return Err(ProxyError::Size {
            name: "ShExp",
            actual: format!("{} bands", exp.bands()),
            expected: format!("{bands} bands"),
        });
    }
    Ok(bands)
}

/// One receiver as the CPU twin sees it (the receiver buffer's texel, decoded).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverSample {
    /// World position.
    pub position: Vec3,
    /// False for a background receiver (`recv_position.w == 0`).
    pub valid: bool,
    /// World normal (normalised here).
    pub normal: Vec3,
    /// Linear albedo.
    pub albedo: Vec3,
    /// Metallic factor.
    pub metallic: f32,
    /// Perceptual roughness (selects the glossy row of the BRDF tables).
    pub roughness: f32,
}

/// What the shade pass's glossy receivers need beyond the sums: the camera and the BRDF SH
/// tables at the parameters' band count.
#[derive(Debug, Clone, Copy)]
pub struct GlossyView<'a> {
    /// Camera position.
    pub camera: Vec3,
    /// The tables the GPU reads (`GatherBrdf::gpu_data`).
    pub brdf: &'a GatherBrdf,
}

/// CPU twin of `proxy_accumulate` at one receiver: the
/// [`sums_stride`](crate::passes::proxy::sums_stride) floats it writes. Every
/// proxy is visited (the splat only skips proxies whose contribution is exactly 0). `exp` is
/// the SH machinery of the parameters' band count.
pub fn accumulate_cpu(
    receiver: &ReceiverSample,
    proxies: &[GpuProxy],
    tables: &ProxyTables,
    environment: &EnvironmentSh,
    params: &ProxyParams,
    exp: &ShExp,
) -> Result<Vec<f32>, ProxyError> {
    let bands = check_exp(params, exp)?;
    let n2 = bands * bands;
    let product = params.accumulation == Accumulation::Product;
    let mut acc = vec![0.0f32; n2];
    if product {
        acc[0] = SQRT_4PI;
    }
    let mut indirect = Vec3::ZERO;
    let mut omega = 0.0f32;
    if receiver.valid {
        let p = receiver.position;
        let n = receiver.normal.normalize();
        let hn = rotate_zh(&clamped_cosine_zh(bands)?, n)?;
        for proxy in proxies {
            let Ok(BlockerSubstitute::Use { center, radius }) =
                self_shadow_substitute(p, n, proxy.center(), proxy.sphere[3])
            else {
                continue;
            };
            let dv = center - p;
            let dist = dv.length();
            if dist.is_nan() || dist <= 0.0 {
                continue;
            }
            let alpha = (radius / dist).min(1.0);
            let dir = dv / dist;
            if product {
                let mut o = rotate_zh(&tables.visibility_full.lookup(alpha), dir)?;
                o.iter_mut().for_each(|x| *x = -*x);
                o[0] += SQRT_4PI;
                acc = exp.tensor().product(&acc, &o)?;
            } else {
                let log = rotate_zh(&tables.log_occlusion.lookup(alpha), dir)?;
                acc.iter_mut().zip(&log).for_each(|(a, l)| *a += l);
            }
            if params.indirect {
                let table = if product {
                    &tables.visibility_full
                } else {
                    &tables.visibility
                };
                let mut zh = table.lookup(alpha);
                zh[INDIRECT_BANDS..].iter_mut().for_each(|x| *x = 0.0);
                let v = rotate_zh(&zh, dir)?;
                let vh = shine_sh::dot(&v, &hn)?;
                // eq. 12, paper 002: the proxy's true solid angle 2π(1 − cos θ), sin θ = α,
                // wherever its (clamped) visibility is not 0 — not the clamped table's DC, which
                // would cancel the indirect fade of §4.1.
                if zh[0] > 0.0 {
                    omega += std::f32::consts::TAU * (1.0 - (1.0 - alpha * alpha).max(0.0).sqrt());
                }
                let d = averaged_operator_fit(alpha);
                let d_sh = rotate_zh(&d, dir)?;
                let kappa = Vec3::from_array(std::array::from_fn(|c| {
                    shine_sh::dot(&d_sh, &environment.irradiance[c][..9]).unwrap_or(0.0)
                }));
                indirect += proxy.albedo() / std::f32::consts::PI * kappa * vh;
            }
        }
    }
    acc.extend(indirect.to_array());
    acc.push(omega);
    Ok(acc)
}

/// CPU twin of `proxy_shade` at one receiver, from its [`accumulate_cpu`] sums: the occlusion
/// vector `O_p` and the outgoing radiance towards `view.camera` (diffuse and glossy).
pub fn shade_cpu(
    receiver: &ReceiverSample,
    sums: &[f32],
    environment: &EnvironmentSh,
    params: &ProxyParams,
    exp: &ShExp,
    view: &GlossyView<'_>,
) -> Result<(Vec<f32>, Vec3), ProxyError> {
    let bands = check_exp(params, exp)?;
    let n2 = bands * bands;
    if sums.len() != n2 + 4 {
        return Err(ProxyError::Size {
            name: "sums",
            actual: sums.len().to_string(),
            expected: (n2 + 4).to_string(),
        });
    }
    let f = &sums[..n2];
    let o = match (params.accumulation, params.exp) {
        (Accumulation::Product, _) => f.to_vec(),
        (_, ExpMethod::Hyb) => exp.exp_hyb(f)?,
        (_, ExpMethod::Ps) => exp.exp_ps(f)?,
        (_, ExpMethod::Ol) => exp.exp_ol(f)?,
    };
    if !receiver.valid {
        return Ok((o, Vec3::ZERO));
    }
    let hn = rotate_zh(&clamped_cosine_zh(bands)?, receiver.normal.normalize())?;
    // H · (O ∗ L) = L · (O ∗ H): one product for the three channels, as the shader
    let oh = exp.tensor().product(&o, &hn)?;
    let mut psi = [0.0f32; 3];
    for (c, out) in psi.iter_mut().enumerate() {
        *out = shine_sh::dot(&oh, &environment.radiance[c])?;
    }
    let summed = Vec3::new(sums[n2], sums[n2 + 1], sums[n2 + 2]);
    let xi = overlap_normalisation(o[0], sums[n2 + 3]);
    let n = receiver.normal.normalize();
    let wo = (view.camera - receiver.position).normalize();
    let cos_o = n.dot(wo);
    let (kd, ks) = indirect_weights(receiver.albedo, receiver.metallic, cos_o);
    let ks = table_fresnel_weight(ks, cos_o)
        * (1.0 - trace_weight(receiver.roughness, params.specular_limit));
    let mut radiance =
        kd / std::f32::consts::PI * (Vec3::from_array(psi) + xi * summed).max(Vec3::ZERO);
    if ks.max_element() > 0.0
        && let Some((t, b, theta_o)) = receiver_frame(n, wo)
    {
        // L · (O ∗ F_w): the glossy row rotated from the receiver frame to the world
        let f_local = view.brdf.glossy_f(receiver.roughness, theta_o);
        let rotation = ShRotation::from_mat3(Mat3::from_cols(t, b, n), bands)?;
        let of = exp.tensor().product(&o, &rotation.apply(&f_local)?)?;
        let mut glossy = [0.0f32; 3];
        for (c, out) in glossy.iter_mut().enumerate() {
            *out = shine_sh::dot(&of, &environment.radiance[c])?;
        }
        radiance += ks * Vec3::from_array(glossy).max(Vec3::ZERO);
    }
    Ok((o, radiance))
}
