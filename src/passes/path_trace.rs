//! `path_trace`: the reference path tracer (docs/frame.md, "Path-traced reference").
//!
//! Progressive: every dispatch adds [`PathTraceParams::samples`] samples per pixel to running
//! sums in an accumulation buffer (three planes of RGBA32F texels — direct, indirect, full —
//! alpha counting the samples), so the caller keeps the buffer across frames and divides on
//! readback ([`crate::reference`]). Each sample's random numbers are seeded from (pixel,
//! sample index, seed): runs are deterministic and disjoint sample ranges independent.

use crate::gpu_scene::SceneHandles;
use crate::graph::{Buffer, Handle, Image, RenderGraph, vk};
use crate::shaders;
use glam::Mat4;

/// Bytes of one pixel of one plane of the accumulation buffer (RGBA32F).
pub const ACCUMULATION_TEXEL: u64 = 16;
/// Planes of the accumulation buffer: direct, indirect, full.
pub const ACCUMULATION_PLANES: u64 = 3;

/// Push constants of path_trace.comp (112 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PathTraceConstants {
    /// Clip space (with the raster passes' Y flip) to world.
    pub inv_view_proj: [[f32; 4]; 4],
    /// Width, height, index of the first sample of this dispatch, samples per pixel.
    pub frame: [u32; 4],
    /// Bounces, light count, flags (`FLAG_*`), seed.
    pub config: [u32; 4],
    /// x: the specular limit of [`FLAG_PRIMARY_SPECULAR`]; y, z, w: padding.
    pub options: [f32; 4],
}

/// Jitter the camera ray within the pixel (anti-aliasing); off: through the pixel centre, as
/// the raster passes sample.
pub const FLAG_JITTER: u32 = 1;
/// Emissive surfaces light other surfaces (always seen by the camera).
pub const FLAG_EMISSIVE_LIGHTING: u32 = 2;
/// Diagnostic: every surface is Lambertian with albedo = base colour (white-furnace tests).
pub const FLAG_LAMBERT_ONLY: u32 = 4;
/// Next-event estimation for the emissive triangles and the environment, weighted against
/// BRDF sampling by multiple importance sampling (`light_sampling.glsl`); off: their light is
/// found only by BRDF-sampled rays.
pub const FLAG_LIGHT_SAMPLING: u32 = 8;
/// The camera's surface reflects through its GGX lobe alone, weighted by the share the traced
/// specular takes (`specular_trace_weight` at [`PathTraceParams::specular_limit`]): the truth
/// of a GI context's specular output. Later vertices scatter by the whole BRDF.
pub const FLAG_PRIMARY_SPECULAR: u32 = 16;

/// What one `path_trace` dispatch computes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathTraceParams {
    /// Image size in pixels.
    pub extent: [u32; 2],
    /// Camera view-projection of the raster passes (`gbuffer::camera_view(..).view_proj()`).
    pub view_proj: Mat4,
    /// Scattering vertices after the first one (0: direct only, 1: one-bounce indirect).
    pub bounces: u32,
    /// Number of lights in the scene's light buffer.
    pub light_count: u32,
    /// `FLAG_*` bits.
    pub flags: u32,
    /// The `specular.limit` of [`FLAG_PRIMARY_SPECULAR`] (unused without it).
    pub specular_limit: f32,
    /// Seed mixed into every pixel's random numbers.
    pub seed: u32,
    /// Index of this dispatch's first sample (progressive accumulation).
    pub first_sample: u32,
    /// Samples per pixel added by this dispatch.
    pub samples: u32,
    /// Whether the light tables sample the environment
    /// ([`crate::reference::light_tables::LightTables::environment`]): picks the shader variant
    /// that holds that code (lavapipe runs a branch's code whatever its condition, so the
    /// variant without it is about 7% faster on scenes that do not need it).
    pub environment_sampling: bool,
    /// Whether any material has a texture: without, the variant with no texture lookups runs
    /// (lavapipe runs a lookup whatever its condition; about 9% of the path tracer's time on
    /// the cornell box).
    pub textures: bool,
}

/// The scene's buffers `path_trace.comp` reads, as images holding their copies
/// ([`crate::reference::scene_texels`]).
#[derive(Debug, Clone, Copy)]
pub struct SceneTexels {
    /// `material_texels`: the materials, five texels each.
    pub materials: Handle<Image>,
    /// `vertex_texels`: the vertices, four texels each.
    pub vertices: Handle<Image>,
    /// `index_texels`: the flattened indices, one R32UI texel each.
    pub indices: Handle<Image>,
    /// `light_texels`: the punctual lights, four texels each.
    pub lights: Handle<Image>,
    /// `light_table_texels`: the light tables' words, one R32UI texel each.
    pub light_tables: Handle<Image>,
}

/// Adds one progressive `path_trace` dispatch accumulating into `accumulation` (at least
/// `ACCUMULATION_PLANES × width × height × 16` bytes), tracing the scene's BVH and lit by
/// `environment` (RGBA32F equirectangular, src/gpu_scene/environment.rs) on escape, reading
/// the scene's materials, vertices, indices, lights and light tables
/// ([`crate::reference::light_tables::LightTables::words`]) from `texels`.
#[allow(clippy::too_many_arguments)]
pub fn path_trace(
    rg: &mut RenderGraph,
    scene: &SceneHandles,
    texels: &SceneTexels,
    environment: &Handle<Image>,
    accumulation: &mut Handle<Buffer>,
    params: &PathTraceParams,
    texture_sampler: vk::Sampler,
    environment_sampler: vk::Sampler,
) {
    let [w, h] = params.extent;
    let constants = PathTraceConstants {
        inv_view_proj: params.view_proj.inverse().to_cols_array_2d(),
        frame: [w, h, params.first_sample, params.samples],
        config: [
            params.bounces,
            params.light_count,
            params.flags,
            params.seed,
        ],
        options: [params.specular_limit, 0.0, 0.0, 0.0],
    };
    let shader = match (params.environment_sampling, params.textures) {
        (true, true) => &shaders::PATH_TRACE_COMP_ENVIRONMENT,
        (false, true) => &shaders::PATH_TRACE_COMP_NO_ENVIRONMENT,
        (true, false) => &shaders::PATH_TRACE_COMP_ENVIRONMENT_UNTEXTURED,
        (false, false) => &shaders::PATH_TRACE_COMP_NO_ENVIRONMENT_UNTEXTURED,
    };
    let mut pass = rg.compute("path_trace", shader);
    scene.trace.bind(&mut pass);
    pass.read("material_texels", &texels.materials)
        .read("srgb_textures", &scene.srgb_textures)
        .read("linear_textures", &scene.linear_textures)
        .sampler("texture_sampler", texture_sampler)
        .read("vertex_texels", &texels.vertices)
        .read("index_texels", &texels.indices)
        .read("light_texels", &texels.lights)
        .read("environment", environment)
        .sampler("environment_sampler", environment_sampler)
        .read("light_table_texels", &texels.light_tables)
        .write("accumulation", accumulation)
        .push(&constants)
        .dispatch([w, h, 1]);
}
