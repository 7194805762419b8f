//! What rays that meet the scene's surfaces read: its materials, textures, vertices and
//! lights (`shaders/include/path.glsl`, `surface.glsl`), its BVH, and the environment where
//! they escape. Shared by the passes that shade ray hits with the one-bounce light: the
//! traced specular reflections (`passes::specular`), the environment cubes' fill
//! (`passes::cubes`) and HVL's near field (`passes::hvl::near`).

use crate::gpu_scene::SceneHandles;
use crate::gpu_scene::bvh::TraceImages;
use crate::graph::{ComputePass, Handle, Image, vk};

/// The scene as rays see it.
#[derive(Debug, Clone, Copy)]
pub struct TracedScene<'a> {
    /// The scene's buffers and textures.
    pub handles: &'a SceneHandles,
    /// Its BVH.
    pub bvh: &'a TraceImages,
    /// Lights in the light buffer.
    pub light_count: u32,
    /// The sampler of the scene's textures (level 0 at ray hits).
    pub texture_sampler: vk::Sampler,
    /// The environment (RGBA32F equirectangular) seen by rays that escape.
    pub environment: &'a Handle<Image>,
    /// Its sampler (linear, repeating in u, clamped in v).
    pub environment_sampler: vk::Sampler,
    /// The environment also lights the ray hits (one cosine-sampled, shadowed ray each).
    pub environment_lighting: bool,
}

impl TracedScene<'_> {
    /// Binds the scene's bindings of `path.glsl`, `surface.glsl`, `trace.glsl` and
    /// `environment.glsl` to `pass`.
    pub fn bind(&self, pass: &mut ComputePass<'_>) {
        self.bind_surfaces(pass);
        pass.read("environment", self.environment)
            .sampler("environment_sampler", self.environment_sampler);
    }

    /// Binds the scene's bindings of `path.glsl`, `surface.glsl` and `trace.glsl` to `pass`
    /// (a pass whose rays never see the environment).
    pub fn bind_surfaces(&self, pass: &mut ComputePass<'_>) {
        bind_surfaces(pass, self.handles, self.texture_sampler, self.bvh);
    }
}

/// Binds the bindings of `path.glsl`, `surface.glsl` and `trace.glsl` to `pass`: the scene's
/// materials, textures (read through `texture_sampler`), vertices and lights in `handles`,
/// and its BVH `bvh`. For passes that hold these without a [`TracedScene`] (AAF's sampling).
pub fn bind_surfaces(
    pass: &mut ComputePass<'_>,
    handles: &SceneHandles,
    texture_sampler: vk::Sampler,
    bvh: &TraceImages,
) {
    pass.read("materials", &handles.materials)
        .read("srgb_textures", &handles.srgb_textures)
        .read("linear_textures", &handles.linear_textures)
        .sampler("texture_sampler", texture_sampler)
        .read("vertices", &handles.vertices)
        .read("indices", &handles.indices)
        .read("lights", &handles.lights);
    bvh.bind(pass);
}
