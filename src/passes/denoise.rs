//! The denoiser of the traced signals (issue 47): a prep pass and `denoise_atrous`
//! (`shaders/denoise_prep.comp`, `shaders/denoise_atrous.comp`, each in a `specular` and a
//! `diffuse` variant; formulas in `shaders/include/denoise.glsl`; CPU twin
//! [`crate::reference::denoise`]). One pass family for every traced part: the specular
//! ([`specular`]: `specular_prep`, `denoise_atrous_i`), the sky's visibility and HVL's near
//! field ([`diffuse`]: `sky_prep`, `sky_atrous_i`, `hvl_near_prep`, `hvl_near_atrous_i`).
//!
//! At one sample per pixel (`--ssaa 1`, a host's real-time frame) the specular pass's two
//! reflection rays leave a rough metal salt-and-pepper and a glossy floor speckled. The filter
//! is SVGF's edge-stopping à-trous (Schied et al. 2017) with the spatial reach of NRD's
//! specular filters (hit-distance-driven radius):
//!
//! 1. **specular_prep**: the radiance divided by `share · ks` (the trace share of the lobe and
//!    Schlick's Fresnel at n·v, the albedo's colour), so texture and colour stay sharp; a
//!    firefly clamp (a pixel's luminance at most twice the largest of its 3×3 neighbours on
//!    the same surface whose lobe is no wider than its own, whatever the roughness test: a
//!    tile's edge pixel of its own roughness is bounded too); the 3×3 luminance variance; the
//!    footprint radius
//!    `r = tan θ · max(d / (z + d), ½) / pixel angle` in pixels, θ the reflected lobe's median
//!    half-angle (twice the GGX half vector's, `tan θ_h = α`), `d / (z + d)` the parallax of
//!    the hits the specular pass stores (at least ½: what touches the receiver is seen sharp,
//!    but two rays leave it as noisy as the rest).
//! 2. **denoise_atrous** × [`DenoiseParams::iterations`]: 5×5 B3 taps spaced 2^i, weighted by
//!    the footprint's gaussian (σ = r), the tangent-plane distance, the normals (within the
//!    lobe's angle: `exp(−(1 − n_p·n_q) / (1 − cos θ))`, so a curved mirror's neighbours,
//!    which reflect other directions, stay apart), the roughness and SVGF's luminance weight
//!    (over the centre's variance prefiltered by a 3×3 gaussian, SVGF eq. 5); the variance
//!    filtered with the squared weights. The last iteration multiplies by `share · ks` again.
//!
//! A **sharp** footprint (`r` under `DENOISE_SHARP_RADIUS`, half a pixel: a mirror's rays meet
//! within the pixel and agree) is neither clamped nor filtered: the last iteration writes the
//! traced value back as it came, bit for bit.
//!
//! The **diffuse variant** takes the sky's `A · L̃(b) / π` and the near field's `E_near / π`,
//! demodulated already (their receivers' `kd` comes back in the last iteration, so textures
//! stay sharp), at receiver resolution, with a diffuse footprint ([`Footprint`]): for a
//! cosine-weighted signal the "lobe" is the hemisphere, so no angle bounds the reach. The near
//! field's radius is [`NEAR_FOOTPRINT_PER_HIT`] times its rays' mean hit distance (the pass
//! writes it in alpha; NRD's diffuse filters do the same), seen from the eye; the sky's is a
//! stated [`SKY_RADIUS`] receivers, since its open rays have no hit distance. The normal
//! weight is the receivers' upsample match (`DENOISE_DIFFUSE_NORMAL_TOLERANCE`), no roughness
//! test, no firefly clamp, and the luminance weight divides by the larger of the two pixels'
//! deviations (symmetric; over the centre's alone, SVGF's, a few rays' skewed signal lost
//! energy: the dark majority refuses the rare bright samples).
//!
//! Measured (docs/quality.md): `builtin:metals` at one sample, the gold sphere (roughness 0.3)
//! 0.341 → 0.201 of the truth (0.194 with the default shared rays, `specular.adaptive`; 0.154
//! with the regularised paths, `specular.regularise`), the chrome one unchanged; 4–8% of a
//! 256² frame on lavapipe.
//! The diffuse variant against the bilateral, `builtin:animated` at one sample: the orange
//! wall 0.145 → 0.143 of the truth (noise-free), 0.070 → 0.060 of the same renderer at 1024
//! sky and 256 near rays.
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
//! * **The sky and HVL's near field go through this filter too** (`denoise.diffuse` for the
//!   sky, on by default; `denoise.near_field` for the near field, off by default; off: their
//!   joint bilateral, `sky_filter.comp`, as before issue 47's second part). It beat the
//!   bilateral on every scene measured, against the path-traced truth and against the same
//!   renderer with many rays, and leaves no mottle on large matte walls; but on the near field
//!   it flickered more on a moving figure (`builtin:animated` 0.74× → 0.79× of the truth's
//!   flicker; the sky alone 0.74×), which issue 47 forbids, so the near field keeps the
//!   bilateral unless asked.
//! * **Receiver resolution** for the diffuse signals, where they are traced and summed before
//!   the upsample: each receiver holds its own rays, so neighbours' noise is independent there
//!   (at full resolution the upsample copies a receiver's noise into s × s pixels, which the
//!   3×3 variance would take for signal), and it costs 1/s² of a full-resolution filter.

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};
use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::{GBuffer, View};
use crate::passes::receivers::Receivers;
use crate::shaders;

