//! Traced specular reflections (issue 21, item 3): the `specular` pass
//! (`shaders/specular.comp`).
//!
//! The SH techniques carry a receiver's glossy lobe through band-limited tables (HVL's gather,
//! IGI's filter) or not at all (the proxies), so a lobe sharper than their band limit comes out
//! as a blurred average of the scene: the chrome torus of `room` turned grey, the metal torus of
//! `spheres` black. This pass takes the sharp part of every lobe instead: per G-buffer pixel,
//! [`SpecularParams::samples`] GGX-sampled reflection rays through the BVH, each seeing
//! next-event estimation to the punctual lights at its hit or the environment where it escapes
//! (the one-bounce light of the path-traced reference), weighted by [`trace_weight`] of the
//! pixel's roughness. The techniques scale their glossy term by `1 − trace_weight`, so each part
//! of a lobe is counted once: rough lobes stay with the SH tables, sharp ones are traced.
//!
//! # Decisions
//!
//! * Full resolution (reflections move with the view and change within a pixel); the frame's
//!   history ([`crate::passes::accumulate`]) averages the noise of successive frames, whose
//!   seeds differ when there is a history (without one, changing noise would only add
//!   flicker).
//! * One bounce: the hit is lit by the punctual lights (shadow rays) and, in a scene with an
//!   environment, by one cosine-sampled ray towards it; not by its own indirect light or
//!   emission, as the GI techniques' convention. Rays that escape see the environment.
//! * [`LIMIT`] (0.5): on `room` and `spheres` FLIP against the truth barely moves between 0.5
//!   and 1.0, while at 0.3 the brushed torus of `spheres` (0.35) goes black under the proxies
//!   again (docs/quality.md); rougher lobes need more rays for the same noise. [`FADE`] (0.1)
//!   blends the traced and the SH glossy term over a range of roughness so no seam shows.

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};

use crate::graph::{Buffer, BufferDesc, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::GBuffer;
use crate::passes::traced_scene::TracedScene;
use crate::shaders;

/// Default roughness limit: lobes rougher than this are left to the SH techniques.
pub const LIMIT: f32 = 0.5;
/// Width of the roughness range over which the traced share fades from 1 to 0 (GLSL
/// `SPECULAR_FADE`).
pub const FADE: f32 = 0.1;
/// Roughness limits the settings take.
pub const LIMIT_RANGE: RangeInclusive<f32> = 0.0..=1.0;
/// Default reflection rays per pixel and frame.
pub const SAMPLES: u32 = 2;
/// Reflection rays per pixel the settings take.
pub const SAMPLES_RANGE: RangeInclusive<u32> = 1..=256;
/// Most rays of a pixel one dispatch traces: more are split over dispatches that carry the
/// sums in f32 (`specular.comp`'s variants). lavapipe ends every loop of an invocation after
/// 65 535 iterations in all (docs/pitfalls.md), and each ray's traversals are loops: on
/// builtin:metals at 256 rays a pixel, the spheres' pixels that see each other kept 156–206 of
/// their rays and came out up to a third too dark. 16, as the path tracer's
/// `MAX_SAMPLES_PER_DISPATCH`.
pub const RAYS_PER_DISPATCH: u32 = 16;

/// `[specular]`: reflection rays for the sharp part of every glossy lobe (issue 21), in every
/// frame with a GI technique; the techniques keep the lobes rougher than `limit`. The
/// specular pass's parameters, each declared once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct SpecularParams {
    /// Trace the reflections (off: the techniques' SH glossy term takes every lobe, and the
    /// proxies none).
    #[setting(default = true, affects = both)]
    pub enabled: bool,
    /// Reflection rays per pixel and frame.
    #[setting(default = SAMPLES, range = SAMPLES_RANGE, affects = both)]
    pub samples: u32,
    /// Roughness above which a lobe is left to the SH techniques ([`trace_weight`]: faded
    /// over the [`FADE`] below it).
    #[setting(default = LIMIT, range = LIMIT_RANGE, affects = both)]
    pub limit: f32,
    /// Share the frame's `samples` × traced-pixels rays by the lobes' widths (each pixel one,
    /// the rest by claim, at most 4 × `samples`; `specular_budget`) instead of `samples` each;
    /// a lobe too narrow for the denoiser to widen (tan θ under `DENOISE_RAY_KEEP_TAN`, a
    /// mirror) keeps its `samples` on top of the budget. On builtin:metals at one sample the
    /// gold sphere 0.201 → 0.194 of the truth, the chrome one unchanged (docs/quality.md).
    #[setting(default = true, affects = both)]
    pub adaptive: bool,
    /// Path regularisation (Kaplanyan and Dachsbacher 2013, as `aaf.hit_roughness_min`): a
    /// reflection ray's hit is shaded with a lobe no sharper than the receiver's, so a light's
    /// highlight on a mirror, seen in a rough floor, is the blur the floor's lobe makes of it
    /// anyway rather than a firefly one ray in hundreds finds. On builtin:metals at one
    /// sample the gold sphere (roughness 0.3, beside the mirrors) 0.195 → 0.154 of the
    /// path-traced truth, which is not regularised (docs/quality.md).
    #[setting(default = true, affects = quality)]
    pub regularise: bool,
    /// Seed of the random numbers (set by the frame).
    #[serde(skip)]
    #[setting(default = 0)]
    pub seed: u32,
}

