//! Sampled HVL visibility: a few shadow rays per receiver instead of one per HVL, and the
//! `hvl_shadow_filter` pass that denoises them with a ratio estimator.
//!
//! Paper 003's HVLs are unshadowed (§6). On the cornell box that leaves the indirect light 12%
//! too bright, because the boxes hide the floor's HVLs from half the room. One shadow ray per
//! receiver and HVL ([`ShadowSampling::rays`] = 0) fixes the energy but multiplies the gather's
//! cost by about 8 on lavapipe (400 rays per receiver). With `rays = K`, the gather
//! (`shaders/hvl_gather.comp`, `_vis` variants) draws K HVLs per receiver in proportion to
//! their contribution (weighted reservoirs over its loop) and traces only those, giving an
//! unbiased, noisy shadowed sum `S` beside the exact unshadowed sum `U`. The filter
//! (`shaders/hvl_shadow_filter.comp`) then returns `U · min(1, Σ w S / Σ w U)` over the
//! receivers around each one: the ratio estimator of Heitz, Hill and McGuire (2018,
//! "Combining analytic direct illumination and stochastic shadows"), which keeps `U`'s detail
//! and denoises only the shadowing. The weights are the sky filter's: a gaussian of the offset
//! times paper 002's bilateral match, so shadows do not bleed across edges.
//!
//! Amortised frames (`hvl.slices = 4`) filter the refreshed slice over its own receivers
//! (steps of 2), and the receivers regathered after a disocclusion, scattered, take their own
//! ratio `U · min(1, S/U)` in the gather; the history smooths both.
//!
//! [`ratio_filter`] is the filter's CPU twin.

use std::ops::RangeInclusive;

use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::receivers::Receivers;
use crate::passes::upsample::{UpsampleParams, bilateral_match};
use crate::shaders;

/// Most shadow rays per receiver (`HVL_SHADOW_RAYS_MAX` in `shaders/hvl_gather.comp`).
pub const RAYS_MAX: u32 = 4;
/// Shadow rays per receiver the settings take (0: one per HVL).
pub const RAYS_RANGE: RangeInclusive<u32> = 0..=RAYS_MAX;
/// Default shadow rays per receiver of the sampled visibility.
pub const RAYS: u32 = 4;
/// Default radius of the shadow filter, in receivers.
pub const FILTER_RADIUS: u32 = 3;
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
    /// Seed of the rays' random numbers (the frame index when a history averages frames).
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
    /// receivers ([`super::resolve::slice_of_frame`]).
    pub slice: u32,
    /// Padding.
    pub pad: [u32; 2],
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
    let mut filtered = rg.create_image(
        "hvl_shadowed",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let push = ShadowFilterPush {
        extent: receivers.extent,
        radius: sampling.filter_radius,
        depth_sigma: sampling.matching.depth_sigma,
        normal_power: sampling.matching.normal_power,
        slice,
        pad: [0; 2],
    };
    rg.compute("hvl_shadow_filter", &shaders::HVL_SHADOW_FILTER_COMP)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("shadowed", shadowed)
        .read("unshadowed", unshadowed)
        .write("filtered", &mut filtered)
        .push(&push)
        .dispatch(if slice == 0 {
            [w, h, 1]
        } else {
            [w.div_ceil(2), h.div_ceil(2), 1]
        });
    filtered
}

/// One receiver as the filter reads it: position (w: view depth, 0 on background), normal,
/// shadowed estimate `S` and unshadowed sum `U` (RGB).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterTexel {
    /// xyz world position, w view depth (0: background).
    pub position: [f32; 4],
    /// Shading normal (xyz).
    pub normal: [f32; 4],
    /// The gather's shadowed estimate.
    pub shadowed: [f32; 3],
    /// The gather's unshadowed sum.
    pub unshadowed: [f32; 3],
}

/// CPU twin of `hvl_shadow_filter.comp` (every receiver, slice 0) over a `width`-wide
/// row-major image: per channel,
/// `U · min(1, Σ w S / Σ w U)` with the shader's weights, `S` where `Σ w U` is 0, and 0 on
/// background.
pub fn ratio_filter(
    texels: &[FilterTexel],
    width: usize,
    sampling: &ShadowSampling,
) -> Vec<[f32; 3]> {
    let height = texels.len() / width.max(1);
    let r = sampling.filter_radius as i64;
    let inv_two_sigma2 = if r > 0 { 2.0 / (r * r) as f32 } else { 0.0 };
    let mut out = vec![[0.0; 3]; texels.len()];
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            let centre = &texels[(y * width as i64 + x) as usize];
            let n = centre.normal;
            if !on_surface(centre.position) || n[0] * n[0] + n[1] * n[1] + n[2] * n[2] <= 0.0 {
                continue;
            }
            let n = normalized(n);
            let (mut num, mut den) = ([0.0f32; 3], [0.0f32; 3]);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (cx, cy) = (x + dx, y + dy);
                    if cx < 0 || cy < 0 || cx >= width as i64 || cy >= height as i64 {
                        continue;
                    }
                    let q = &texels[(cy * width as i64 + cx) as usize];
                    if !on_surface(q.position) {
                        continue;
                    }
                    let w = (-((dx * dx + dy * dy) as f32) * inv_two_sigma2).exp()
                        * bilateral_match(
                            centre.position[3],
                            n,
                            q.position[3],
                            q.normal,
                            &sampling.matching,
                        );
                    for c in 0..3 {
                        num[c] += w * q.shadowed[c];
                        den[c] += w * q.unshadowed[c];
                    }
                }
            }
            let o = &mut out[(y * width as i64 + x) as usize];
            for c in 0..3 {
                o[c] = if den[c] > 0.0 {
                    centre.unshadowed[c] * (num[c] / den[c]).min(1.0)
                } else {
                    centre.shadowed[c]
                };
            }
        }
    }
    out
}

/// Whether a receiver's position is on a surface (view depth above 0; NaN is not).
fn on_surface(position: [f32; 4]) -> bool {
    position[3] > 0.0
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
