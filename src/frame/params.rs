//! [`FrameParams`]: what one frame computes, in the parameter types the passes and techniques
//! own. [`FrameParams::from_settings`] is the one conversion from [`Settings`]; nothing below
//! the frame reads the settings.

use crate::passes::aaf::AafParams;
use crate::passes::accumulate::AccumulateParams;
use crate::passes::composite::{Component, CompositeParams};
use crate::passes::cubes::CubeParams;
use crate::passes::direct::{SHADOW_DEPTH_BIAS, SHADOW_NORMAL_OFFSET, ShadowParams};
use crate::passes::exposure::ExposureParams;
use crate::passes::hvl::HvlParams;
use crate::passes::hvl::near::NearField;
use crate::passes::hvl::shadows::ShadowSampling;
use crate::passes::igi::{self, IgiParams};
use crate::passes::proxy::{Accumulation, ProxyParams, paper_expansion};
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
    /// Harmonics Virtual Lights (paper 003), when the frame has them (their `near_range` is set
    /// by the frame from `hvl_near`).
    pub hvl: Option<HvlParams>,
    /// HVL's traced near field, when the frame has HVLs and asks for it.
    pub hvl_near: Option<NearField>,
    /// Instant GI (paper 000), when the frame has it.
    pub igi: Option<IgiParams>,
    /// Sphere proxies (paper 002), when the frame has them.
    pub proxy: Option<ProxySetup>,
    /// Axis-aligned filtering of path-traced indirect light (paper 004), when the frame has it.
    pub aaf: Option<AafParams>,
    /// Traced specular reflections, when on and the frame has a GI technique (the techniques'
    /// `specular_limit` is its limit then, else 0).
    pub specular: Option<SpecularParams>,
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
    /// Temporal antialiasing (camera jitter and the direct light's history), when on.
    pub taa: Option<AccumulateParams>,
    /// Exposure and tonemap of the composite.
    pub composite: CompositeParams,
    /// Which part of the radiance the frame shows.
    pub component: Component,
}

/// The proxy technique's parameters: its passes' and how its GPU data is built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProxySetup {
    /// The parameters of the proxy passes.
    pub pass: ProxyParams,
    /// Shadow expansion factor η of the α tables (§4.1), resolved from the settings.
    pub shadow_expansion: f32,
    /// Indirect expansion factor of the α tables.
    pub indirect_expansion: f32,
    /// 0: the scene's proxies; k > 0: k spheres refitted to each proxied mesh.
    pub fit_count: u32,
    /// Receivers per refresh (paper 001; 1 or [`crate::passes::amortise::SLICES`]).
    pub slices: u32,
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

    /// The parameters chosen by `settings` (which the caller has validated).
    pub fn from_settings(settings: &Settings) -> Self {
        let gi = &settings.gi;
        let h = &settings.hvl;
        let i = &settings.igi;
        let p = &settings.proxy;
        let specular =
            (settings.specular.traced_limit() > 0.0 && !gi.is_none()).then(|| SpecularParams {
                samples: settings.specular.samples,
                limit: settings.specular.limit,
                ..SpecularParams::default()
            });
        let specular_limit = specular.map_or(0.0, |s| s.limit);
        let upsample = UpsampleParams {
            depth_sigma: settings.upsample.depth_epsilon,
            normal_power: settings.upsample.normal_power,
            ..UpsampleParams::default()
        };
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
                count: h.count,
                distribution: h.distribution,
                radius: h.radius,
                radius_scale: h.radius_scale,
                conv_bands: h.convolution_bands,
                emission_bands: h.emission_bands,
                path: h.gather,
                window: h.window,
                falloff: h.falloff,
                visibility: h.visibility,
                shadows: ShadowSampling {
                    rays: h.shadow_rays,
                    filter_radius: h.shadow_filter_radius,
                    matching: upsample,
                    seed: 0,
                },
                near_range: 0.0,
                slices: h.slices,
                specular_limit,
            }),
            hvl_near: (gi.contains(GiTechnique::Hvl) && h.near_range > 0.0).then_some(NearField {
                range_fraction: h.near_range,
                rays: h.near_rays,
                ..NearField::default()
            }),
            igi: gi.contains(GiTechnique::Igi).then_some(IgiParams {
                pattern: [i.n, i.m],
                vpl_count: i.vpl_count,
                distribution: i.distribution,
                sh_order: i.sh_order,
                filter_radius: i.filter_radius,
                mode: i.filter,
                glossy: i.glossy,
                clamp_distance: i.clamp_distance,
                depth_tolerance: i.depth_tolerance,
                normal_threshold: i.normal_threshold,
                specular_limit,
                slices: i.slices,
                // The device's limit replaces it when the frame is prepared.
                storage_limit: igi::MAX_STORAGE_BUFFER,
            }),
            proxy: gi.contains(GiTechnique::Proxy).then_some(ProxySetup {
                pass: ProxyParams {
                    bands: p.sh_order,
                    accumulation: if p.brute_force {
                        Accumulation::Product
                    } else {
                        Accumulation::Splat
                    },
                    exp: p.exp,
                    indirect: p.indirect,
                    specular_limit,
                },
                shadow_expansion: if p.expansion > 0.0 {
                    p.expansion
                } else {
                    paper_expansion(p.sh_order)
                },
                indirect_expansion: p.indirect_expansion,
                fit_count: p.fit_count,
                slices: p.slices,
            }),
            aaf: gi.contains(GiTechnique::Aaf).then(|| {
                let a = &settings.aaf;
                AafParams {
                    first_samples: a.samples,
                    mu: a.mu,
                    omega_h: a.omega_h,
                    spp_min: a.spp_min,
                    spp_max: a.spp_max,
                    bounces: a.bounces,
                    adaptive: a.adaptive,
                    filter: a.filter,
                    filter_degree: a.filter_degree,
                    irradiance_vector: a.irradiance_vector,
                    specular_limit,
                    slices: a.slices,
                    ..AafParams::default()
                }
            }),
            specular,
            sky: (settings.sky.enabled && !gi.contains(GiTechnique::Proxy)).then(|| SkyParams {
                rays: settings.sky.rays,
                range: settings.sky.range,
                bent_normal: settings.sky.bent_normal,
                filter_radius: settings.sky.filter_radius,
                ..SkyParams::default()
            }),
            cavity: settings.cavity.enabled.then(|| SkyParams {
                rays: settings.cavity.rays,
                range: settings.cavity.range,
                bent_normal: false,
                ..SkyParams::default()
            }),
            cubes: settings.cubes.enabled.then_some(CubeParams {
                lookup: settings.cubes.lookup,
                solid_angle: settings.cubes.solid_angle,
                mask: settings.cubes.mask,
                slices: settings.cubes.slices,
            }),
            upsample,
            history: (settings.history.frames > 1).then_some(AccumulateParams {
                max_frames: settings.history.frames,
                clip: settings.history.clip,
                geometry: true,
            }),
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
