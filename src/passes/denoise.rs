//! The denoiser of the traced signals (issue 47): `specular_prep` and `denoise_atrous`
//! (`shaders/specular_prep.comp`, `shaders/denoise_atrous.comp`, formulas in
//! `shaders/include/denoise.glsl`; CPU twin [`crate::reference::denoise`]).
//!
//! At one sample per pixel (`--ssaa 1`, a host's real-time frame) the specular pass's two
//! reflection rays leave a rough metal salt-and-pepper and a glossy floor speckled. The filter
//! is SVGF's edge-stopping à-trous (Schied et al. 2017) with the spatial reach of NRD's
//! specular filters (hit-distance-driven radius):
//!
//! 1. **specular_prep**: the radiance divided by `share · ks` (the trace share of the lobe and
//!    Schlick's Fresnel at n·v, the albedo's colour), so texture and colour stay sharp; a
//!    firefly clamp (a pixel's luminance at most twice the largest of its 3×3 neighbours on
//!    the same surface); the 3×3 luminance variance; the footprint radius
//!    `r = tan θ · max(d / (z + d), ½) / pixel angle` in pixels, θ the reflected lobe's median
//!    half-angle (twice the GGX half vector's, `tan θ_h = α`), `d / (z + d)` the parallax of
//!    the hits the specular pass stores (at least ½: what touches the receiver is seen sharp,
//!    but two rays leave it as noisy as the rest).
//! 2. **denoise_atrous** × [`DenoiseParams::iterations`]: 5×5 B3 taps spaced 2^i, weighted by
//!    the footprint's gaussian (σ = r), the tangent-plane distance, the normals (within the
//!    lobe's angle: `exp(−(1 − n_p·n_q) / (1 − cos θ))`, so a curved mirror's neighbours,
//!    which reflect other directions, stay apart), the roughness and SVGF's luminance weight;
//!    the variance filtered with the squared weights. The last iteration multiplies by
//!    `share · ks` again.
//!
//! Measured (docs/quality.md): `builtin:metals` at one sample, the gold sphere (roughness 0.3)
//! 0.341 → 0.204 of the truth, the chrome one unchanged; 4–8% of a 256² frame on lavapipe.
//!
//! # Decisions
//!
//! * **Where the radius comes from.** A mirror (r < ½ pixel) keeps its own pixel, so sharp
//!   reflections stay sharp; a rough lobe whose hits lie far away blurs as far as its
//!   reflection does. The lobe's median (`denoise.glsl`'s `DENOISE_LOBE_FRACTION`) rather than
//!   its full width: the filter's gaussian then spans about the lobe's half-energy cone.
//! * **Demodulation by `ks`**, Schlick's F at the mirror direction, not a pre-integrated GGX
//!   table: the factor only has to be the same on the way in and out; between neighbours it
//!   differs by their colour and view angle, which is what must not blur.
//! * **Spatial variance** (3×3) rather than SVGF's temporal moments: the frame's history comes
//!   after the composite (`[history]`), and a single frame or a camera cut has none.
//! * **Orthographic views** take the pixel's width over one metre as its angle (a
//!   perspective stand-in; no built-in camera is orthographic).
//! * The sky and HVL's near field keep their joint bilateral filter (`sky_filter.comp`) at
//!   receiver resolution; this filter serves the full-resolution specular.

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};
use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::{GBuffer, View};
use crate::shaders;

/// Default à-trous iterations (tap spacing 1, 2, 4: a reach of 14 pixels).
pub const ITERATIONS: u32 = 3;
/// Iterations the settings take.
pub const ITERATIONS_RANGE: RangeInclusive<u32> = 1..=5;