impl SpecularParams {
    /// The roughness limit of the traced pass in a frame with indirect light: `limit` when the
    /// pass is enabled, 0 (no pass) otherwise. The GI techniques leave the lobes below it out.
    pub fn traced_limit(&self) -> f32 {
        if self.enabled {
            self.limit.max(0.0)
        } else {
            0.0
        }
    }
}

/// What the specular pass refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SpecularError {
    /// A parameter out of its range.
    #[error("specular: {0}")]
    OutOfRange(#[from] crate::declare::OutOfRange),
}

impl SpecularParams {
    /// Checks every parameter against its range.
    pub fn validate(&self) -> Result<(), SpecularError> {
        Ok(self.check_in("specular.")?)
    }
}

/// Share of a lobe of perceptual `roughness` that the pass traces, for a roughness `limit`
/// (0: no pass): 1 up to `limit − FADE`, a smoothstep down to 0 at `limit`. GLSL twin:
/// `specular_trace_weight` in `shaders/include/brdf.glsl`.
pub fn trace_weight(roughness: f32, limit: f32) -> f32 {
    if limit <= 0.0 {
        return 0.0;
    }
    let t = ((roughness - (limit - FADE)) / FADE).clamp(0.0, 1.0);
    1.0 - t * t * (3.0 - 2.0 * t)
}

/// Push constants of `shaders/specular.comp` (64 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SpecularPush {
    /// Width, height, light count, seed.
    pub frame: [u32; 4],
    /// xyz camera position, w the roughness limit.
    pub camera: [f32; 4],
    /// Samples per pixel, 1 when the environment lights the hits, 1 to store the hits'
    /// parallax in alpha (the denoiser follows), 1 to share the rays by the lobes' widths
    /// ([`SpecularParams::adaptive`]).
    pub config: [u32; 4],
    /// 1 to regularise the paths ([`SpecularParams::regularise`]), then padding.
    pub options: [u32; 4],
}

/// The most rays one pixel takes in a frame of `params`: `samples`, or with the shared budget
/// `DENOISE_RAY_MAX_FACTOR` times it (a mirror's kept rays are at most `samples`).
pub fn max_rays(params: &SpecularParams) -> u32 {
    let samples = params.samples.max(1);
    if params.adaptive {
        (crate::reference::denoise::RAY_MAX_FACTOR * samples as f32) as u32
    } else {
        samples
    }
}

/// Push constants of `shaders/specular_budget.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BudgetPush {
    /// xyz camera position, w the roughness limit.
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// 8×8 tiles per row.
    pub tiles_x: u32,
    /// Padding.
    pub pad: u32,
}

/// Adds `specular_budget` and `specular_budget_total` over `g`: the frame's total claim on
/// the specular rays and its traced pixels (two f32), which the specular pass shares its rays
/// by when [`SpecularParams::adaptive`].
fn budget(
    rg: &mut RenderGraph,
    g: &GBuffer,
    camera: glam::Vec3,
    params: &SpecularParams,
) -> Handle<Buffer> {
    let tiles = g.extent.map(|e| e.div_ceil(8));
    let count = tiles[0] * tiles[1];
    let mut tile_sums = rg.create_buffer("budget_tiles", BufferDesc::new(8 * u64::from(count)));
    rg.compute("specular_budget", &shaders::SPECULAR_BUDGET_COMP)
        .read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_material", &g.material)
        .write("budget_tiles", &mut tile_sums)
        .push(&BudgetPush {
            camera: camera.extend(params.limit).to_array(),
            extent: g.extent,
            tiles_x: tiles[0],
            pad: 0,
        })
        .dispatch([g.extent[0], g.extent[1], 1]);
    let mut total = rg.create_buffer("budget", BufferDesc::new(8));
    rg.compute(
        "specular_budget_total",
        &shaders::SPECULAR_BUDGET_TOTAL_COMP,
    )
    .read("budget_tiles", &tile_sums)
    .write("budget", &mut total)
    .push(&count)
    .dispatch([64, 1, 1]);
    total
}