/// Default à-trous iterations (tap spacing 1, 2, 4: a reach of 14 pixels).
pub const ITERATIONS: u32 = 3;
/// Iterations the settings take.
pub const ITERATIONS_RANGE: RangeInclusive<u32> = 1..=5;
/// The sky visibility's footprint radius (the gaussian's σ), in receivers: a stated radius,
/// the sky pass keeps no hit distances (its open rays have none). Tried at 2, 3 and 4 with the
/// near field at the same radius: `builtin:animated`'s orange wall against the same renderer
/// at 1024 sky and 256 near rays 0.0625, 0.0576, 0.0575; 3, the smallest on that plateau.
pub const SKY_RADIUS: f32 = 3.0;
/// HVL's near field's footprint radius over its rays' mean hit distance (world units, 2R
/// for a ray that meets nothing; NRD's diffuse filters' hit-distance-driven radius: light found
/// close by changes over that distance, so a corner keeps its gradient and an open floor is
/// smoothed wide). Against the same renderer at 256 near rays: 0.25, 0.5, 1, 2 left
/// `builtin:animated`'s orange wall at 0.071, 0.060, 0.058, 0.059 and `builtin:motion-sun`'s
/// frame at 0.018, 0.024, 0.029, 0.032 (docs/quality.md).
pub const NEAR_FOOTPRINT_PER_HIT: f32 = 0.5;

/// The diffuse footprint's radius (the gaussian's σ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Footprint {
    /// A radius in pixels of the filtered image.
    Pixels(f32),
    /// `scale` times the rays' mean hit distance the light holds in alpha (averaged over the
    /// 3×3 neighbours on the same surface), seen from the eye through pixels of angle
    /// `pixel_angle` ([`pixel_angle`]): `denoise_world_radius`, at least
    /// `DENOISE_DIFFUSE_MIN_RADIUS` pixels.
    HitDistance {
        /// The radius over the mean hit distance.
        scale: f32,
        /// The angle one pixel subtends at the eye.
        pixel_angle: f32,
    },
}

/// `[denoise]`: the edge-stopping filter of the traced signals (issue 47): the specular, the
/// sky's visibility and HVL's near field; its parameters, each declared once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct DenoiseParams {
    /// Filter the traced signals (off: the specular as traced, the sky and HVL's near field by
    /// their joint bilateral).
    #[setting(default = true, affects = both)]
    pub enabled: bool,
    /// À-trous iterations; iteration i spaces its 5×5 taps 2^i pixels apart.
    #[setting(default = ITERATIONS, range = ITERATIONS_RANGE, affects = both)]
    pub iterations: u32,
    /// Clamp fireflies: a pixel's luminance at most twice the largest of its 3×3 neighbours on
    /// the same surface with a lobe no wider than its own.
    /// (The specular's only: the diffuse signals' few rays leave neighbours at 0, and a lone
    /// ray's real light would be cut.)
    #[setting(default = true, affects = quality)]
    pub clamp: bool,
    /// Filter the sky's light too, with the diffuse footprint (off: its joint bilateral,
    /// `sky.filter_radius`).
    #[setting(default = true, affects = both)]
    pub diffuse: bool,
    /// Filter HVL's traced near field too, with the footprint of its rays' hit distance (off:
    /// its joint bilateral). Off by default: closer to the truth on still frames
    /// (`builtin:motion-sun` 0.0716 → 0.0711) but it flickered more on a moving figure
    /// (`builtin:animated`, indirect light: 0.74× → 0.79× of the truth's flicker; the sky
    /// alone 0.74×; docs/quality.md).
    #[setting(default = false, affects = both)]
    pub near_field: bool,
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

/// Push constants of `shaders/denoise_prep.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PrepPush {
    /// xyz: camera position; w: the specular pass's roughness limit, or the diffuse
    /// footprint's radius over the mean hit distance (0: the footprint is in pixels).
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// The specular variant, or the diffuse one from hit distances: the angle one pixel
    /// subtends at the eye ([`pixel_angle`]); else the footprint radius in pixels
    /// ([`Footprint`]).
    pub footprint: f32,
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
    let guide = Guide {
        position: &g.position,
        normal: &g.normal,
        albedo: &g.albedo,
        material: &g.material,
        extent: g.extent,
    };
    let push = PrepPush {
        camera: view.eye.extend(limit).to_array(),
        extent: g.extent,
        footprint: pixel_angle(view, g.extent[1]),
        clamp: u32::from(params.clamp),
    };
    let signal = Signal {
        names: ["specular_prep", "denoise_atrous", "specular_denoised"],
        input: ("specular", specular),
        prep: &shaders::DENOISE_PREP_COMP_SPECULAR,
        atrous: &shaders::DENOISE_ATROUS_COMP_SPECULAR,
    };
    filter(rg, &guide, &signal, &push, params)
}

