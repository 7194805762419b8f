//! Sky light for the frames without proxies (issue 16, item 7; issue 18, item 2): the `sky`
//! pass (`shaders/sky.comp`).
//!
//! Only the proxies (paper 002) lit a scene by its environment, so under HVL, IGI or AAF the
//! ground of `spheres` was black wherever the sun did not reach. This pass adds the diffuse sky
//! light at every receiver: [`SkyParams::rays`] cosine-weighted rays through the BVH measure
//! the cosine-weighted sky visibility `A` (ambient occlusion, up to [`SkyParams::range`]; 0:
//! the whole scene) and the bent normal `b` (the mean open direction), and the receiver sends
//! `kd/π · A · L̃(b)` (`L̃` the environment's SH irradiance at 3 bands, paper 002 §3).
//! The demodulated `A · L̃(b) / π` is filtered before it is multiplied by `kd`
//! ([`LightFilter`]): by default by the traced signals' à-trous denoiser with its diffuse
//! footprint ([`crate::passes::denoise::diffuse`], issue 47); with `denoise.diffuse = false`
//! by the `sky_filter` pass (`shaders/sky_filter.comp`), the joint bilateral mean over
//! [`SkyParams::filter_radius`] receivers around each one.
//!
//! # Decisions
//!
//! * Receiver resolution, summed with HVL's light before the upsample: sky light is smooth.
//! * Visibility times the unshadowed irradiance at the bent normal rather than a traced sum of
//!   the sky's radiance: with few rays the noise is in `A` alone, the colour and direction of
//!   the sky come from the SH (exact for a uniform sky, `tests/sky.rs`).
//! * A spatial filter of the demodulated light (issue 47 made it the à-trous denoiser's; the
//!   bilateral below remains with `denoise.diffuse = false`): 16 rays leave the visibility
//!   noisy where little sky is open (`animated`'s room, lit through its window), and a new
//!   seed every frame made that noise flicker (docs/quality.md, "The sky's noise, filtered").
//!   The filter uses the upsample's bilateral match (paper 002 eq. 11), so it does not blur
//!   across edges, and it leaves the albedo's texture alone. The denoiser that replaced it by
//!   default (issue 47) keeps both properties and smooths large matte walls further
//!   (docs/quality.md).
//! * Not in frames with proxies: they shadow the environment themselves (paper 002). In every
//!   other frame, `gi = none` included: light from the sky that scatters once is direct light
//!   (as the path tracer counts it).

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};

use crate::gpu_scene::bvh::TraceImages;
use crate::graph::{Buffer, Handle, Image, RenderGraph};
use crate::passes::brdf_tables::indirect_weights;
use crate::passes::denoise::{self, DenoiseError, DenoiseParams};
use crate::passes::receivers::{Receivers, on_surface};
use crate::passes::upsample::{UpsampleParams, bilateral_match, bilateral_plane_match};
use crate::shaders;

/// Default rays per receiver.
pub const RAYS: u32 = 16;
/// Rays per receiver the settings take.
pub const RAYS_RANGE: RangeInclusive<u32> = 1..=1024;
/// Ranges of the rays the settings take, in world units (0: unbounded).
pub const RANGE_RANGE: RangeInclusive<f32> = 0.0..=1e6;
/// SH bands of the environment's irradiance the pass reads.
pub const BANDS: u32 = 3;
/// Default radius of the sky filter, in receivers.
pub const FILTER_RADIUS: u32 = 3;
/// Filter radii the settings take (0: no filter).
pub const FILTER_RADIUS_RANGE: RangeInclusive<u32> = 0..=8;

/// `[sky]`: the environment's diffuse light times each receiver's sky visibility and bent
/// normal (issue 16), in every frame without the proxies (which shadow the environment
/// themselves; `gi = none` included), when the scene has an environment: the sky pass's
/// parameters, each declared once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct SkyParams {
    /// Light the receivers by the sky (the frame declares the pass only then).
    #[setting(default = true, affects = both)]
    pub enabled: bool,
    /// Rays per receiver.
    #[setting(default = RAYS, range = RAYS_RANGE, affects = both)]
    pub rays: u32,
    /// How far a ray looks for an occluder, in world units (0: unbounded, the sky's
    /// visibility; a short range gives cavity occlusion).
    #[setting(default = 0.0, range = RANGE_RANGE, affects = quality)]
    pub range: f32,
    /// Look the irradiance up at the bent normal (the mean open direction); false: at the
    /// shading normal.
    #[setting(default = true, affects = quality)]
    pub bent_normal: bool,
    /// Seed of the rays (set by the frame).
    #[serde(skip)]
    #[setting(default = 0)]
    pub seed: u32,
    /// Radius in receivers of the joint bilateral filter of the sky's light, used with
    /// `denoise.diffuse = false` or `denoise.enabled = false` (0: none; unused by the cavity
    /// pass).
    #[setting(default = FILTER_RADIUS, range = FILTER_RADIUS_RANGE, affects = both)]
    pub filter_radius: u32,
}

