//! The IGI technique (paper 000) as the frame uses it: the BRDF SH tables of its GGX resolve,
//! and the passes it adds to a frame at full resolution (VPLs from the primary light's RSM,
//! `vpl_sh` with shadow rays through the BVH, `sh_filter`; `src/passes/igi.rs`). With
//! `igi.slices = 4` the VPL sets are amortised over frames (paper 001): `vpl_sh` gathers the
//! set of one pixel per 2×2 cell per frame into a history of per-pixel SH, `igi_reproject`
//! carries every other pixel's SH over from the previous frame where it shows the same surface,
//! `igi_regather` gathers the rest, and `sh_filter` filters them all as every frame
//! (`src/passes/amortise.rs`). A static view thus gathers every set of the pattern in four
//! frames and renders the per-frame image exactly.

use glam::Vec3;
use shine_gpu::Device;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu_scene::bvh::TraceImages;
use crate::passes::amortise::{self, RecordHistory, RecordSignal, Schedule, Slice};
use crate::passes::brdf_tables::BrdfTables;
use crate::passes::debug_view::LightRecords;
use crate::passes::gbuffer::GBuffer;
use crate::passes::igi::{self, IgiParams, IgiSlice};
use crate::passes::rsm::Rsm;
use crate::passes::sample_history::{
    SampleHistoryPush, SampleSchedule, SampleSetup, sample_history,
};

/// The IGI technique's persistent state: the BRDF tables of the GGX resolve per SH order, and
/// which frame last wrote the amortised light's history.
pub struct IgiTechnique {
    brdf: BrdfTables,
    schedule: Schedule,
    /// Which frame last wrote the VPLs' own history.
    samples: SampleSchedule,
    /// The device's `maxStorageBufferRange` ([`IgiParams::storage_limit`]).
    storage_limit: u64,
}

/// An IGI frame ready to be declared: its parameters and, for the GGX resolve, its tables
/// imported into the graph.
pub struct PreparedIgi {
    params: IgiParams,
    brdf: Option<Handle<Buffer>>,
    /// Amortised frames (`igi.slices = 4`): this frame's slice.
    amortised: Option<Slice>,
    /// The VPLs' own history, when on.
    samples: Option<SampleHistoryPush>,
}

/// What the IGI passes read from the rest of the frame.
pub struct IgiInputs<'a> {
    /// The full-resolution G-buffer (the interleaving needs the pixel grid).
    pub gbuffer: &'a GBuffer,
    /// The RSM faces the VPLs are drawn from, the primary light's first (the grid uses that
    /// one only).
    pub rsm: &'a [Rsm],
    /// The scene's BVH for the VPL shadow rays.
    pub bvh: &'a TraceImages,
    /// The camera position.
    pub camera: Vec3,
    /// R of the traced near field in world units (0: none): the VPLs leave the light of
    /// surfaces within it to `hvl_near` ([`IgiParams::near_radius`]).
    pub near_radius: f32,
}

impl IgiTechnique {
    /// The technique on `device`; nothing is uploaded until the first frame.
    pub fn new(device: &Device) -> Self {
        Self {
            brdf: BrdfTables::new(device, "igi brdf tables"),
            schedule: Schedule::default(),
            samples: SampleSchedule::default(),
            storage_limit: u64::from(device.info().max_storage_buffer_range),
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

    /// Forgets the tables and the history: a frame that may have uploaded or written them was
    /// dropped unrun.
    pub fn forget_uploads(&mut self) {
        self.brdf.clear();
        self.reset();
    }

    /// Uploads the BRDF tables of the GGX resolve when `params` uses it (once per SH order)
    /// and imports them into `rg`; for amortised frames of `extent`, picks this frame's slice.
    /// With a sample weight below 1 the VPLs keep their own history over the scene's `lights`.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        mut params: IgiParams,
        extent: [u32; 2],
        samples: SampleSetup,
    ) -> Result<PreparedIgi, RenderError> {
        params.storage_limit = self.storage_limit;
        // The SH history's layout: another order or mode is no history.
        let words = params.coefficients() * igi::COEFFICIENT_WORDS;
        let amortised = self.schedule.next(rg.frame(), extent, params.slices, words);
        let brdf = if params.needs_brdf_tables() {
            Some(self.brdf.import(rg, params.sh_order)?)
        } else {
            None
        };
        let samples = samples.push(&mut self.samples, rg.frame(), params.vpl_count);
        Ok(PreparedIgi {
            params,
            brdf,
            amortised,
            samples,
        })
    }
}

impl PreparedIgi {
    /// Adds the IGI passes; returns the full-resolution indirect light (RGBA16F) and the VPLs
    /// (a context's debug view draws them).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &IgiInputs<'_>,
    ) -> Result<(Handle<Image>, LightRecords), RenderError> {
        let params = &IgiParams {
            near_radius: inputs.near_radius,
            ..self.params
        };
        let (g, camera) = (inputs.gbuffer, inputs.camera);
        let mut lights = igi::vpls(rg, inputs.rsm, params)?;
        if let Some(push) = &self.samples {
            sample_history(rg, "igi samples", &mut lights, push);
        }
        let lights = igi::sets(rg, lights, params)?;
        let records = LightRecords {
            records: lights.vpls,
            count: params.vpl_count,
        };
        let Some(amortised) = self.amortised else {
            let sh = igi::vpl_sh(
                rg,
                g,
                &lights,
                inputs.bvh,
                camera,
                params,
                IgiSlice::default(),
            )?;
            let light = igi::sh_filter(rg, g, &sh, self.brdf.as_ref(), camera, params)?;
            return Ok((light, records));
        };
        let words = params.coefficients() * igi::COEFFICIENT_WORDS;
        let mut history =
            RecordHistory::declare(rg, "igi", g.extent, words, RecordSignal::PackedRgb);
        let first = IgiSlice {
            slice: amortised.slice,
            marks: None,
            into: Some(history.records.current),
        };
        history.records.current = igi::vpl_sh(rg, g, &lights, inputs.bvh, camera, params, first)?;
        let marks = amortise::reproject_records(rg, g.into(), &g.motion, &mut history, amortised)?;
        if amortised.slice != 0 {
            // The pixels whose history was rejected or whose block changed gather their sets
            // now (what moved first).
            let again = IgiSlice {
                slice: amortise::REGATHER_SLICE,
                marks: Some(marks),
                into: Some(history.records.current),
            };
            history.records.current =
                igi::vpl_sh(rg, g, &lights, inputs.bvh, camera, params, again)?;
        }
        let sh = history.records.current;
        let light = igi::sh_filter(rg, g, &sh, self.brdf.as_ref(), camera, params)?;
        Ok((light, records))
    }
}
