//! `upsample`: joint bilateral upsampling of a receiver-resolution result to full resolution
//! (paper 002 §4.2, eq. 11; docs/frame.md "Upsample").
//!
//! Each full-resolution pixel p blends the 2×2 nearest receiver samples i with
//! `w̃_i = w_i^b · w_i^z · w_i^N`, normalised (eq. 11):
//!
//! - `w_i^b`: the standard bilinear weight of p between the receiver sample centres (receiver
//!   texel coordinate `u = (x + 0.5) / s − 0.5`, indices clamped to the edge);
//! - `w_i^z = 1 / (1 + |z_p − z_i| / (σ_z z_p))`: eq. 11's `1 / (ε + |z_p − z_i|)` with
//!   `ε = σ_z z_p`, so the weight is 1 at equal depth and halves at a relative depth
//!   difference of σ_z (scale-invariant);
//! - `w_i^N = max(0, N_p · N_i)^n`, n = 32 in the paper;
//! - `w̃_i = 0` for a receiver that does not "sufficiently match" p (§4.2), i.e. whose
//!   `m_i = w_i^z · w_i^N < μ`, and for a background receiver (`w == 0`): the hyperbolic
//!   `w^z` alone would leak a few per cent across every silhouette (12 % at s = 4 for a depth
//!   ratio of 2, measured by tests/upsample.rs).
//!
//! Fallback (§4.2, "no coarse sample sufficiently matches"): when no receiver of the 2×2
//! matches (`Σ w̃_i = 0`), p takes the radiance of the valid receiver with the
//! largest `m` among the 3×3 receivers around its own (the receiver of its s×s block; own on
//! ties, then row-major order), 0 when all nine are background. The 3×3 search finds the
//! other side of an edge that the 2×2 misses: with the foreground-biased receivers, a
//! background pixel next to a silhouette can have only foreground receivers in its 2×2.
//! Background pixels (`w == 0`) get 0. With s = 1 the output is an exact copy of the radiance.
//!
//! The same pass upsamples any coarse grid ([`CoarseGrid`]): with a step of `W/w` pixels per
//! sample instead of s, `u = (x + 0.5) / step − 0.5` and p's own sample is
//! `floor((x + 0.5) / step)` (for an integer s both are the formulas above). A GI context's
//! internal resolution (75 %, a step of 4/3) uses it through [`upsample_grid`].

use serde::{Deserialize, Serialize};

use crate::declare::Settings;
use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::GBuffer;
use crate::passes::receivers::{ReceiverError, Receivers, receiver_extent};
use crate::shaders;

/// The paper's normal-weight exponent n in `w^N = (N_p · N_i)^n` (eq. 11, paper 002).
pub const NORMAL_POWER_N: f32 = 32.0;

/// σ_z: the relative depth difference `|z_p − z_i| / z_p` that halves `w^z` (eq. 11, paper
/// 002, whose ε this scales with depth). 1 %: across an edge with a depth ratio of 2 a
/// receiver from the other side has `w^z` ≈ 1/50 to 1/100, below [`MIN_MATCH_MU`]; along a
/// sloped floor seen at 1080p, neighbouring 1/4-resolution receivers differ by about 1–6 %.
pub const DEPTH_SIGMA: f32 = 0.01;

/// μ: the match `w^z · w^N` a receiver needs to "sufficiently match" the target (§4.2, paper
/// 002) and enter the blend; when none of the 2×2 does, the fallback is used. 0.05 is reached at a
/// relative depth difference of 19 σ_z (19 %) or normals 24° apart (`cos(24°)^32 ≈ 0.05`).
pub const MIN_MATCH_MU: f32 = 0.05;

/// σ_z a frame's settings take (`upsample.depth_epsilon`).
pub const DEPTH_SIGMA_RANGE: std::ops::RangeInclusive<f32> = 1e-6..=10.0;

/// Normal exponents n a frame's settings take (`upsample.normal_power`; tests use 0, plain
/// depth weights).
pub const NORMAL_POWER_RANGE: std::ops::RangeInclusive<f32> = 1.0..=256.0;

