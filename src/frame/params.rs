//! [`FrameParams`]: what one frame computes, in the parameter types the passes and techniques
//! own. [`FrameParams::from_settings`] is the one conversion from [`Settings`]; nothing below
//! the frame reads the settings.

use crate::passes::aaf::AafParams;
use crate::passes::accumulate::AccumulateParams;
use crate::passes::composite::{Component, CompositeParams};
use crate::passes::cubes::CubeParams;
use crate::passes::denoise::DenoiseParams;
use crate::passes::direct::{SHADOW_DEPTH_BIAS, SHADOW_NORMAL_OFFSET, ShadowParams};
use crate::passes::exposure::ExposureParams;
use crate::passes::hvl::HvlParams;
use crate::passes::hvl::near::NearField;
use crate::passes::igi::IgiParams;
use crate::passes::proxy::ProxySettings;
use crate::passes::sky::SkyParams;
use crate::passes::specular::SpecularParams;
use crate::passes::upsample::UpsampleParams;
use crate::settings::{GiTechnique, Settings};

/// Everything a frame needs to know, resolved from the settings: a technique is in the frame
/// exactly when its parameters are present.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameParams {
    /// Width and height of the output frame in pixels (the passes before the composite run
    /// at [`FrameParams::render_extent`]).
    pub extent: [u32; 2],
    /// Receiver-buffer downscale s (paper 002 §4.2) of the receiver-resolution techniques.
    pub receiver_scale: u32,
    /// Side of the primary light's reflective shadow map (HVL and IGI).
    pub rsm_size: u32,
    /// Side of each shadow-atlas tile in texels.
    pub shadow_size: u32,
    /// How the direct pass filters and biases its shadow lookups.
    pub shadow: ShadowParams,
    /// Trilinear texture filtering over the mip chains (off: level 0 only).
    pub mipmaps: bool,
    /// Harmonics Virtual Lights (paper 003), when the frame has them (their `near_radius`, in
    /// world units, is set by the frame from `near_field`).
    pub hvl: Option<HvlParams>,
    /// The traced near field of HVL's or IGI's (`hvl.near_range`, `igi.near_range`), when the
    /// frame has that technique and asks for it.
    pub near_field: Option<NearField>,
    /// Instant GI (paper 000), when the frame has it (its `near_radius` set by the frame from
    /// `near_field`, as HVL's).
    pub igi: Option<IgiParams>,
    /// Sphere proxies (paper 002), when the frame has them.
    pub proxy: Option<ProxySettings>,
    /// Axis-aligned filtering of path-traced indirect light (paper 004), when the frame has it.
    pub aaf: Option<AafParams>,
    /// Traced specular reflections, when on and the frame has a GI technique (the techniques'
    /// `specular_limit` is its limit then, else 0).
    pub specular: Option<SpecularParams>,
    /// The traced specular's filter, when the specular pass runs and `denoise.enabled`.
    pub denoise: Option<DenoiseParams>,
    /// The sky's filter, when `denoise.enabled` and `denoise.diffuse` (else its joint
    /// bilateral).
    pub denoise_diffuse: Option<DenoiseParams>,
    /// HVL's near field's filter, when `denoise.enabled` and `denoise.near_field` (else its
    /// joint bilateral).
    pub denoise_near: Option<DenoiseParams>,
    /// The sky light, when on and the frame has no proxies (which shadow the environment
    /// themselves), `gi = none` included: the sky's light is direct light, though it travels
    /// in the indirect image. Declared only for a scene with an environment.
    pub sky: Option<SkyParams>,
    /// Cavity shading of HVL's light, when on: its rays and their reach as a fraction of the
    /// scene's largest side.
    pub cavity: Option<SkyParams>,
    /// Tiny environment cubes for the dynamic objects, when on (paper 001).
    pub cubes: Option<CubeParams>,
    /// The joint bilateral upsample of the receiver-resolution light.
    pub upsample: UpsampleParams,
    /// The indirect light's accumulation over frames, when it has a history longer than one
    /// frame.
    pub history: Option<AccumulateParams>,
    /// Weight of this frame in each HVL's and VPL's own history (`history.samples`; 1: none),
    /// with or without the screen's history.
    pub sample_weight: f32,
    /// Temporal antialiasing (camera jitter and the direct light's history), when on.
    pub taa: Option<AccumulateParams>,
    /// Exposure and tonemap of the composite.
    pub composite: CompositeParams,
    /// Which part of the radiance the frame shows.
    pub component: Component,
}