/// Adds a prep pass `names[0]` and à-trous iterations `names[1]_i` over `light` (the
/// demodulated diffuse light, light / π, RGBA16F at receiver resolution: the sky's or HVL's
/// near field's) guided by `receivers` seen from `camera`, in the footprint `footprint`,
/// without the firefly clamp: the filtered light times each receiver's `kd` (RGBA16F, a = 0), as
/// [`crate::passes::sky::bilateral_filter`] does. Returns a new image `names[2]`.
///
/// At receiver resolution, where both signals are traced and summed before the upsample: each
/// receiver holds its own rays, so neighbours' noise is independent there (at full resolution
/// the upsample copies one receiver's noise into s × s pixels, which the 3×3 variance would
/// read as signal), and the filter costs 1/s² of a full-resolution one.
pub fn diffuse(
    rg: &mut RenderGraph,
    names: [&str; 3],
    receivers: &Receivers,
    light: &Handle<Image>,
    camera: glam::Vec3,
    footprint: Footprint,
    params: &DenoiseParams,
) -> Result<Handle<Image>, DenoiseError> {
    let guide = Guide {
        position: &receivers.position,
        normal: &receivers.normal,
        albedo: &receivers.albedo,
        material: &receivers.material,
        extent: receivers.extent,
    };
    let (world, footprint) = match footprint {
        Footprint::Pixels(radius) => (0.0, radius),
        Footprint::HitDistance { scale, pixel_angle } => (scale.max(0.0), pixel_angle),
    };
    let push = PrepPush {
        camera: camera.extend(world).to_array(),
        extent: receivers.extent,
        footprint,
        clamp: 0,
    };
    let signal = Signal {
        names,
        input: ("light", light),
        prep: &shaders::DENOISE_PREP_COMP_DIFFUSE,
        atrous: &shaders::DENOISE_ATROUS_COMP_DIFFUSE,
    };
    filter(rg, &guide, &signal, &push, params)
}

/// The guide images of a filter: a G-buffer's or the receivers' (same formats).
struct Guide<'a> {
    position: &'a Handle<Image>,
    normal: &'a Handle<Image>,
    albedo: &'a Handle<Image>,
    material: &'a Handle<Image>,
    extent: [u32; 2],
}

/// One traced signal through the filter: the prep pass's name, the iterations' (`_i` added),
/// the output image's, the input's binding and image, and the two shaders' variants.
struct Signal<'a> {
    names: [&'a str; 3],
    input: (&'a str, &'a Handle<Image>),
    prep: &'static crate::gpu::ShaderDesc,
    atrous: &'static crate::gpu::ShaderDesc,
}

/// Adds the prep pass and `params.iterations` à-trous iterations of `signal` over `guide`.
fn filter(
    rg: &mut RenderGraph,
    guide: &Guide<'_>,
    signal: &Signal<'_>,
    push: &PrepPush,
    params: &DenoiseParams,
) -> Result<Handle<Image>, DenoiseError> {
    params.validate()?;
    let [w, h] = guide.extent;
    let image = |rg: &mut RenderGraph, name: &str| {
        rg.create_image(
            name,
            ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
        )
    };
    let mut filtered = image(rg, "denoise_signal");
    let mut radius = image(rg, "denoise_footprint");
    let [prep_name, atrous_name, output] = signal.names;
    let mut prep = rg.compute(prep_name, signal.prep);
    prep.read(signal.input.0, signal.input.1)
        .read("gb_position", guide.position)
        .read("gb_normal", guide.normal);
    if signal.prep.binding("gb_albedo").is_some() {
        prep.read("gb_albedo", guide.albedo)
            .read("gb_material", guide.material);
    }
    prep.write("denoise_signal", &mut filtered)
        .write("denoise_footprint", &mut radius)
        .push(push)
        .dispatch([w, h, 1]);
    for i in 0..params.iterations {
        let last = i + 1 == params.iterations;
        let mut out = image(rg, if last { output } else { "denoise_signal" });
        rg.compute(&format!("{atrous_name}_{i}"), signal.atrous)
            .read("denoise_in", &filtered)
            .read("denoise_footprint", &radius)
            .read("gb_position", guide.position)
            .read("gb_normal", guide.normal)
            .read("gb_albedo", guide.albedo)
            .read("gb_material", guide.material)
            .read("denoise_source", signal.input.1)
            .write("denoise_out", &mut out)
            .push(&AtrousPush {
                camera: push.camera,
                extent: guide.extent,
                step: 1 << i,
                remodulate: u32::from(last),
            })
            .dispatch([w, h, 1]);
        filtered = out;
    }
    Ok(filtered)
}
