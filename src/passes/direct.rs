//! `direct`: the punctual lights on the G-buffer (Lambert + GGX), the primary light shadowed
//! through the RSM depth with a PCF kernel, plus emission (docs/frame.md).

use super::gbuffer::{GBuffer, SceneHandles, ShadowMap};
use crate::shaders;
use shine_gpu::vk;
use shine_graph::{Handle, Image, ImageDesc, RenderGraph};

/// Push constants of direct.comp (96 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DirectConstants {
    /// World to the shadow map's clip space.
    pub shadow_view_proj: [[f32; 4]; 4],
    /// Camera position.
    pub eye: [f32; 4],
    /// Light count, shadowed light index, PCF radius (texels), 1 when a shadow map exists.
    pub counts: [u32; 4],
    /// x: depth bias (NDC depth), y: texel size (at 1 m, or absolute when z = 1), w: normal
    /// offset in texels.
    pub shadow: [f32; 4],
}

/// Shadow filtering parameters.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowParams {
    /// PCF kernel radius in shadow-map texels (a (2r+1)² kernel): the softness of edges.
    pub pcf_radius: u32,
    /// Depth bias in NDC depth units, on top of the raster slope bias.
    pub bias: f32,
    /// Receiver offset along its normal, in shadow-map texels (against acne at grazing angles).
    pub normal_offset: f32,
}

/// Adds the direct-light pass; returns `direct` (RGBA16F, full resolution).
#[allow(clippy::too_many_arguments)]
pub fn direct(
    rg: &mut RenderGraph,
    gbuffer: &GBuffer,
    scene: &SceneHandles,
    light_count: u32,
    shadow_map: Option<&ShadowMap>,
    eye: glam::Vec3,
    shadow: ShadowParams,
    sampler: vk::Sampler,
) -> Handle<Image> {
    let [w, h] = gbuffer.extent;
    let mut out = rg.create_image(
        "direct",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    // Without a shadow map the shadow binding still needs an image: the G-buffer depth is bound
    // and ignored (counts.w = 0).
    let (shadow_depth, view_proj, primary, has_shadow) = match shadow_map {
        Some(r) => (r.depth, r.view.view_proj(), r.light, 1),
        None => (gbuffer.depth, glam::Mat4::IDENTITY, u32::MAX, 0),
    };
    let (texel, orthographic) = match shadow_map {
        Some(r) if r.view.orthographic => (r.view.extent / r.size as f32, 1.0),
        Some(r) => (2.0 * (0.5 * r.view.extent).tan() / r.size as f32, 0.0),
        None => (0.0, 0.0),
    };
    let constants = DirectConstants {
        shadow_view_proj: view_proj.to_cols_array_2d(),
        eye: eye.extend(1.0).to_array(),
        counts: [light_count, primary, shadow.pcf_radius, has_shadow],
        shadow: [shadow.bias, texel, orthographic, shadow.normal_offset],
    };
    rg.compute("direct", &shaders::DIRECT_COMP)
        .read("gb_position", &gbuffer.position)
        .read("gb_normal", &gbuffer.normal)
        .read("gb_albedo", &gbuffer.albedo)
        .read("gb_material", &gbuffer.material)
        .read("gb_emissive", &gbuffer.emissive)
        .read("lights", &scene.lights)
        .read("shadow_depth", &shadow_depth)
        .sampler("shadow_sampler", sampler)
        .write("direct", &mut out)
        .push(&constants)
        .dispatch([w, h, 1]);
    out
}
