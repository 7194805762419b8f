//! `direct`: the punctual lights on the G-buffer (Lambert + GGX), each shadowed through its
//! tiles of the shadow atlas ([`super::shadows`]) with a PCF kernel, plus emission; the
//! environment behind the scene (docs/frame.md).

use super::gbuffer::{GBuffer, View};
use super::shadows::ShadowAtlas;
use crate::gpu_scene::SceneHandles;
use crate::shaders;
use shine_gpu::vk;
use shine_graph::{Handle, Image, ImageDesc, RenderGraph};

/// Push constants of direct.comp (112 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DirectConstants {
    /// Camera clip space to world directions (the view without its translation): background
    /// pixels look up the environment.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Camera position.
    pub eye: [f32; 4],
    /// Light count, PCF radius (texels), 1 when the atlas holds views, 0.
    pub counts: [u32; 4],
    /// x: depth bias (NDC depth), y: normal offset in texels, zw: one atlas texel in uv.
    pub shadow: [f32; 4],
}

/// Shadow-map depth bias in NDC depth units, on top of the raster slope bias.
pub const SHADOW_DEPTH_BIAS: f32 = 1e-4;
/// Receiver offset along its normal in shadow-map texels (removes acne at grazing angles).
pub const SHADOW_NORMAL_OFFSET: f32 = 1.5;

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

/// The environment seen behind the scene: the baked equirectangular texture
/// (`crate::gpu_scene::environment`) and a sampler repeating in u, clamped in v.
#[derive(Clone, Copy, Debug)]
pub struct Background {
    /// The environment texture.
    pub environment: Handle<Image>,
    /// Its sampler.
    pub sampler: vk::Sampler,
}

/// Adds the direct-light pass; returns `direct` (RGBA16F, full resolution; background pixels
/// hold the environment seen by `camera`).
#[allow(clippy::too_many_arguments)]
pub fn direct(
    rg: &mut RenderGraph,
    gbuffer: &GBuffer,
    scene: &SceneHandles,
    light_count: u32,
    atlas: &ShadowAtlas,
    camera: &View,
    background: &Background,
    shadow: ShadowParams,
    sampler: vk::Sampler,
) -> Handle<Image> {
    let [w, h] = gbuffer.extent;
    let mut out = rg.create_image(
        "direct",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let constants = DirectConstants {
        // Rotation only: the background needs directions, and dropping the translation keeps
        // them precise far from the origin.
        inv_view_proj: (camera.proj * glam::Mat4::from_mat3(glam::Mat3::from_mat4(camera.view)))
            .inverse()
            .to_cols_array_2d(),
        eye: camera.eye.extend(1.0).to_array(),
        counts: [
            light_count,
            shadow.pcf_radius,
            u32::from(atlas.view_count > 0),
            0,
        ],
        shadow: [
            shadow.bias,
            shadow.normal_offset,
            1.0 / atlas.extent[0] as f32,
            1.0 / atlas.extent[1] as f32,
        ],
    };
    rg.compute("direct", &shaders::DIRECT_COMP)
        .read("gb_position", &gbuffer.position)
        .read("gb_normal", &gbuffer.normal)
        .read("gb_albedo", &gbuffer.albedo)
        .read("gb_material", &gbuffer.material)
        .read("gb_emissive", &gbuffer.emissive)
        .read("lights", &scene.lights)
        .read("shadow_atlas", &atlas.depth)
        .read("shadow_views", &atlas.views)
        .read("shadow_lights", &atlas.lights)
        .sampler("shadow_sampler", sampler)
        .read("environment", &background.environment)
        .sampler("environment_sampler", background.sampler)
        .write("direct", &mut out)
        .push(&constants)
        .dispatch([w, h, 1]);
    out
}
