//! HVL's near field: light from surfaces within `2R` of a receiver, traced
//! (`shaders/hvl_near.comp`), where HVLs are blind.
//!
//! An HVL's sphere caps its light near its centre (paper 003's eq. 20–22 stand for a patch
//! tens of centimetres wide), so a receiver a few centimetres from a lit wall gets little of
//! that wall's light: on the cornell box the floor's front corners sat at 0.4 of the truth and
//! the bases of the boxes at 0.7–0.8, while point lights without a clamp (IGI) have them right.
//! The fix splits every sender point by its distance `t` from the receiver with
//! `f(t) = smoothstep(R, 2R, t)`: the gather scales each HVL's light by `f` of its centre's
//! distance ([`super::HvlParams::near_radius`]), and `hvl_near` traces [`NearField::rays`]
//! cosine-weighted rays up to `2R`, each hit sending `(1 − f(t))` of what it reflects from the
//! punctual lights (next-event estimation with shadow rays). That is Kollig and Keller's bias
//! compensation (2004, "Illumination in the presence of weak singularities") with a smooth
//! boundary. The traced light is demodulated (with the rays' mean hit distance, which sets the
//! denoiser's footprint), filtered by one of the sky's filters
//! ([`crate::passes::sky::LightFilter`]: the joint bilateral by default, its match measured
//! off the receiver's tangent plane and bounded in world space by [`WORLD_SIGMA_PER_RANGE`],
//! or the à-trous
//! denoiser's diffuse variant with `denoise.near_field`, which flickered more on moving
//! figures; then `kd`), and added to the gather's. Diffuse only: the receiver's glossy lobe
//! sees the near field through the HVLs alone.

use std::ops::RangeInclusive;

use crate::graph::{Handle, Image, RenderGraph};
use crate::passes::denoise::{DenoiseError, Footprint, NEAR_FOOTPRINT_PER_HIT, pixel_angle};
use crate::passes::gbuffer::View;
use crate::passes::receivers::Receivers;
use crate::passes::sky::{BilateralReach, LightFilter, Reach};
use crate::passes::traced_scene::TracedScene;
use crate::shaders;

/// Default R of the near field (HVL's and IGI's) as a fraction of the scene's largest side.
/// 0.1 (HVL's was 0.05 before issue 43's session 10; IGI had none): on the cornell box's
/// still frame HVL's error fell 0.160 → 0.135 and IGI's 0.294 → 0.133, and cold flicker fell
/// on every motion scene. Wider ranges cut the flicker further but leave blobs of the four
/// rays' noise where a small bright patch lies within 2R (`builtin:animated`'s lamp on its
/// wall; docs/quality.md, issue 43, change 11).
pub const RANGE: f32 = 0.1;
/// R (fractions of the scene's largest side) the settings take; 0: no near field.
pub const RANGE_RANGE: RangeInclusive<f32> = 0.0..=0.5;
/// Default rays per receiver. 8 were tried with the filter's world reach (issue 43, change 13):
/// on the motion scenes they lowered the error further (HVL at t = 0.5 s: `sun` 0.221 →
/// 0.215, `crossing` 0.208 → 0.177) for +21 ms of `hvl_near` at 256², but on
/// `builtin:animated`, a scene they were not chosen on, one ray in 8 found its lamp's small
/// bright patch and the filter spread it into a blob (64², t = 0.5 s: 0.518 → 0.607, energy
/// 1.045 → 1.071; 16 and 32 rays 0.519 and 0.515). Such a patch is a firefly for any few
/// rays; 4 stay the default (docs/quality.md).
pub const RAYS: u32 = 4;
/// Rays per receiver the settings take.
pub const RAYS_RANGE: RangeInclusive<u32> = 1..=256;
/// Default radius of the near field's bilateral filter, in receivers.
pub const FILTER_RADIUS: u32 = 4;
/// σ of the near field filter's gaussian over its radius (the sky's is 1/2: the near field's
/// few rays need the wider mean).
pub const SIGMA_PER_RADIUS: f32 = 1.0;
/// σ of the near field filter's gaussian over the receivers' world distance, over R (issue
/// 43, change 13). The near field changes within R of the surfaces it sees, but the filter's
/// 9×9 receivers reach metres along a floor seen at a grazing angle, and across a whole wall at
/// 64²; with the plane match (`bilateral_plane_match`) in place of the depth match, this reach
/// keeps the rows of a grazing floor together (their stripes flickered on `crossing`) and
/// bounds the blur. HVL's single frames at t = 0.5 s, 4 rays: `sun` 0.268 → 0.221, `sweep`
/// 0.177 → 0.167; at σ = R 0.272 and 0.187, without the reach (the plane match alone) 0.317
/// and 0.208 (docs/quality.md).
pub const WORLD_SIGMA_PER_RANGE: f32 = 0.5;

/// The near field a frame asks for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearField {
    /// R as a fraction of the scene's largest side (rays reach 2R).
    pub range_fraction: f32,
    /// Rays per receiver.
    pub rays: u32,
    /// Radius in receivers of the bilateral filter (unused by the à-trous denoiser).
    pub filter_radius: u32,
}

impl NearField {
    /// The near field a technique's `near_range` and `near_rays` ask for; `None` at range 0.
    pub fn asked(range_fraction: f32, rays: u32) -> Option<Self> {
        (range_fraction > 0.0).then_some(Self {
            range_fraction,
            rays,
            ..Self::default()
        })
    }
}

impl Default for NearField {
    fn default() -> Self {
        Self {
            range_fraction: RANGE,
            rays: RAYS,
            filter_radius: FILTER_RADIUS,
        }
    }
}

/// Push constants of `shaders/hvl_near.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct NearPush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Rays per receiver.
    pub rays: u32,
    /// Seed of the rays.
    pub seed: u32,
    /// Lights in the light buffer.
    pub light_count: u32,
    /// R (world units).
    pub range: f32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Adds `hvl_near` and its filter `filter` (`hvl_near_filter`, or `hvl_near_prep` and
/// `hvl_near_atrous_i`) over `receivers` seen from `camera`, with R = `range` world units and
/// the rays of `seed`: returns the near field's outgoing radiance (RGBA16F at receiver
/// resolution), to be added to the gather's (which must have run with `near_radius = range`).
#[allow(clippy::too_many_arguments)]
pub fn hvl_near(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    traced: &TracedScene<'_>,
    near: &NearField,
    range: f32,
    seed: u32,
    camera: &View,
    filter: LightFilter<'_>,
) -> Result<Handle<Image>, DenoiseError> {
    let [w, h] = receivers.extent;
    let mut light = receivers.light_image(rg, "hvl_near_irradiance");
    let push = NearPush {
        extent: receivers.extent,
        rays: near.rays,
        seed,
        light_count: traced.light_count,
        range,
        pad: [0; 2],
    };
    let mut pass = rg.compute("hvl_near", &shaders::HVL_NEAR_COMP);
    traced.bind_surfaces(&mut pass);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .write("near_light", &mut light)
        .push(&push)
        .dispatch([w, h, 1]);
    filter.apply(
        rg,
        ["hvl_near", "hvl_near_light"],
        receivers,
        &light,
        camera.eye,
        Reach {
            bilateral: BilateralReach {
                radius: near.filter_radius,
                sigma_per_radius: SIGMA_PER_RADIUS,
                world_sigma: range * WORLD_SIGMA_PER_RANGE,
            },
            footprint: Footprint::HitDistance {
                scale: NEAR_FOOTPRINT_PER_HIT,
                pixel_angle: pixel_angle(camera, receivers.extent[1]),
            },
        },
    )
}