/// `[denoise]`: the edge-stopping filter of the traced specular (issue 47): its parameters,
/// each declared once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct DenoiseParams {
    /// Filter the traced specular (off: its samples as traced).
    #[setting(default = true, affects = both)]
    pub enabled: bool,
    /// À-trous iterations; iteration i spaces its 5×5 taps 2^i pixels apart.
    #[setting(default = ITERATIONS, range = ITERATIONS_RANGE, affects = both)]
    pub iterations: u32,
    /// Clamp fireflies: a pixel's luminance at most twice the largest of its 3×3 neighbours on
    /// the same surface.
    #[setting(default = true, affects = quality)]
    pub clamp: bool,
}

/// What the denoiser refuses.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DenoiseError {
    /// A parameter out of its range.
    #[error("denoise: {0}")]
    OutOfRange(#[from] crate::declare::OutOfRange),
}

impl DenoiseParams {
    /// Checks every parameter against its range.
    pub fn validate(&self) -> Result<(), DenoiseError> {
        Ok(self.check_in("denoise.")?)
    }
}

/// Push constants of `shaders/specular_prep.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PrepPush {
    /// xyz: camera position; w: the specular pass's roughness limit.
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// Angle one pixel subtends at the eye ([`pixel_angle`]).
    pub pixel_angle: f32,
    /// 1: the firefly clamp on.
    pub clamp: u32,
}

/// Push constants of `shaders/denoise_atrous.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AtrousPush {
    /// xyz: camera position; w: the specular pass's roughness limit.
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// Tap spacing 2^i.
    pub step: u32,
    /// 1: the last iteration, remodulated.
    pub remodulate: u32,
}

/// The angle one pixel of a `height`-pixel image of `view` subtends at the eye: `2 tan(fov/2)
/// / height` (perspective); an orthographic view's pixel width over a metre.
pub fn pixel_angle(view: &View, height: u32) -> f32 {
    let h = height.max(1) as f32;
    if view.orthographic {
        view.extent / h
    } else {
        2.0 * (0.5 * view.extent).tan() / h
    }
}

/// Adds `specular_prep` and the à-trous iterations over `specular` (the specular pass's
/// output with its parallax in alpha, `specular.config.z = 1`) of the G-buffer `g` seen from
/// `view`, whose roughness limit was `limit`; returns the filtered radiance (RGBA16F, a = 0).
pub fn specular(
    rg: &mut RenderGraph,
    g: &GBuffer,
    specular: &Handle<Image>,
    view: &View,
    limit: f32,
    params: &DenoiseParams,
) -> Result<Handle<Image>, DenoiseError> {
    params.validate()?;
    let [w, h] = g.extent;
    let camera = view.eye.extend(limit).to_array();
    let image = |rg: &mut RenderGraph, name: &str| {
        rg.create_image(
            name,
            ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
        )
    };
    let mut signal = image(rg, "denoise_signal");
    let mut radius = image(rg, "denoise_footprint");
    rg.compute("specular_prep", &shaders::SPECULAR_PREP_COMP)
        .read("specular", specular)
        .read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_albedo", &g.albedo)
        .read("gb_material", &g.material)
        .write("denoise_signal", &mut signal)
        .write("denoise_footprint", &mut radius)
        .push(&PrepPush {
            camera,
            extent: g.extent,
            pixel_angle: pixel_angle(view, h),
            clamp: u32::from(params.clamp),
        })
        .dispatch([w, h, 1]);
    for i in 0..params.iterations {
        let last = i + 1 == params.iterations;
        let mut out = image(
            rg,
            if last {
                "specular_denoised"
            } else {
                "denoise_signal"
            },
        );
        rg.compute(
            &format!("denoise_atrous_{i}"),
            &shaders::DENOISE_ATROUS_COMP,
        )
        .read("denoise_in", &signal)
        .read("denoise_footprint", &radius)
        .read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_albedo", &g.albedo)
        .read("gb_material", &g.material)
        .write("denoise_out", &mut out)
        .push(&AtrousPush {
            camera,
            extent: g.extent,
            step: 1 << i,
            remodulate: u32::from(last),
        })
        .dispatch([w, h, 1]);
        signal = out;
    }
    Ok(signal)
}
