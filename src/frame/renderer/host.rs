//! The indirect light of a host's G-buffer, recorded into the host's command buffer: the
//! frame a GI context (`crate::embed`) records.

use super::Renderer;
use crate::frame::error::RenderError;
use crate::frame::params::FrameParams;
use crate::passes::debug_view::{DebugView, debug_view};
use crate::passes::gbuffer::{GBuffer, View};
use crate::passes::history;
use crate::passes::upsample::{Coarse, CoarseGrid, upsample_grid};
use shine_gpu::vk;
use shine_graph::{Buffer, Handle, Image, RenderGraph};

/// The host's side of a frame, declared into its graph.
pub(crate) struct HostSide {
    /// The G-buffer converted from the host's images, at the frame's extent: the display
    /// size, or a context's internal resolution.
    pub g: GBuffer,
    /// Below the display size: the display-size G-buffer that guides the upsample of the
    /// outputs (`None`: `g` is at the display size).
    pub guide: Option<GBuffer>,
    /// The host's diffuse output image, imported, if it gave one.
    pub diffuse: Option<Handle<Image>>,
    /// The host's specular output image, imported, if it gave one: the traced reflections go
    /// there instead of into `diffuse`.
    pub specular: Option<Handle<Image>>,
    /// The host's environment map projected to SH, when it gave one.
    pub environment: Option<Handle<Buffer>>,
    /// The host's debug output image, imported, and the view it shows, if it gave one.
    pub debug: Option<(Handle<Image>, DebugView)>,
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
            guide,
            diffuse,
            specular,
            environment,
            debug,
        } = host(rg)?;
        let indirect = self.declare_indirect(rg, p, &handles, &g, camera, environment)?;
        if let Some((mut output, view)) = debug {
            let display = guide.as_ref().map_or(g.extent, |guide| guide.extent);
            let image = debug_view(rg, view, &indirect.debug, &g, display, camera.view_proj());
            rg.blit_image("debug to host", &image, &mut output, vk::Filter::NEAREST);
        }
        // With a specular output the reflections go there, unaccumulated (the denoiser has
        // filtered them in space; reprojecting a reflection by its surface's motion smears it).
        let (to_diffuse, to_specular) = match specular {
            Some(_) => (indirect.techniques, indirect.reflections),
            None => (indirect.summed(rg)?, None),
        };
        match diffuse {
            Some(mut output) => {
                // With a history (issue 23), the host's G-buffer is kept for the next frame's
                // disocclusion test.
                let light =
                    self.accumulate
                        .apply(rg, p.history, p.extent, to_diffuse, &g, |rg| {
                            history::gbuffer_history(rg, &g)
                        })?;
                let light = light
                    .map(|l| to_display(rg, "gi upsample", l, &g, guide.as_ref(), p))
                    .transpose()?;
                write_or_clear(rg, "gi to host", light, &mut output);
            }
            None => self.accumulate.reset(),
        }
        if let Some(mut output) = specular {
            let light = to_specular
                .map(|l| to_display(rg, "specular upsample", l, &g, guide.as_ref(), p))
                .transpose()?;
            write_or_clear(rg, "specular to host", light, &mut output);
        }
        Ok(())
    }
}

/// `light` (on `g`'s grid) at the display size: itself without a `guide`, else upsampled
/// joint-bilaterally (paper 002 eq. 11, `p.upsample`'s weights) guided by the display-size
/// G-buffer.
fn to_display(
    rg: &mut RenderGraph,
    name: &str,
    light: Handle<Image>,
    g: &GBuffer,
    guide: Option<&GBuffer>,
    p: &FrameParams,
) -> Result<Handle<Image>, RenderError> {
    Ok(match guide {
        Some(guide) => {
            let coarse = Coarse {
                position: g.position,
                normal: g.normal,
                grid: CoarseGrid::internal(guide.extent, g.extent)?,
            };
            upsample_grid(rg, name, &light, &coarse, guide, &p.upsample)
        }
        None => light,
    })
}

/// Blits `light` into the host's `output`, or clears it when the frame has none.
fn write_or_clear(
    rg: &mut RenderGraph,
    name: &str,
    light: Option<Handle<Image>>,
    output: &mut Handle<Image>,
) {
    match light {
        Some(light) => {
            rg.blit_image(name, &light, output, vk::Filter::NEAREST);
        }
        None => {
            rg.clear_image(name, output, [0.0; 4]);
        }
    }
}
