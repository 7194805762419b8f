//! The IGI technique (paper 000) as the frame uses it: the BRDF SH tables of its GGX resolve,
//! and the passes it adds to a frame at full resolution (VPLs from the primary light's RSM,
//! `vpl_sh` with shadow rays through the BVH, `sh_filter`; `src/passes/igi.rs`).

use glam::Vec3;
use shine_gpu::Device;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu_scene::bvh::TraceBuffers;
use crate::passes::brdf_tables::BrdfTables;
use crate::passes::gbuffer::GBuffer;
use crate::passes::igi::{self, IgiParams};
use crate::passes::rsm::Rsm;

/// The IGI technique's persistent state: the BRDF tables of the GGX resolve per SH order.
pub struct IgiTechnique {
    brdf: BrdfTables,
}

/// An IGI frame ready to be declared: its parameters and, for the GGX resolve, its tables
/// imported into the graph.
pub struct PreparedIgi {
    params: IgiParams,
    brdf: Option<Handle<Buffer>>,
}

/// What the IGI passes read from the rest of the frame.
pub struct IgiInputs<'a> {
    /// The full-resolution G-buffer (the interleaving needs the pixel grid).
    pub gbuffer: &'a GBuffer,
    /// The RSM faces the VPLs are drawn from, the primary light's first (the grid uses that
    /// one only).
    pub rsm: &'a [Rsm],
    /// The scene's BVH for the VPL shadow rays.
    pub bvh: &'a TraceBuffers,
    /// The camera position.
    pub camera: Vec3,
}

impl IgiTechnique {
    /// The technique on `device`; nothing is uploaded until the first frame.
    pub fn new(device: &Device) -> Self {
        Self {
            brdf: BrdfTables::new(device, "igi brdf tables"),
        }
    }

    /// Bytes of device memory: `(tables, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        self.brdf.allocated_bytes()
    }

    /// Forgets the tables: a frame that may have uploaded them was dropped unrun.
    pub fn forget_uploads(&mut self) {
        self.brdf.clear();
    }

    /// Uploads the BRDF tables of the GGX resolve when `params` uses it (once per SH order)
    /// and imports them into `rg`.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        params: IgiParams,
    ) -> Result<PreparedIgi, RenderError> {
        let brdf = if params.needs_brdf_tables() {
            Some(self.brdf.import(rg, params.sh_order)?)
        } else {
            None
        };
        Ok(PreparedIgi { params, brdf })
    }
}

impl PreparedIgi {
    /// Adds the IGI passes; returns the full-resolution indirect light (RGBA16F).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &IgiInputs<'_>,
    ) -> Result<Handle<Image>, RenderError> {
        Ok(igi::igi(
            rg,
            inputs.gbuffer,
            inputs.rsm,
            inputs.bvh,
            self.brdf.as_ref(),
            inputs.camera,
            &self.params,
        )?)
    }
}
