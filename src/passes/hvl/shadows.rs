//! Sampled HVL visibility: a few shadow rays per receiver instead of one per HVL, and the
//! `hvl_shadow_filter` pass that denoises them with a ratio estimator.
//!
//! Paper 003's HVLs are unshadowed (§6). On the cornell box that leaves the indirect light 12%
//! too bright, because the boxes hide the floor's HVLs from half the room. One shadow ray per
//! receiver and HVL ([`ShadowSampling::rays`] = 0, the `_vis` variants) fixes the energy but
//! multiplies the gather's cost by about 10 on lavapipe (400 rays per receiver). With
//! `rays = K`, the gather (`shaders/hvl_gather.comp`, `_shadows` variants) splits the HVLs into
//! K strata by identity (stratum k: every light's samples k, k + K, k + 2K, … of its sequence;
//! with the flux distribution's Sobol points and K a power of two, a band of each light's
//! flux, [`Hvl::light_samples`](super::Hvl::light_samples) telling where each light's
//! run of records ends), draws one HVL of each in proportion to its weight `w_j` (the mean of
//! its light's channels) by an exponential race keyed by the HVL's identity (the least
//! `−ln u_j / w_j` wins; `u_j` a hash of the receiver and the identity), and traces only
//! those. So an HVL keeps its stratum and its number when another light's count changes and
//! the records move to other slots (issue 43): `S = W_in + Σ_k W_k V_k` (`W_k` a stratum's weight,
//! `V_k` its drawn HVL's visibility, `W_in` the weight of HVLs the receiver is inside of) is an
//! unbiased, noisy shadowed weight beside the exact unshadowed light `U` and its weight `W_u`. The filter
//! (`shaders/hvl_shadow_filter.comp`) then returns `U · min(1, Σ w S / Σ w W_u)` over the
//! receivers around each one: exactly `U` where nothing is in the way (a scalar ratio: the
//! shadows take the light's colour, not the hidden HVLs' own). This is the ratio estimator of
//! Heitz, Hill and McGuire (2018,
//! "Combining analytic direct illumination and stochastic shadows"), which keeps `U`'s detail
//! and denoises only the shadowing. The weights are a gaussian of the offset (σ = the radius,
//! twice the sky filter's: the visibility's noise needs the wider mean) times paper 002's
//! bilateral match with its depth offset measured off the receiver's tangent plane
//! ([`bilateral_plane_match`]: a grazing floor keeps its rows' receivers, issue 43), so
//! shadows do not bleed across edges.
//!
//! Amortised frames (`hvl.slices = 4`) filter the refreshed slice over its own receivers
//! (steps of 2), and the receivers regathered after a disocclusion, scattered, take their own
//! ratio `U · min(1, S / W_u)` in the gather; the resolve's history smooths both (amortised
//! frames draw new rays every frame, [`ShadowSampling::seed`]).
//!
//! [`ratio_filter`] is the filter's CPU twin.

use std::ops::RangeInclusive;

use crate::graph::{Handle, Image, RenderGraph};
use crate::passes::amortise;
use crate::passes::receivers::{Receivers, on_surface};
use crate::passes::upsample::{UpsampleParams, bilateral_plane_match};
use crate::shaders;

/// Most shadow rays per receiver (`HVL_SHADOW_RAYS_MAX` in `shaders/hvl_gather.comp`).
pub const RAYS_MAX: u32 = 16;
/// Shadow rays per receiver the settings take (0: one per HVL).
pub const RAYS_RANGE: RangeInclusive<u32> = 0..=RAYS_MAX;
/// Default shadow rays per receiver of the sampled visibility.
pub const RAYS: u32 = 8;
/// Default radius of the shadow filter, in receivers.
pub const FILTER_RADIUS: u32 = 4;
/// σ of the filter's gaussian over its radius (the sky filter's is 1/2: the visibility's noise
/// needs the wider mean).
pub const SIGMA_PER_RADIUS: f32 = 1.0;
/// Filter radii the settings take (0: each receiver's own ratio).
pub const FILTER_RADIUS_RANGE: RangeInclusive<u32> = 0..=8;

/// Which shadow rays a gather variant traces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shadowing {
    /// None (paper 003): variants `full_cN`, `zonal_cN`.
    None,
    /// One per receiver and HVL: variants `…_vis`.
    EveryHvl,
    /// [`ShadowSampling::rays`] per receiver, then the ratio filter: variants `…_shadows`.
    Sampled,
}

impl Shadowing {
    /// What `visibility` and `sampling` ask for.
    pub fn of(visibility: bool, sampling: &ShadowSampling) -> Self {
        match (visibility, sampling.rays) {
            (false, _) => Self::None,
            (true, 0) => Self::EveryHvl,
            (true, _) => Self::Sampled,
        }
    }

    /// The suffix of the gather's variant names.
    pub fn suffix(self) -> &'static str {
        match self {
            Self::None => "",
            Self::EveryHvl => "_vis",
            Self::Sampled => "_shadows",
        }
    }
}

/// How the gather shadows its HVLs when `visibility` is on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowSampling {
    /// Shadow rays per receiver, to HVLs drawn by contribution; 0 traces one ray per HVL
    /// (exact, and no filter).
    pub rays: u32,
    /// Radius in receivers of the ratio filter.
    pub filter_radius: u32,
    /// The filter's bilateral match (the frame's upsample's).
    pub matching: UpsampleParams,
    /// Seed of the rays' random numbers (the frame index when a history averages frames: the
    /// indirect light's or the amortised gather's).
    pub seed: u32,
}