/// Adds the `specular` pass over the G-buffer `g` seen from `camera`; returns the reflected
/// radiance towards the camera (RGBA16F, full resolution; a = the hits' mean parallax
/// d / (z + d) when `parallax`, for [`crate::passes::denoise::specular`], else 0). `seed` is
/// added to the parameters' (the frame index when a history averages the frames).
pub fn specular(
    rg: &mut RenderGraph,
    g: &GBuffer,
    scene: &TracedScene<'_>,
    camera: glam::Vec3,
    params: &SpecularParams,
    seed: u32,
    parallax: bool,
) -> Result<Handle<Image>, SpecularError> {
    params.validate()?;
    let [w, h] = g.extent;
    let frame_seed = params.seed.wrapping_add(seed);
    let mut out = rg.create_image(
        "specular",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let budget = if params.adaptive {
        budget(rg, g, camera, params)
    } else {
        // Not read without `adaptive`: a zeroed placeholder fills the binding.
        let mut unused = rg.create_buffer("budget", BufferDesc::new(8));
        rg.fill_buffer("budget_unused", &mut unused, 0);
        unused
    };
    let push = |first: u32| SpecularPush {
        frame: [w, h, scene.light_count, frame_seed],
        camera: camera.extend(params.limit).to_array(),
        config: [
            params.samples,
            u32::from(scene.environment_lighting),
            u32::from(parallax),
            u32::from(params.adaptive),
        ],
        options: [u32::from(params.regularise), first, RAYS_PER_DISPATCH, 0],
    };
    let dispatches = max_rays(params).div_ceil(RAYS_PER_DISPATCH).max(1);
    let mut carried: Option<(Handle<Image>, Handle<Image>)> = None;
    for i in 0..dispatches {
        let last = i + 1 == dispatches;
        let shader = match (i == 0, last) {
            (true, true) => &shaders::SPECULAR_COMP_WHOLE,
            (true, false) => &shaders::SPECULAR_COMP_FIRST,
            (false, false) => &shaders::SPECULAR_COMP_MIDDLE,
            (false, true) => &shaders::SPECULAR_COMP_LAST,
        };
        let mut next = (!last).then(|| {
            let image = |rg: &mut RenderGraph, name: &str, format| {
                rg.create_image(name, ImageDesc::new_2d(format, w, h))
            };
            (
                image(rg, "partial_sum", vk::Format::R32G32B32A32_SFLOAT),
                image(rg, "partial_met", vk::Format::R32_SFLOAT),
            )
        });
        let name = if dispatches == 1 {
            "specular".to_string()
        } else {
            format!("specular_{i}")
        };
        let mut pass = rg.compute(&name, shader);
        scene.bind(&mut pass);
        pass.read("gb_position", &g.position)
            .read("gb_normal", &g.normal)
            .read("gb_geometric_normal", &g.geometric_normal)
            .read("gb_albedo", &g.albedo)
            .read("gb_material", &g.material)
            .read("budget", &budget);
        if let Some((sum, met)) = &carried {
            pass.read("partial_sum_in", sum).read("partial_met_in", met);
        }
        match &mut next {
            Some((sum, met)) => pass.write("partial_sum", sum).write("partial_met", met),
            None => pass.write("specular", &mut out),
        };
        pass.push(&push(i * RAYS_PER_DISPATCH)).dispatch([w, h, 1]);
        carried = next;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trace_weight_fades_over_the_last_tenth_below_the_limit() {
        assert_eq!(trace_weight(0.05, 0.0), 0.0);
        assert_eq!(trace_weight(0.3, LIMIT), 1.0);
        assert_eq!(trace_weight(LIMIT - FADE, LIMIT), 1.0);
        assert!((trace_weight(LIMIT - 0.5 * FADE, LIMIT) - 0.5).abs() < 1e-6);
        assert_eq!(trace_weight(LIMIT, LIMIT), 0.0);
        assert_eq!(trace_weight(0.9, LIMIT), 0.0);
        let mut last = 1.0;
        for i in 0..=100 {
            let w = trace_weight(i as f32 / 100.0, LIMIT);
            assert!(w <= last && (0.0..=1.0).contains(&w));
            last = w;
        }
    }
}