impl FrameParams {
    /// The size every pass before the composite renders at: the output's times the
    /// supersampling factor.
    pub fn render_extent(&self) -> [u32; 2] {
        let n = self.composite.ssaa.max(1);
        [self.extent[0] * n, self.extent[1] * n]
    }

    /// These parameters as the passes before the composite see them: `extent` is the
    /// rendered size.
    pub fn at_render_extent(&self) -> Self {
        Self {
            extent: self.render_extent(),
            ..self.clone()
        }
    }

    /// The parameters chosen by `settings` (which the caller has validated): the sections
    /// the techniques declared, with what the frame sets (the traced specular limit, the
    /// techniques that are in the frame).
    pub fn from_settings(settings: &Settings) -> Self {
        let gi = &settings.gi;
        let specular =
            (settings.specular.traced_limit() > 0.0 && !gi.is_none()).then_some(settings.specular);
        let specular_limit = specular.map_or(0.0, |s| s.limit);
        let upsample = settings.upsample;
        let h = &settings.hvl;
        Self {
            extent: [settings.width, settings.height],
            receiver_scale: settings.receiver_scale,
            rsm_size: settings.rsm.size,
            shadow_size: settings.shadow.size,
            shadow: ShadowParams {
                // The setting is a radius in texels; the kernel covers whole texels around it.
                pcf_radius: settings.shadow.filter_radius.round() as u32,
                bias: SHADOW_DEPTH_BIAS,
                normal_offset: SHADOW_NORMAL_OFFSET,
            },
            mipmaps: settings.texture.mipmaps,
            hvl: gi.contains(GiTechnique::Hvl).then_some(HvlParams {
                shadow_matching: upsample,
                specular_limit,
                ..*h
            }),
            near_field: if gi.contains(GiTechnique::Hvl) {
                NearField::asked(h.near_range, h.near_rays)
            } else if gi.contains(GiTechnique::Igi) {
                NearField::asked(settings.igi.near_range, settings.igi.near_rays)
            } else {
                None
            },
            igi: gi.contains(GiTechnique::Igi).then_some(IgiParams {
                specular_limit,
                ..settings.igi
            }),
            proxy: gi.contains(GiTechnique::Proxy).then_some(ProxySettings {
                specular_limit,
                ..settings.proxy
            }),
            aaf: gi.contains(GiTechnique::Aaf).then_some(AafParams {
                specular_limit,
                ..settings.aaf
            }),
            specular,
            denoise: specular.and(settings.denoise.enabled.then_some(settings.denoise)),
            denoise_diffuse: (settings.denoise.enabled && settings.denoise.diffuse)
                .then_some(settings.denoise),
            denoise_near: (settings.denoise.enabled && settings.denoise.near_field)
                .then_some(settings.denoise),
            sky: (settings.sky.enabled && !gi.contains(GiTechnique::Proxy)).then_some(settings.sky),
            cavity: settings.cavity.enabled.then(|| settings.cavity.params()),
            cubes: settings.cubes.enabled.then_some(settings.cubes),
            upsample,
            history: (settings.history.max_frames > 1).then_some(settings.history),
            sample_weight: settings.history.samples,
            taa: settings.output.taa.then(AccumulateParams::taa),
            composite: CompositeParams {
                exposure: settings.output.exposure,
                tonemap: settings.output.tonemap,
                ssaa: settings.output.ssaa_for(settings.width, settings.height),
                auto_exposure: settings.output.auto_exposure.then_some(ExposureParams {
                    adaptation: settings.output.adaptation,
                    ..ExposureParams::default()
                }),
            },
            component: settings.output.component,
        }
    }
}
