//! The HVL technique (paper 003) as the frame uses it: the BRDF SH tables it keeps on the
//! device, and the passes it adds to a frame (`hvl_cache` over the primary light's RSM, then
//! `hvl_gather` at every receiver; `src/passes/hvl/mod.rs`).

use glam::Vec3;
use shine_gpu::Device;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu_scene::BUFFER_READ;
use crate::gpu_scene::bvh::TraceBuffers;
use crate::passes::brdf_tables::BrdfTables;
use crate::passes::hvl::{self, HvlParams};
use crate::passes::receivers::Receivers;
use crate::passes::rsm::Rsm;

/// The HVL technique's persistent state: its receiver BRDF tables per band count.
pub struct HvlTechnique {
    device: Device,
    brdf: BrdfTables,
}

/// An HVL frame ready to be declared: its parameters and its tables imported into the graph.
pub struct PreparedHvl {
    params: HvlParams,
    brdf: Handle<Buffer>,
}

/// What the HVL passes read from the rest of the frame.
pub struct HvlInputs<'a> {
    /// The receiver buffer the gather shades.
    pub receivers: &'a Receivers,
    /// The primary light's RSM the HVLs are cut from.
    pub rsm: &'a Rsm,
    /// The scene's BVH this frame (read only with `hvl.visibility`).
    pub bvh: &'a TraceBuffers,
    /// The camera position (the gather's view direction).
    pub camera: Vec3,
}

impl HvlTechnique {
    /// The technique on `device`; nothing is uploaded until the first frame.
    pub fn new(device: &Device) -> Self {
        Self {
            device: device.clone(),
            brdf: BrdfTables::default(),
        }
    }

    /// Uploads the BRDF tables `params` needs (once per band count) and imports them into
    /// `rg`.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        params: HvlParams,
    ) -> Result<PreparedHvl, RenderError> {
        let table = self.brdf.get(&self.device, params.conv_bands)?;
        Ok(PreparedHvl {
            params,
            brdf: rg.import_gpu_buffer(table, BUFFER_READ, BUFFER_READ),
        })
    }
}

impl PreparedHvl {
    /// Adds `hvl_cache` and `hvl_gather`; returns the indirect light at receiver resolution
    /// (RGBA16F outgoing radiance towards the camera).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &HvlInputs<'_>,
    ) -> Result<Handle<Image>, RenderError> {
        let hvls = hvl::hvl_cache(rg, inputs.rsm, &self.params)?;
        let bvh = self.params.visibility.then_some(inputs.bvh);
        Ok(hvl::hvl_gather(
            rg,
            inputs.receivers,
            &hvls,
            &self.brdf,
            bvh,
            inputs.camera,
            &self.params,
        )?)
    }
}