/// `[upsample]`: the joint bilateral weights of the upsample (paper 002 eq. 11), passed to
/// the shader as push constants.
#[repr(C)]
#[derive(
    Debug,
    Clone,
    Copy,
    PartialEq,
    bytemuck::Pod,
    bytemuck::Zeroable,
    Serialize,
    Deserialize,
    Settings,
)]
#[serde(default, deny_unknown_fields)]
pub struct UpsampleParams {
    /// σ_z of the depth weight 1 / (1 + |z_p − z_i| / (σ_z z_p)): paper 002 eq. 11's ε made
    /// relative to the pixel's linear depth z_p, so it does not depend on the scene's scale
    /// ([`DEPTH_SIGMA`]).
    #[serde(rename = "depth_epsilon")]
    #[setting(default = DEPTH_SIGMA, range = DEPTH_SIGMA_RANGE, affects = quality)]
    pub depth_sigma: f32,
    /// Exponent p of the normal weight (N_p · N_i)^p (paper 002: 32; [`NORMAL_POWER_N`]).
    #[setting(default = NORMAL_POWER_N, range = NORMAL_POWER_RANGE, affects = quality)]
    pub normal_power: f32,
    /// μ (≥ 0), see [`MIN_MATCH_MU`].
    #[serde(skip)]
    #[setting(default = MIN_MATCH_MU)]
    pub min_match: f32,
}

impl UpsampleParams {
    /// Checks the ranges (finite, σ_z > 0, n ≥ 0, μ ≥ 0).
    pub fn validate(&self) -> Result<(), ReceiverError> {
        if !(self.depth_sigma.is_finite() && self.depth_sigma > 0.0) {
            return Err(ReceiverError::Parameter(
                "depth_sigma must be finite and > 0",
            ));
        }
        if !(self.normal_power.is_finite() && self.normal_power >= 0.0) {
            return Err(ReceiverError::Parameter(
                "normal_power must be finite and ≥ 0",
            ));
        }
        if !(self.min_match.is_finite() && self.min_match >= 0.0) {
            return Err(ReceiverError::Parameter("min_match must be finite and ≥ 0"));
        }
        Ok(())
    }
}

/// A coarse grid the upsample reads from: `extent` samples, sample i standing for the
/// full-resolution pixels `[i·step, (i+1)·step)` with its centre at `(i + 0.5)·step`.
/// Receivers are blocks of an integer s ([`CoarseGrid::blocks`]); a GI context's internal
/// resolution is any smaller size ([`CoarseGrid::internal`], e.g. 75 %: a step of 4/3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoarseGrid {
    /// Width and height of the coarse images.
    pub extent: [u32; 2],
    /// Full-resolution pixels per coarse sample, along x and y.
    pub step: [f32; 2],
}

impl CoarseGrid {
    /// The receiver grid of a full-resolution `extent` at block size `scale`.
    pub fn blocks(extent: [u32; 2], scale: u32) -> Result<Self, ReceiverError> {
        Ok(Self {
            extent: receiver_extent(extent, scale)?,
            step: [scale as f32; 2],
        })
    }

    /// A grid of `coarse` samples spread evenly over `full` pixels (each side of `coarse` at
    /// least 1 and at most `full`'s).
    pub fn internal(full: [u32; 2], coarse: [u32; 2]) -> Result<Self, ReceiverError> {
        if coarse.contains(&0) {
            return Err(ReceiverError::EmptyExtent(coarse));
        }
        if coarse[0] > full[0] || coarse[1] > full[1] {
            return Err(ReceiverError::Extent {
                name: "coarse grid",
                found: coarse,
                expected: full,
            });
        }
        Ok(Self {
            extent: coarse,
            step: [0, 1].map(|i| full[i] as f32 / coarse[i] as f32),
        })
    }

