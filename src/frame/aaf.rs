//! The AAF technique (paper 004) as the frame uses it: path-traced indirect light at every
//! G-buffer pixel through the BVH, sampled adaptively and filtered (`src/passes/aaf.rs`). It
//! keeps no state between frames yet; it reads the scene's buffers and BVH each frame.

use glam::Vec3;
use shine_graph::{Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu::vk;
use crate::gpu_scene::SceneHandles;
use crate::gpu_scene::bvh::TraceBuffers;
use crate::passes::aaf::{self, AafParams, AafScene};
use crate::passes::gbuffer::{GBuffer, View};

/// The AAF technique.
#[derive(Debug, Default)]
pub struct AafTechnique;

/// An AAF frame ready to be declared: its checked parameters.
pub struct PreparedAaf {
    params: AafParams,
}

/// What the AAF passes read from the rest of the frame.
pub struct AafInputs<'a> {
    /// The full-resolution G-buffer (the receivers).
    pub gbuffer: &'a GBuffer,
    /// The scene's buffers and textures (the rays' hits are shaded from them).
    pub scene: &'a SceneHandles,
    /// The scene's BVH.
    pub bvh: &'a TraceBuffers,
    /// Lights in the scene's light buffer.
    pub light_count: u32,
    /// The scene's bounds ([`aaf::scene_size`]).
    pub bounds: (Vec3, Vec3),
    /// The camera's view (pixel footprints, view direction).
    pub camera: &'a View,
    /// The sampler of the scene's textures.
    pub texture_sampler: vk::Sampler,
}

impl AafTechnique {
    /// Checks `params` (AAF uploads nothing of its own).
    pub fn prepare(&mut self, params: AafParams) -> Result<PreparedAaf, RenderError> {
        params.validate()?;
        Ok(PreparedAaf { params })
    }
}

impl PreparedAaf {
    /// Adds the AAF passes; returns the full-resolution indirect light (RGBA16F).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &AafInputs<'_>,
    ) -> Result<Handle<Image>, RenderError> {
        let scene = AafScene {
            handles: inputs.scene,
            bvh: inputs.bvh,
            light_count: inputs.light_count,
            size: aaf::scene_size(inputs.bounds),
            texture_sampler: inputs.texture_sampler,
        };
        Ok(aaf::aaf(rg, inputs.gbuffer, &scene, inputs.camera, &self.params)?.indirect)
    }
}
