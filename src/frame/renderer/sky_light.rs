//! The frame's sky light and cavity shading (issues 16 and 18), declared by
//! [`super::Renderer::declare_indirect`] at receiver resolution, and the per-frame seed of its
//! Monte-Carlo passes (these and the specular reflections).

use glam::Vec3;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

use crate::frame::error::RenderError;
use crate::frame::params::FrameParams;
use crate::frame::proxy::ProxyTechnique;
use crate::gpu_scene::bvh::TraceImages;
use crate::passes::aaf::scene_size;
use crate::passes::receivers::Receivers;
use crate::passes::sky::{self, SkyParams};

/// The seed the Monte-Carlo passes add to theirs: the frame index when a history averages the
/// frames and `history.reseed` asks for new rays each frame, else 0: every pixel keeps its
/// rays from frame to frame, so their noise holds still as a fixed-seed path tracer's does
/// (issue 43), and a still frame looks the same every time.
pub(super) fn history_seed(rg: &RenderGraph, p: &FrameParams) -> u32 {
    if p.history.is_some_and(|h| h.reseed) {
        rg.frame() as u32
    } else {
        0
    }
}

/// HVL's unshadowed receiver `light` darkened by paper 001's cavity shading when `p` asks for
/// it (its reach a fraction of the largest side of the scene's `bounds`); else `light`.
pub(super) fn cavity_shaded(
    rg: &mut RenderGraph,
    p: &FrameParams,
    bounds: (Vec3, Vec3),
    bvh: &TraceImages,
    receivers: Option<&Receivers>,
    light: Option<Handle<Image>>,
) -> Result<Option<Handle<Image>>, RenderError> {
    let (Some(light), Some(params), Some(receivers)) = (light, p.cavity, receivers) else {
        return Ok(light);
    };
    let params = SkyParams {
        range: params.range * scene_size(bounds),
        ..params
    };
    let seed = history_seed(rg, p);
    Ok(Some(sky::cavity(
        rg, receivers, &light, bvh, &params, seed,
    )?))
}

/// The filter of the sky's light (`near` false) or HVL's near field's (`near`) that `p` asks
/// for: the denoiser's diffuse variant (`denoise.diffuse`, `denoise.near_field`) or the joint
/// bilateral with the upsample's match.
pub(super) fn light_filter(p: &FrameParams, near: bool) -> sky::LightFilter<'_> {
    match if near {
        &p.denoise_near
    } else {
        &p.denoise_diffuse
    } {
        Some(params) => sky::LightFilter::Denoise(params),
        None => sky::LightFilter::Bilateral(&p.upsample),
    }
}

/// Where the sky's SH comes from: a host's environment map, projected at [`sky::BANDS`] bands
/// this frame, or else the scene's environment (the proxies' projection).
pub(super) struct SkySh<'a> {
    /// The host's projection, when the host gave a map.
    pub host: Option<Handle<Buffer>>,
    /// The technique that projects the scene's environment.
    pub scene: &'a mut ProxyTechnique,
}

/// The sky's diffuse light at `receivers` seen from `camera`, from the environment's SH at
/// [`sky::BANDS`] bands.
pub(super) fn sky_light(
    rg: &mut RenderGraph,
    p: &FrameParams,
    params: &SkyParams,
    sh: SkySh<'_>,
    bvh: &TraceImages,
    receivers: &Receivers,
    camera: Vec3,
) -> Result<Handle<Image>, RenderError> {
    let environment = match sh.host {
        Some(host) => host,
        None => sh.scene.environment_sh(rg, sky::BANDS)?,
    };
    let seed = history_seed(rg, p);
    Ok(sky::sky(
        rg,
        receivers,
        &environment,
        bvh,
        camera,
        params,
        light_filter(p, false),
        seed,
    )?)
}