    /// The full-resolution pixel whose G-buffer sample coarse sample `i` of an internal grid
    /// of `full` pixels holds: the one under its centre ([`texel_under_centre`], what
    /// `shaders/host_gbuffer.comp` fetches). Its centre lies up to half a pixel from
    /// `(i + 0.5) · step`, where the upsample's bilinear weights place the sample (half a
    /// pixel right and down at 50 % and 25 %): accepted, the light varies slowly.
    pub fn source_texel(&self, i: [u32; 2], full: [u32; 2]) -> [u32; 2] {
        [0, 1].map(|a| texel_under_centre(i[a], self.extent[a], full[a]))
    }

    /// True when each coarse sample is one full-resolution pixel (the upsample copies).
    pub fn is_identity(&self, full: [u32; 2]) -> bool {
        self.step == [1.0; 2] && self.extent == full
    }
}

/// The texel of a `to`-wide grid under the centre of texel `i` of a `from`-wide grid over the
/// same image: `floor((i + 0.5) · to / from)`, in integers (a float ratio rounds the exact ties
/// of a 2× or 4× step either way). GLSL twin: `texel_under_centre` in
/// `shaders/include/grid.glsl`.
pub fn texel_under_centre(i: u32, from: u32, to: u32) -> u32 {
    ((2 * u64::from(i) + 1) * u64::from(to) / (2 * u64::from(from))) as u32
}

/// Push constants of `shaders/upsample.comp` (40 bytes: std430 rounds the block up to its
/// `vec2` alignment).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct UpsamplePush {
    /// Full-resolution extent.
    pub extent: [u32; 2],
    /// Coarse (receiver) extent.
    pub recv_extent: [u32; 2],
    /// Full-resolution pixels per coarse sample ([`CoarseGrid::step`]).
    pub step: [f32; 2],
    /// The weights' parameters.
    pub params: UpsampleParams,
    /// Padding to the block's 8-byte alignment.
    pub pad: u32,
}

/// Adds the `upsample` pass: `radiance` (RGBA16F at the receiver extent) to a new transient
/// full-resolution RGBA16F image, guided by `receivers` and `gbuffer` positions and normals.
pub fn upsample(
    rg: &mut RenderGraph,
    radiance: &Handle<Image>,
    receivers: &Receivers,
    gbuffer: &GBuffer,
    params: &UpsampleParams,
) -> Result<Handle<Image>, ReceiverError> {
    params.validate()?;
    let expected = receiver_extent(gbuffer.extent, receivers.scale)?;
    if receivers.extent != expected {
        return Err(ReceiverError::Extent {
            name: "receivers",
            found: receivers.extent,
            expected,
        });
    }
    let desc = radiance.desc();
    if desc.format != vk::Format::R16G16B16A16_SFLOAT {
        return Err(ReceiverError::Format {
            name: "radiance",
            found: desc.format,
        });
    }
    let extent = desc.extent;
    if [extent.width, extent.height] != expected {
        return Err(ReceiverError::Extent {
            name: "radiance",
            found: [extent.width, extent.height],
            expected,
        });
    }
    let coarse = Coarse {
        position: receivers.position,
        normal: receivers.normal,
        grid: CoarseGrid::blocks(gbuffer.extent, receivers.scale)?,
    };
    Ok(upsample_grid(
        rg, "upsample", radiance, &coarse, gbuffer, params,
    ))
}

/// The guide of a coarse image: the positions and normals of its samples, and its grid.
#[derive(Debug, Clone, Copy)]
pub struct Coarse {
    /// Coarse `gb_position` (RGBA32F, linear depth in w; w = 0: background).
    pub position: Handle<Image>,
    /// Coarse `gb_normal` (RGBA16F).
    pub normal: Handle<Image>,
    /// How the coarse samples sit over the full-resolution pixels.
    pub grid: CoarseGrid,
}

