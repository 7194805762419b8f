//! An image's history as the frame uses it: the indirect light's (issue 23) and the direct
//! light's under TAA (issue 21). It knows which frame last accumulated into it, so that a frame
//! blends only with the one just before it at the same size (`src/passes/accumulate.rs`).

use shine_graph::{Handle, Image, RenderGraph};

use super::error::RenderError;
use crate::passes::accumulate::{self, AccumulateParams};
use crate::passes::gbuffer::GBuffer;

/// The accumulation's persistent state: its pass name and history key, and the frame number
/// and extent of the last frame that wrote the history.
pub struct AccumulateTechnique {
    name: &'static str,
    key: &'static str,
    last: Option<(u64, [u32; 2])>,
}

/// An accumulation ready to be declared: its parameters and whether the history holds the
/// previous frame.
pub struct PreparedAccumulate {
    name: &'static str,
    key: &'static str,
    params: AccumulateParams,
    has_history: bool,
}

impl AccumulateTechnique {
    /// An accumulation whose pass is `name` and whose history images are `key`; no history
    /// yet.
    pub fn new(name: &'static str, key: &'static str) -> Self {
        Self {
            name,
            key,
            last: None,
        }
    }

    /// Forgets the history (a new scene, a frame without accumulation, a dropped frame).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// `current` (on the surfaces of `g`, at `extent`) accumulated with `params` when the frame
    /// has both (`geometry_then` declares or returns the previous frame's `gbuffer history`,
    /// asked for only then); otherwise the history is forgotten and `current` passes through.
    pub fn apply(
        &mut self,
        rg: &mut RenderGraph,
        params: Option<AccumulateParams>,
        extent: [u32; 2],
        current: Option<Handle<Image>>,
        g: &GBuffer,
        geometry_then: impl FnOnce(&mut RenderGraph) -> Handle<Image>,
    ) -> Result<Option<Handle<Image>>, RenderError> {
        match (current, params) {
            (Some(light), Some(params)) => {
                let then = geometry_then(rg);
                let prepared = self.prepare(rg, params, extent);
                Ok(Some(prepared.declare(rg, &light, g, &then)?))
            }
            (light, _) => {
                self.reset();
                Ok(light)
            }
        }
    }

    /// This frame's accumulation at `extent`: it has history when the previous frame
    /// accumulated at the same extent.
    pub fn prepare(
        &mut self,
        rg: &RenderGraph,
        params: AccumulateParams,
        extent: [u32; 2],
    ) -> PreparedAccumulate {
        let frame = rg.frame();
        let has_history = self.last == Some((frame.wrapping_sub(1), extent));
        self.last = Some((frame, extent));
        PreparedAccumulate {
            name: self.name,
            key: self.key,
            params,
            has_history,
        }
    }
}

impl PreparedAccumulate {
    /// Adds `accumulate` over `current` (this frame's indirect light on the surfaces of `g`;
    /// `history_geometry` is the previous frame's `gbuffer history`); returns the accumulated
    /// light.
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        current: &Handle<Image>,
        g: &GBuffer,
        history_geometry: &Handle<Image>,
    ) -> Result<Handle<Image>, RenderError> {
        let mut history = accumulate::accumulate_history(rg, self.key, g.extent);
        accumulate::accumulate(
            rg,
            self.name,
            current,
            g,
            history_geometry,
            &mut history,
            &self.params,
            self.has_history,
        )
        .map_err(|e| RenderError::Invalid(e.to_string()))
    }
}
