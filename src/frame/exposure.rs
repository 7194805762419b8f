//! Automatic exposure as the frame uses it (issue 21, item 5): the exposure history, and which
//! frame last wrote it, so that a frame adapts only from the one just before it.

use shine_graph::{Buffer, Handle, Image, RenderGraph};

use crate::passes::exposure::{self, ExposureParams};

/// The frame number of the last frame that computed an automatic exposure.
#[derive(Debug, Default)]
pub struct ExposureTechnique {
    last: Option<u64>,
}

impl ExposureTechnique {
    /// Forgets the history (a new scene, a dropped frame, a frame without automatic exposure).
    pub fn reset(&mut self) {
        self.last = None;
    }

    /// This frame's exposure buffer from its `direct` (+ `indirect`) light when `params` asks
    /// for automatic exposure (adapting from the previous frame's when it computed one); else
    /// `None`, and the history is forgotten.
    pub fn apply(
        &mut self,
        rg: &mut RenderGraph,
        params: Option<ExposureParams>,
        direct: &Handle<Image>,
        indirect: Option<&Handle<Image>>,
    ) -> Option<Handle<Buffer>> {
        let Some(params) = params else {
            self.reset();
            return None;
        };
        let frame = rg.frame();
        let has_history = self.last == Some(frame.wrapping_sub(1));
        self.last = Some(frame);
        let mut history = exposure::exposure_history(rg);
        Some(exposure::exposure(
            rg,
            direct,
            indirect,
            &mut history,
            has_history,
            &params,
        ))
    }
}