/// Adds an upsample pass named `name`: `radiance` (RGBA16F on `coarse`'s grid, checked by
/// the caller) to a new transient RGBA16F image of `gbuffer`'s extent, with the weights of
/// [`upsample`]. `params` must be valid ([`UpsampleParams::validate`]).
pub fn upsample_grid(
    rg: &mut RenderGraph,
    name: &str,
    radiance: &Handle<Image>,
    coarse: &Coarse,
    gbuffer: &GBuffer,
    params: &UpsampleParams,
) -> Handle<Image> {
    let [w, h] = gbuffer.extent;
    let mut out = rg.create_image(
        "upsampled",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let push = UpsamplePush {
        extent: gbuffer.extent,
        recv_extent: coarse.grid.extent,
        step: coarse.grid.step,
        params: *params,
        pad: 0,
    };
    rg.compute(name, &shaders::UPSAMPLE_COMP)
        .read("radiance", radiance)
        .read("recv_position", &coarse.position)
        .read("recv_normal", &coarse.normal)
        .read("gb_position", &gbuffer.position)
        .read("gb_normal", &gbuffer.normal)
        .write("upsampled", &mut out)
        .push(&push)
        .dispatch([w, h, 1]);
    out
}

/// Inputs of [`upsample_cpu`]: RGBA floats, 4 per pixel, row-major.
#[derive(Debug, Clone, Copy)]
pub struct UpsampleInputs<'a> {
    /// Receiver-resolution radiance.
    pub radiance: &'a [f32],
    /// `recv_position`.
    pub recv_position: &'a [f32],
    /// `recv_normal`.
    pub recv_normal: &'a [f32],
    /// Full-resolution `gb_position`.
    pub position: &'a [f32],
    /// Full-resolution `gb_normal`.
    pub normal: &'a [f32],
    /// Full-resolution extent W×H.
    pub extent: [u32; 2],
    /// The coarse grid of `radiance`, `recv_position` and `recv_normal`.
    pub grid: CoarseGrid,
}

/// The joint bilateral match of a receiver at depth `z_i` with normal `n_i` for a target at
/// depth `z` with normal `n` (paper 002 §4.2, eq. 11, with ε = σ_z z):
/// `1 / (1 + |z − z_i| / (σ_z z)) · max(0, n · n_i)^n`. GLSL twin: `bilateral_match` in
/// `shaders/include/bilateral.glsl` (the upsample, the sky's and the near field's bilateral
/// filter).
pub fn bilateral_match(
    z: f32,
    n: [f32; 4],
    z_i: f32,
    n_i: [f32; 4],
    params: &UpsampleParams,
) -> f32 {
    let wz = 1.0 / (1.0 + (z - z_i).abs() / (params.depth_sigma * z));
    let cos = n[0] * n_i[0] + n[1] * n_i[1] + n[2] * n_i[2];
    wz * cos.max(0.0).powf(params.normal_power)
}

/// [`bilateral_match`] with the depth offset measured off the target's tangent plane:
/// `1 / (1 + |n · (x_i − x)| / (σ_z z)) · max(0, n · n_i)^n` for a target at `x` (xyz, w its
/// depth z) with normal `n` and a receiver at `x_i` with normal `n_i` (issue 43). On a plane
/// seen at a grazing angle the rows' depths differ by more than σ_z z, so the depth test keeps
/// a receiver's own row and a filter of noisy samples leaves stripes that flicker as the samples
/// move; the plane's own receivers lie on it at 0. HVL's sampled shadows' ratio filter
/// ([`crate::passes::hvl::shadows::ratio_filter`]) and the near field's filter (with a world
/// reach, [`crate::passes::sky::bilateral_cpu`]) use it; the upsample keeps paper 002's depth. GLSL
/// twin: `bilateral_plane_match` in `shaders/include/bilateral.glsl`.
pub fn bilateral_plane_match(
    x: [f32; 4],
    n: [f32; 4],
    x_i: [f32; 4],
    n_i: [f32; 4],
    params: &UpsampleParams,
) -> f32 {
    let offset = (0..3).map(|k| n[k] * (x_i[k] - x[k])).sum::<f32>();
    let wz = 1.0 / (1.0 + offset.abs() / (params.depth_sigma * x[3]));
    let cos = n[0] * n_i[0] + n[1] * n_i[1] + n[2] * n_i[2];
    wz * cos.max(0.0).powf(params.normal_power)
}

