//! The executor's pipeline cache: a compute pipeline per shader and a graphics pipeline per
//! description, each created the first time a pass needs it and kept for later frames.

use std::collections::HashMap;
use std::collections::hash_map::Entry;

use shine_gpu::{ComputePipeline, Device, GraphicsPipeline, GraphicsPipelineDesc, ShaderDesc};

/// Pipelines created so far, by shader name (compute) or by description (graphics).
#[derive(Default)]
pub(crate) struct PipelineCache {
    compute: HashMap<&'static str, ComputePipeline>,
    graphics: HashMap<String, GraphicsPipeline>,
}

/// What tells two graphics pipeline descriptions apart.
fn graphics_key(desc: &GraphicsPipelineDesc) -> String {
    format!(
        "{}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}|{:?}",
        desc.vertex.name,
        desc.fragment.map(|f| f.name),
        desc.vertex_buffers,
        desc.topology,
        desc.cull_mode,
        desc.color_targets,
        desc.depth,
        desc.depth_bias
    )
}

impl PipelineCache {
    /// The compute pipeline of `shader`, created on first use.
    pub fn compute(
        &mut self,
        device: &Device,
        shader: &'static ShaderDesc,
    ) -> Result<&ComputePipeline, shine_gpu::Error> {
        Ok(match self.compute.entry(shader.name) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(ComputePipeline::new(device, shader)?),
        })
    }

    /// The graphics pipeline of `desc`, created on first use.
    pub fn graphics(
        &mut self,
        device: &Device,
        desc: &GraphicsPipelineDesc,
    ) -> Result<&GraphicsPipeline, shine_gpu::Error> {
        Ok(match self.graphics.entry(graphics_key(desc)) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(GraphicsPipeline::new(device, desc)?),
        })
    }
}
