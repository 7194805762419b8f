//! The AAF technique (paper 004) as the frame uses it: path-traced indirect light at every
//! G-buffer pixel through the BVH, sampled adaptively and filtered (`src/passes/aaf/`). With
//! `aaf.slices = 4` its samples are amortised (paper 001): one pixel per 2×2 cell per frame is
//! sampled into a history of per-pixel sums and filter widths, `aaf_reproject` carries the
//! others over where they show the same surface, the rest are sampled again
//! (`aaf_resample_*`), and the filter runs over all of them every frame
//! (`src/passes/amortise.rs`).

use glam::Vec3;
use shine_graph::{Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::gpu::{Device, vk};
use crate::gpu_scene::SceneHandles;
use crate::gpu_scene::bvh::TraceImages;
use crate::passes::aaf::{self, AafParams, AafRecords, AafScene, AafSlice};
use crate::passes::amortise::{self, RecordHistory, RecordSignal, Schedule, Slice};
use crate::passes::debug_view::AafSpp;
use crate::passes::gbuffer::{GBuffer, View};

/// The AAF technique: which frame last wrote its amortised samples' history, and how large a
/// storage buffer its device allows.
#[derive(Debug)]
pub struct AafTechnique {
    schedule: Schedule,
    /// The device's `maxStorageBufferRange` ([`AafParams::storage_limit`]).
    storage_limit: u64,
}

/// An AAF frame ready to be declared: its checked parameters.
pub struct PreparedAaf {
    params: AafParams,
    /// Amortised frames (`aaf.slices = 4`): this frame's slice.
    amortised: Option<Slice>,
}

/// What the AAF passes read from the rest of the frame.
pub struct AafInputs<'a> {
    /// The full-resolution G-buffer (the receivers).
    pub gbuffer: &'a GBuffer,
    /// The scene's buffers and textures (the rays' hits are shaded from them).
    pub scene: &'a SceneHandles,
    /// The scene's BVH.
    pub bvh: &'a TraceImages,
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
    /// The technique on `device`.
    pub fn new(device: &Device) -> Self {
        Self {
            schedule: Schedule::default(),
            storage_limit: u64::from(device.info().max_storage_buffer_range),
        }
    }

    /// Checks `params` and that `extent`'s sums fit the device (AAF uploads nothing of its own);
    /// for amortised frames of `extent`,
    /// picks this frame's slice.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        mut params: AafParams,
        extent: [u32; 2],
    ) -> Result<PreparedAaf, RenderError> {
        params.storage_limit = self.storage_limit;
        params.validate()?;
        params.check_extent(extent)?;
        let amortised = self.schedule.next(rg.frame(), extent, params.slices, 0);
        Ok(PreparedAaf { params, amortised })
    }

    /// Forgets the history: a new scene, or a frame that may have written it was dropped
    /// unrun.
    pub fn reset(&mut self) {
        self.schedule.reset();
    }
}

impl PreparedAaf {
    /// Adds the AAF passes; returns the full-resolution indirect light (RGBA16F) and the
    /// per-pixel sample counts (a context's debug view shows them).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        inputs: &AafInputs<'_>,
    ) -> Result<(Handle<Image>, AafSpp), RenderError> {
        let scene = AafScene {
            handles: inputs.scene,
            bvh: inputs.bvh,
            light_count: inputs.light_count,
            size: aaf::scene_size(inputs.bounds),
            texture_sampler: inputs.texture_sampler,
        };
        let (g, camera, params) = (inputs.gbuffer, inputs.camera, &self.params);
        let spp = |widths| AafSpp {
            widths,
            range: [params.spp_min as f32, params.spp_upper()],
        };
        let Some(amortised) = self.amortised else {
            let outputs = aaf::aaf(rg, g, &scene, camera, params)?;
            return Ok((outputs.indirect, spp(outputs.widths)));
        };
        let sums_words = (aaf::SUMS_BYTES / 4) as u32;
        let widths_words = (aaf::WIDTHS_BYTES / 4) as u32;
        let mut sums =
            RecordHistory::declare(rg, "aaf", g.extent, sums_words, RecordSignal::MeanRgb);
        let mut widths =
            RecordHistory::declare(rg, "aaf_widths", g.extent, widths_words, RecordSignal::None);
        let mut slice = AafSlice {
            slice: amortised.slice,
            marks: None,
            into: Some(AafRecords {
                sums: sums.records.current,
                widths: widths.records.current,
            }),
        };
        let mut samples = aaf::aaf_sample(rg, g, &scene, camera, params, slice)?;
        sums.records.current = samples.sums;
        widths.records.current = samples.widths;
        let marks = amortise::reproject_records(rg, g.into(), &g.motion, &mut sums, amortised)?;
        // Its marks (the same rejected history, no change test) are not read: the sums' marks,
        // which add the changed blocks, rebeta and resample the widths there too.
        amortise::reproject_records(rg, g.into(), &g.motion, &mut widths, amortised)?;
        if amortised.slice != 0 {
            // The pixels whose history was rejected or whose block changed are sampled now
            // (what moved first).
            slice = AafSlice {
                slice: amortise::REGATHER_SLICE,
                marks: Some(marks),
                into: Some(AafRecords {
                    sums: sums.records.current,
                    widths: widths.records.current,
                }),
            };
            samples = aaf::aaf_sample(rg, g, &scene, camera, params, slice)?;
        }
        let light = aaf::aaf_filter(rg, g, &samples.sums, &samples.widths, camera, params)?;
        Ok((light, spp(samples.widths)))
    }
}