impl Default for ShadowSampling {
    fn default() -> Self {
        Self {
            rays: RAYS,
            filter_radius: FILTER_RADIUS,
            matching: UpsampleParams::default(),
            seed: 0,
        }
    }
}

/// Push constants of `shaders/hvl_shadow_filter.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadowFilterPush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Radius of the filter in receivers.
    pub radius: u32,
    /// σ_z of the bilateral match.
    pub depth_sigma: f32,
    /// Normal exponent of the bilateral match.
    pub normal_power: f32,
    /// 0: every receiver; 1 + k: only the amortised gather's slice k, filtered over its own
    /// receivers ([`amortise::slice_of_frame`]).
    pub slice: u32,
    /// σ of the gaussian over the radius ([`SIGMA_PER_RADIUS`]).
    pub sigma_per_radius: f32,
    /// Padding.
    pub pad: u32,
}

/// Adds `hvl_shadow_filter`: the ratio-filtered light of the sampled gather's `shadowed`
/// estimate and its `unshadowed` sum (both RGBA16F at receiver resolution), returned as a new
/// image of the same kind. `slice` is the gather's: 0 filters every receiver, 1 + k only
/// those of slice k (the others are left undefined, as the gather leaves them).
pub fn shadow_filter(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    shadowed: &Handle<Image>,
    unshadowed: &Handle<Image>,
    sampling: &ShadowSampling,
    slice: u32,
) -> Handle<Image> {
    let [w, h] = receivers.extent;
    let mut filtered = receivers.light_image(rg, "hvl_shadowed");
    let push = ShadowFilterPush {
        extent: receivers.extent,
        radius: sampling.filter_radius,
        depth_sigma: sampling.matching.depth_sigma,
        normal_power: sampling.matching.normal_power,
        slice,
        sigma_per_radius: SIGMA_PER_RADIUS,
        pad: 0,
    };
    rg.compute("hvl_shadow_filter", &shaders::HVL_SHADOW_FILTER_COMP)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("shadowed", shadowed)
        .read("unshadowed", unshadowed)
        .write("filtered", &mut filtered)
        .push(&push)
        .dispatch(amortise::slice_threads([w, h], slice));
    filtered
}

/// One receiver as the filter reads it: position (w: view depth, 0 on background), normal,
/// unshadowed light `U` with its weight, and the shadowed weight `S`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterTexel {
    /// xyz world position, w view depth (0: background).
    pub position: [f32; 4],
    /// Shading normal (xyz).
    pub normal: [f32; 4],
    /// The gather's unshadowed light (RGB).
    pub unshadowed: [f32; 3],
    /// Its weight: the sum over the HVLs of the mean of their light's channels.
    pub unshadowed_weight: f32,
    /// The gather's estimate of the shadowed weight.
    pub shadowed_weight: f32,
}

/// CPU twin of `hvl_shadow_filter.comp` over a `width`-wide row-major image:
/// `U · min(1, Σ w S / Σ w W_u)`, 0 where `Σ w W_u` is 0 and on background. `slice` as the
/// pass's: 0 every receiver; 1 + k those of slice k, filtered over their own slice (`None`
/// for the others, which the pass leaves alone).
pub fn ratio_filter(
    texels: &[FilterTexel],
    width: usize,
    sampling: &ShadowSampling,
    slice: u32,
) -> Vec<Option<[f32; 3]>> {
    let height = texels.len() / width.max(1);
    let (step, offset) = match slice {
        0 => (1, (0, 0)),
        s => (2, (((s - 1) & 1) as i64, ((s - 1) >> 1) as i64)),
    };
    let r = sampling.filter_radius as i64;
    let sigma = SIGMA_PER_RADIUS * r as f32;
    let inv_two_sigma2 = if r > 0 { 0.5 / (sigma * sigma) } else { 0.0 };
    let at = |x: i64, y: i64| &texels[(y * width as i64 + x) as usize];
    let mut out = vec![None; texels.len()];
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            if step == 2 && (x % 2, y % 2) != offset {
                continue;
            }
            let centre = at(x, y);
            let n = centre.normal;
            let o = &mut out[(y * width as i64 + x) as usize];
            *o = Some([0.0; 3]);
            if !on_surface(centre.position) || n[0] * n[0] + n[1] * n[1] + n[2] * n[2] <= 0.0 {
                continue;
            }
            let n = normalized(n);
            let (mut num, mut den) = (0.0f32, 0.0f32);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (cx, cy) = (x + step * dx, y + step * dy);
                    if cx < 0 || cy < 0 || cx >= width as i64 || cy >= height as i64 {
                        continue;
                    }
                    let q = at(cx, cy);
                    if !on_surface(q.position) {
                        continue;
                    }
                    let w = (-((dx * dx + dy * dy) as f32) * inv_two_sigma2).exp()
                        * bilateral_plane_match(
                            centre.position,
                            n,
                            q.position,
                            q.normal,
                            &sampling.matching,
                        );
                    num += w * q.shadowed_weight;
                    den += w * q.unshadowed_weight;
                }
            }
            if den > 0.0 {
                *o = Some(centre.unshadowed.map(|u| u * (num / den).min(1.0)));
            }
        }
    }
    out
}

/// `n` scaled to unit length (xyz; w kept); zero stays zero.
fn normalized(n: [f32; 4]) -> [f32; 4] {
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        [n[0] / len, n[1] / len, n[2] / len, n[3]]
    } else {
        n
    }
}
