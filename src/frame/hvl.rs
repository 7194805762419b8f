//! The HVL technique (paper 003) as the frame uses it: the BRDF SH tables it keeps on the
//! device, and the passes it adds to a frame (`hvl_cache` over the primary light's RSM, then
//! `hvl_gather` at every receiver; `src/passes/hvl/mod.rs`). With `hvl.slices = 4` the gather
//! is amortised over frames (paper 001): one receiver per 2×2 cell per frame, the rest
//! reprojected by `hvl_resolve` (`src/passes/amortise.rs`) from the history this object
//! keeps track of.

use glam::Vec3;
use shine_gpu::Device;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu_scene::bvh::TraceImages;
use crate::passes::amortise::{self, ResolveHistory, Schedule, Slice};
use crate::passes::brdf_tables::BrdfTables;
use crate::passes::debug_view::LightRecords;
use crate::passes::hvl::{self, HvlParams};
use crate::passes::receivers::Receivers;
use crate::passes::rsm::Rsm;
use crate::passes::sample_history::{
    SampleHistoryPush, SampleSchedule, SampleSetup, sample_history,
};

/// The HVL technique's persistent state: its receiver BRDF tables per band count, and which
/// frame last wrote the amortised gather's history.
pub struct HvlTechnique {
    brdf: BrdfTables,
    /// Which frame last resolved into the amortised gather's history.
    schedule: Schedule,
    /// Which frame last wrote the HVLs' own history.
    samples: SampleSchedule,
}

/// An HVL frame ready to be declared: its parameters and its tables imported into the graph.
pub struct PreparedHvl {
    params: HvlParams,
    brdf: Handle<Buffer>,
    /// Amortised frames: the refreshed slice (0: every receiver) and whether the history
    /// holds the previous frame.
    amortised: Option<Slice>,
    /// The HVLs' own history, when on.
    samples: Option<SampleHistoryPush>,
}

/// What the HVL passes read from the rest of the frame.
pub struct HvlInputs<'a> {
    /// The receiver buffer the gather shades.
    pub receivers: &'a Receivers,
    /// The RSM faces the HVLs are drawn from, the primary light's first (the grid uses that
    /// one only).
    pub rsm: &'a [Rsm],
    /// The scene's BVH this frame (read only with `hvl.visibility`).
    pub bvh: &'a TraceImages,
    /// The camera position (the gather's view direction).
    pub camera: Vec3,
    /// The G-buffer's motion vectors (amortised frames reproject with them).
    pub motion: &'a Handle<Image>,
    /// Seed of the sampled shadow rays (the frame index when a history averages frames).
    pub seed: u32,
    /// R of the near field the frame traces beside the gather (world units; 0: none).
    pub near_radius: f32,
}

impl HvlTechnique {
    /// The technique on `device`; nothing is uploaded until the first frame.
    pub fn new(device: &Device) -> Self {
        Self {
            brdf: BrdfTables::new(device, "hvl brdf tables"),
            schedule: Schedule::default(),
            samples: SampleSchedule::default(),
        }
    }

    /// Bytes of device memory: `(tables, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        self.brdf.allocated_bytes()
    }

    /// Forgets the history (a new scene).
    pub fn reset(&mut self) {
        self.schedule.reset();
        self.samples.reset();
    }

    /// Forgets the history and the tables: a frame that may have uploaded them was dropped
    /// unrun.
    pub fn forget_uploads(&mut self) {
        self.reset();
        self.brdf.clear();
    }

    /// Uploads the BRDF tables `params` needs (once per band count) and imports them into
    /// `rg`; for amortised frames (`params.slices > 1`) at receivers of `receiver_extent`,
    /// picks this frame's slice. Without the previous frame's history (first frame, a resize,
    /// a frame skipped) the gather shades every receiver. With a sample weight below 1 the
    /// HVLs keep their own history over the scene's `lights`.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        params: HvlParams,
        receiver_extent: [u32; 2],
        samples: SampleSetup,
    ) -> Result<PreparedHvl, RenderError> {
        let brdf = self.brdf.import(rg, params.conv_bands)?;
        let amortised = self
            .schedule
            .next(rg.frame(), receiver_extent, params.slices, 0);
        let samples = samples.push(&mut self.samples, rg.frame(), params.count);
        Ok(PreparedHvl {
            params,
            brdf,
            amortised,
            samples,
        })
    }
}

impl PreparedHvl {
    /// Adds `hvl_cache` and `hvl_gather`; returns the indirect light at receiver resolution
    /// (RGBA16F outgoing radiance towards the camera) and the HVLs (a context's debug view
    /// draws them).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &HvlInputs<'_>,
    ) -> Result<(Handle<Image>, LightRecords), RenderError> {
        let mut params = self.params;
        params.shadow_seed = inputs.seed;
        params.near_radius = inputs.near_radius;
        let mut hvls = hvl::hvl_cache(rg, inputs.rsm, &params)?;
        if let Some(push) = &self.samples {
            sample_history(rg, "hvl samples", &mut hvls, push);
        }
        let lights = LightRecords {
            records: hvls,
            count: params.count,
        };
        let records = hvl::hvl_gather_prep(rg, &hvls, &params)?;
        let bvh = params.visibility.then_some(inputs.bvh);
        let slice = self.amortised.map_or(0, |s| s.slice);
        let mut gathered = hvl::hvl_gather(
            rg,
            inputs.receivers,
            &records,
            &self.brdf,
            bvh,
            inputs.camera,
            &params,
            slice,
        )?;
        let Some(amortised) = self.amortised else {
            return Ok((gathered, lights));
        };
        let surfaces = inputs.receivers.into();
        let mut history = ResolveHistory::declare(rg, "hvl", inputs.receivers.extent);
        if slice != 0 {
            // The receivers whose history was rejected, or whose changed cell's refreshed
            // receiver shows another surface, are gathered now (what moved first).
            amortise::regather_mask(
                rg,
                surfaces,
                &mut gathered,
                inputs.motion,
                &history,
                amortised,
            )?;
            hvl::hvl_regather(
                rg,
                inputs.receivers,
                &records,
                &self.brdf,
                bvh,
                inputs.camera,
                &params,
                &mut gathered,
            )?;
        }
        let resolved = amortise::resolve(
            rg,
            surfaces,
            &gathered,
            inputs.motion,
            &mut history,
            amortised,
        )?;
        Ok((resolved, lights))
    }
}
