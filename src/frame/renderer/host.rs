//! The indirect light of a host's G-buffer, recorded into the host's command buffer: the
//! frame a GI context (`crate::embed`) records.

use super::Renderer;
use crate::frame::error::RenderError;
use crate::frame::params::FrameParams;
use crate::passes::gbuffer::{GBuffer, View};
use crate::passes::history;
use shine_gpu::vk;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

/// The host's side of a frame, declared into its graph.
pub(crate) struct HostSide {
    /// The G-buffer converted from the host's images.
    pub g: GBuffer,
    /// The host's output image, imported.
    pub output: Handle<Image>,
    /// The host's environment map projected to SH, when it gave one.
    pub environment: Option<Handle<Buffer>>,
}

/// Declares the host's side of a frame into its graph.
pub(crate) type DeclareHost<'a> = dyn FnMut(&mut RenderGraph) -> Result<HostSide, RenderError> + 'a;

impl Renderer {
    /// Records into `cb`, as the host's frame `frame_index` (`None`: a frame of shine's own
    /// that is waited for, which leaves the host's frame clock alone), the scene's updates, `host`'s G-buffer conversion, the techniques of
    /// `p` seen from `camera`, and their indirect light written into the host's output image
    /// (cleared to 0 when the frame has no indirect light, e.g. no primary light for HVL).
    /// Neither submits nor waits. After an error nothing usable was recorded, and what this
    /// frame meant to leave for the next (history, uploads) is forgotten.
    pub(crate) fn record_indirect(
        &mut self,
        cb: vk::CommandBuffer,
        frame_index: Option<u64>,
        p: &FrameParams,
        camera: &View,
        host: &mut DeclareHost<'_>,
    ) -> Result<(), RenderError> {
        if let Some(frame_index) = frame_index {
            self.begin_host_frame(frame_index);
        }
        let mut rg = self.executor.begin_frame();
        let recorded = match self.declare_host_frame(&mut rg, p, camera, host) {
            Ok(()) => self
                .executor
                .execute(cb, rg)
                .map(drop)
                .map_err(RenderError::from),
            Err(e) => Err(e),
        };
        if recorded.is_err() {
            self.forget_history();
        }
        recorded
    }

    /// The passes of [`Renderer::record_indirect`].
    fn declare_host_frame(
        &mut self,
        rg: &mut RenderGraph,
        p: &FrameParams,
        camera: &View,
        host: &mut DeclareHost<'_>,
    ) -> Result<(), RenderError> {
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        let handles = scene.gpu.declare(rg)?;
        let HostSide {
            g,
            mut output,
            environment,
        } = host(rg)?;
        let indirect = self.declare_indirect(rg, p, &handles, &g, camera, environment)?;
        // With a history (issue 23), the host's G-buffer is kept for the next frame's
        // disocclusion test.
        let indirect = self
            .accumulate
            .apply(rg, p.history, p.extent, indirect, &g, |rg| {
                history::gbuffer_history(rg, &g)
            })?;
        match indirect {
            Some(indirect) => {
                rg.blit_image("gi to host", &indirect, &mut output, vk::Filter::NEAREST);
            }
            None => {
                rg.clear_image("gi to host", &mut output, [0.0; 4]);
            }
        }
        Ok(())
    }
}