/// `[cavity]`: paper 001's cavity shading of HVL's unshadowed indirect light (issue 18): the
/// light times the share of short cosine-weighted rays that meet nothing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct CavitySettings {
    /// Darken HVL's light by its receivers' cavity occlusion. Meant for HVLs without shadows
    /// (`hvl.visibility = false`): shadowed HVLs already lose that light.
    #[setting(default = false, affects = both)]
    pub enabled: bool,
    /// Rays per receiver.
    #[setting(default = CAVITY_RAYS, range = RAYS_RANGE, affects = both)]
    pub rays: u32,
    /// Reach of the rays as a fraction of the scene's largest side.
    #[setting(default = CAVITY_RANGE, range = CAVITY_RANGE_RANGE, affects = quality)]
    pub range: f32,
}

impl CavitySettings {
    /// The cavity pass's parameters: its rays, and their reach as a fraction of the scene's
    /// largest side.
    pub fn params(&self) -> SkyParams {
        SkyParams {
            rays: self.rays,
            range: self.range,
            bent_normal: false,
            ..SkyParams::default()
        }
    }
}

/// What the sky pass refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SkyError {
    /// A parameter out of its range.
    #[error("sky: {0}")]
    OutOfRange(#[from] crate::declare::OutOfRange),
    /// The denoiser refused its parameters.
    #[error(transparent)]
    Denoise(#[from] DenoiseError),
}

impl SkyParams {
    /// Checks every parameter against its range.
    pub fn validate(&self) -> Result<(), SkyError> {
        // No prefix: the cavity pass runs on these parameters too (`[cavity]`).
        Ok(self.check_in("")?)
    }
}

/// Push constants of `shaders/sky.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SkyPush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Rays per receiver.
    pub rays: u32,
    /// Seed.
    pub seed: u32,
    /// 1: the irradiance at the bent normal; 0: at the shading normal.
    pub bent_normal: u32,
    /// The rays' range (0: unbounded).
    pub range: f32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Push constants of `shaders/sky_filter.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SkyFilterPush {
    /// xyz camera position (the receivers' view direction for `kd`), w unused.
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Radius of the filter in receivers (0: none).
    pub radius: u32,
    /// σ_z of the bilateral match.
    pub depth_sigma: f32,
    /// Normal exponent of the bilateral match.
    pub normal_power: f32,
    /// σ of the gaussian over the radius ([`SKY_SIGMA_PER_RADIUS`] for the sky).
    pub sigma_per_radius: f32,
    /// σ of a gaussian over the receivers' world distance, with the match's depth offset
    /// measured off the receiver's tangent plane; 0: neither (the sky's).
    pub world_sigma: f32,
    /// Padding.
    pub pad: u32,
}

/// σ of the sky filter's gaussian over its radius.
pub const SKY_SIGMA_PER_RADIUS: f32 = 0.5;

/// Adds the `sky` pass and its filter over `receivers` seen from `camera`: the
/// environment's SH (`environment`, `EnvironmentSh::gpu_data` at [`BANDS`] bands) times each
/// receiver's sky visibility through `bvh`, filtered by `filter` and multiplied by `kd`.
/// Returns the outgoing radiance (RGBA16F at receiver resolution). `seed` is added to the
/// parameters' (the frame index when a history averages the frames).
#[allow(clippy::too_many_arguments)]
pub fn sky(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    environment: &Handle<Buffer>,
    bvh: &TraceImages,
    camera: glam::Vec3,
    params: &SkyParams,
    filter: LightFilter<'_>,
    seed: u32,
) -> Result<Handle<Image>, SkyError> {
    params.validate()?;
    let irradiance = trace_pass(
        rg,
        "sky",
        "sky_irradiance",
        &shaders::SKY_COMP_SKY,
        receivers,
        bvh,
        params,
        seed,
        |pass| {
            pass.read("environment", environment);
        },
    );
    Ok(filter.apply(
        rg,
        ["sky", "sky_light"],
        receivers,
        &irradiance,
        camera,
        Reach {
            bilateral: BilateralReach {
                radius: params.filter_radius,
                sigma_per_radius: SKY_SIGMA_PER_RADIUS,
                world_sigma: 0.0,
            },
            footprint: denoise::Footprint::Pixels(denoise::SKY_RADIUS),
        },
    )?)
}

/// How the sky's and HVL's near field's demodulated light (light / π at receiver resolution)
/// is filtered before it is multiplied by each receiver's `kd`.
#[derive(Debug, Clone, Copy)]
pub enum LightFilter<'a> {
    /// The joint bilateral mean ([`bilateral_filter`]) with this upsample's match.
    Bilateral(&'a UpsampleParams),
    /// The traced signals' à-trous denoiser, its diffuse footprint
    /// ([`crate::passes::denoise::diffuse`]; the sky's default, `denoise.diffuse`; the near
    /// field's with `denoise.near_field`).
    Denoise(&'a DenoiseParams),
}

/// How far each [`LightFilter`] reaches for one signal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// The bilateral's reach.
    pub bilateral: BilateralReach,
    /// The denoiser's footprint.
    pub footprint: denoise::Footprint,
}

/// How far the joint bilateral ([`bilateral_filter`]) reaches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BilateralReach {
    /// Radius in receivers.
    pub radius: u32,
    /// σ of the gaussian over the radius, over the radius.
    pub sigma_per_radius: f32,
    /// σ of a gaussian over the receivers' world distance, the match then measured off the
    /// receiver's tangent plane (HVL's near field, [`crate::passes::hvl::near`]); 0: neither,
    /// the depth match alone (the sky's).
    pub world_sigma: f32,
}

impl LightFilter<'_> {
    /// Adds the filter of `light` over `receivers` seen from `camera`: passes
    /// `{label}_filter` (the bilateral) or `{label}_prep` and `{label}_atrous_i`, writing a
    /// new image `output`, reaching as far as `reach` says. Returns the outgoing radiance
    /// (RGBA16F at receiver resolution).
    pub fn apply(
        self,
        rg: &mut RenderGraph,
        [label, output]: [&str; 2],
        receivers: &Receivers,
        light: &Handle<Image>,
        camera: glam::Vec3,
        reach: Reach,
    ) -> Result<Handle<Image>, DenoiseError> {
        match self {
            Self::Bilateral(upsample) => Ok(bilateral_filter(
                rg,
                [&format!("{label}_filter"), output],
                receivers,
                light,
                camera,
                reach.bilateral,
                upsample,
            )),
            Self::Denoise(params) => denoise::diffuse(
                rg,
                [&format!("{label}_prep"), &format!("{label}_atrous"), output],
                receivers,
                light,
                camera,
                reach.footprint,
                params,
            ),
        }
    }
}

/// Adds a pass `names[0]` of `sky_filter.comp` writing a new image `names[1]`: the joint
/// bilateral mean of the demodulated light
/// `light` (RGBA16F at receiver resolution, light over π) as far as `reach`: a
/// gaussian over the receivers within the radius, times the bilateral match of `upsample`
/// (with a world σ, the plane match times a gaussian of that σ over the receivers' world
/// distance, [`BilateralReach::world_sigma`]);
/// then times the receiver's `kd` seen from `camera`.
/// Returns the outgoing radiance (RGBA16F at receiver resolution). The sky pass's filter, and
/// HVL's near field's ([`crate::passes::hvl::near`]).
pub fn bilateral_filter(
    rg: &mut RenderGraph,
    [name, output]: [&str; 2],
    receivers: &Receivers,
    light: &Handle<Image>,
    camera: glam::Vec3,
    reach: BilateralReach,
    upsample: &UpsampleParams,
) -> Handle<Image> {
    let [w, h] = receivers.extent;
    let mut out = receivers.light_image(rg, output);
    let push = SkyFilterPush {
        camera: camera.extend(0.0).to_array(),
        extent: receivers.extent,
        radius: reach.radius,
        depth_sigma: upsample.depth_sigma,
        normal_power: upsample.normal_power,
        sigma_per_radius: reach.sigma_per_radius,
        world_sigma: reach.world_sigma,
        pad: 0,
    };
    rg.compute(name, &shaders::SKY_FILTER_COMP)
        .read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("sky_irradiance", light)
        .write("sky", &mut out)
        .push(&push)
        .dispatch([w, h, 1]);
    out
}

/// One receiver's inputs to [`bilateral_cpu`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BilateralTexel {
    /// xyz world position, w view depth (0: background).
    pub position: [f32; 4],
    /// Shading normal (xyz).
    pub normal: [f32; 4],
    /// Albedo (RGB).
    pub albedo: [f32; 3],
    /// Metallic.
    pub metallic: f32,
    /// The demodulated light to filter (RGB, light over π).
    pub light: [f32; 3],
}

/// CPU twin of `sky_filter.comp` ([`bilateral_filter`]) over a `width`-wide row-major image
/// seen from `camera`: each receiver's outgoing radiance `kd` times the joint bilateral mean
/// of `light` as far as `reach`, 0 on background.
pub fn bilateral_cpu(
    texels: &[BilateralTexel],
    width: usize,
    camera: glam::Vec3,
    reach: BilateralReach,
    upsample: &UpsampleParams,
) -> Vec<[f32; 3]> {
    let BilateralReach {
        radius,
        sigma_per_radius,
        world_sigma,
    } = reach;
    use glam::Vec3;
    let height = texels.len() / width.max(1);
    let r = radius as i64;
    let sigma = sigma_per_radius * radius as f32;
    let inv_two_sigma2 = if r > 0 { 0.5 / (sigma * sigma) } else { 0.0 };
    let xyz = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]);
    let mut out = vec![[0.0; 3]; texels.len()];
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            let centre = &texels[y as usize * width + x as usize];
            let n = xyz(centre.normal);
            if !on_surface(centre.position) || n.length_squared() <= 0.0 {
                continue;
            }
            let n = n.normalize();
            let n4 = n.extend(0.0).to_array();
            let (mut sum, mut weight_sum) = (Vec3::ZERO, 0.0f32);
            for dy in -r..=r {
                for dx in -r..=r {
                    let (cx, cy) = (x + dx, y + dy);
                    if cx < 0 || cy < 0 || cx >= width as i64 || cy >= height as i64 {
                        continue;
                    }
                    let q = &texels[cy as usize * width + cx as usize];
                    if !on_surface(q.position) {
                        continue;
                    }
                    let mut w = (-((dx * dx + dy * dy) as f32) * inv_two_sigma2).exp();
                    if world_sigma > 0.0 {
                        let d = xyz(q.position) - xyz(centre.position);
                        w *= (-d.length_squared() / (2.0 * world_sigma * world_sigma)).exp()
                            * bilateral_plane_match(
                                centre.position,
                                n4,
                                q.position,
                                q.normal,
                                upsample,
                            );
                    } else {
                        w *= bilateral_match(
                            centre.position[3],
                            n4,
                            q.position[3],
                            q.normal,
                            upsample,
                        );
                    }
                    sum += w * Vec3::from(q.light);
                    weight_sum += w;
                }
            }
            let light = if weight_sum > 0.0 {
                sum / weight_sum
            } else {
                Vec3::from(centre.light)
            };
            let view = (camera - xyz(centre.position)).normalize();
            let (kd, _) = indirect_weights(Vec3::from(centre.albedo), centre.metallic, n.dot(view));
            out[y as usize * width + x as usize] = (kd * light).to_array();
        }
    }
    out
}

/// One pass `name` of `shader` (a variant of `sky.comp`) over `receivers` with `bvh`, the
/// inputs `extra` binds, and the rays of `params` (their seed plus `seed`); writes and returns
/// a new RGBA16F image `output` at receiver resolution.
#[allow(clippy::too_many_arguments)]
fn trace_pass(
    rg: &mut RenderGraph,
    name: &str,
    output: &str,
    shader: &'static crate::gpu::ShaderDesc,
    receivers: &Receivers,
    bvh: &TraceImages,
    params: &SkyParams,
    seed: u32,
    extra: impl FnOnce(&mut crate::graph::ComputePass<'_>),
) -> Handle<Image> {
    let push = SkyPush {
        extent: receivers.extent,
        rays: params.rays,
        seed: params.seed.wrapping_add(seed),
        bent_normal: u32::from(params.bent_normal),
        range: params.range,
        pad: [0; 2],
    };
    let [w, h] = receivers.extent;
    let mut out = receivers.light_image(rg, output);
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal);
    extra(&mut pass);
    bvh.bind(&mut pass);
    pass.write("sky", &mut out).push(&push).dispatch([w, h, 1]);
    out
}

/// Default reach of the cavity rays, as a fraction of the scene's largest side.
pub const CAVITY_RANGE: f32 = 0.02;
/// Cavity ranges the settings take (fractions of the scene's largest side).
pub const CAVITY_RANGE_RANGE: RangeInclusive<f32> = 1e-4..=1.0;
/// Default cavity rays per receiver.
pub const CAVITY_RAYS: u32 = 8;

/// Adds the `cavity` pass (paper 001's cavity shading, issue 18): `light` (RGBA16F at receiver
/// resolution: HVL's unshadowed indirect light) times each receiver's visibility over
/// `params.rays` cosine-weighted rays through `bvh` up to `params.range` (world units, > 0).
/// Returns the darkened light.
pub fn cavity(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    light: &Handle<Image>,
    bvh: &TraceImages,
    params: &SkyParams,
    seed: u32,
) -> Result<Handle<Image>, SkyError> {
    params.validate()?;
    let shader = &shaders::SKY_COMP_CAVITY;
    Ok(trace_pass(
        rg,
        "cavity",
        "cavity_light",
        shader,
        receivers,
        bvh,
        params,
        seed,
        |pass| {
            pass.read("light", light);
        },
    ))
}