/// CPU reference of `upsample` (same weights, order and fallback as the shader): the
/// full-resolution RGBA result, 4 floats per pixel, row-major.
pub fn upsample_cpu(
    inputs: &UpsampleInputs<'_>,
    params: &UpsampleParams,
) -> Result<Vec<f32>, ReceiverError> {
    params.validate()?;
    let recv = inputs.grid.extent;
    let [w, h] = inputs.extent.map(|v| v as usize);
    let [rw, rh] = recv.map(|v| v as usize);
    for (name, data, len, expected) in [
        ("radiance", inputs.radiance, rw * rh, recv),
        ("recv_position", inputs.recv_position, rw * rh, recv),
        ("recv_normal", inputs.recv_normal, rw * rh, recv),
        ("gb_position", inputs.position, w * h, inputs.extent),
        ("gb_normal", inputs.normal, w * h, inputs.extent),
    ] {
        if data.len() != len * 4 {
            return Err(ReceiverError::Extent {
                name,
                found: [(data.len() / 4) as u32, 1],
                expected,
            });
        }
    }
    let texel = |data: &[f32], i: usize| -> [f32; 4] {
        [
            data[i * 4],
            data[i * 4 + 1],
            data[i * 4 + 2],
            data[i * 4 + 3],
        ]
    };
    let step = inputs.grid.step;
    // Receiver index of texel coordinates, clamped to the edge.
    let index = |cx: i64, cy: i64| -> usize {
        cy.clamp(0, rh as i64 - 1) as usize * rw + cx.clamp(0, rw as i64 - 1) as usize
    };
    let mut out = vec![0.0f32; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let p = y * w + x;
            let target = texel(inputs.position, p);
            if target[3] <= 0.0 {
                continue;
            }
            if inputs.grid.is_identity(inputs.extent) {
                out[p * 4..p * 4 + 4].copy_from_slice(&texel(inputs.radiance, p));
                continue;
            }
            let normal = texel(inputs.normal, p);
            // w^z · w^N of receiver c (eq. 11); -1 for a background receiver.
            let match_weight = |c: usize| -> f32 {
                let position = texel(inputs.recv_position, c);
                if position[3] <= 0.0 {
                    return -1.0;
                }
                let n = texel(inputs.recv_normal, c);
                bilateral_match(target[3], normal, position[3], n, params)
            };
            let centre = [x as f32 + 0.5, y as f32 + 0.5];
            let u = [centre[0] / step[0] - 0.5, centre[1] / step[1] - 0.5];
            let base = u.map(f32::floor);
            let f = [u[0] - base[0], u[1] - base[1]];
            let mut sum = [0.0f32; 4];
            let mut weight_sum = 0.0f32;
            for k in 0..4 {
                let (ox, oy) = (k & 1, k >> 1);
                let c = index(base[0] as i64 + ox, base[1] as i64 + oy);
                let wx = if ox == 1 { f[0] } else { 1.0 - f[0] };
                let wy = if oy == 1 { f[1] } else { 1.0 - f[1] };
                let m = match_weight(c);
                let weight = if m >= params.min_match {
                    wx * wy * m
                } else {
                    0.0
                };
                for (acc, v) in sum.iter_mut().zip(texel(inputs.radiance, c)) {
                    *acc += weight * v;
                }
                weight_sum += weight;
            }
            let result = if weight_sum > 0.0 {
                sum.map(|v| v / weight_sum)
            } else {
                // Fallback: the best match among the 3×3 around p's own receiver (own on ties).
                let own = [
                    (centre[0] / step[0]).floor() as i64,
                    (centre[1] / step[1]).floor() as i64,
                ];
                let own_index = index(own[0], own[1]);
                let mut best = match_weight(own_index);
                let mut result = if best >= 0.0 {
                    texel(inputs.radiance, own_index)
                } else {
                    [0.0; 4]
                };
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let c = index(own[0] + dx, own[1] + dy);
                        let m = match_weight(c);
                        if m > best {
                            best = m;
                            result = texel(inputs.radiance, c);
                        }
                    }
                }
                result
            };
            out[p * 4..p * 4 + 4].copy_from_slice(&result);
        }
    }
    Ok(out)
}
