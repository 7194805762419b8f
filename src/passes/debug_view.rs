//! `debug_view` (`shaders/debug_view.comp`): what a GI context's techniques see, drawn at the
//! display size for the host's debug output (`GiDispatch::debug`, docs/embedding.md "Debug
//! view"): the receivers, the primary light's RSM, the virtual lights as points, AAF's samples
//! per pixel.

use glam::Mat4;

use crate::frame::RenderError;
use crate::frame::params::FrameParams;
use crate::graph::{Buffer, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::gbuffer::GBuffer;
use crate::passes::receivers::Receivers;
use crate::shaders;

/// Which picture of what the GI sees a context's debug output shows. Each needs a technique
/// that has it; a dispatch asking for one its context does not run is refused. The default is
/// [`DebugView::LightPoints`] (HVL's and IGI's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum DebugView {
    /// The receivers' world normals (rgb `0.5 n + 0.5`): the reduced-resolution G-buffer HVL,
    /// the proxies, the sky and the cubes shade, upsampled by nearest so that each receiver's
    /// block (`receiver_scale`² internal pixels) shows. Alpha 1 on surfaces, 0 (and black)
    /// on the background. Needs HVL or the proxies.
    ReceiverNormals,
    /// The receivers' albedo (linear rgb), as [`DebugView::ReceiverNormals`].
    ReceiverAlbedo,
    /// The reflective shadow map of the primary light (its first face for a point light): its
    /// flux fitted into the centred square of the output, each pixel the mean flux of the
    /// texels under it times the texel count (W: the flux the map would reflect were every
    /// texel like these). Alpha 1 inside the square. Black when the frame has no light. Needs
    /// HVL or IGI.
    Rsm,
    /// The virtual lights (HVL's HVLs, IGI's VPLs) as 3×3 dots at their centres projected by
    /// the frame's camera, coloured by their flux over its largest channel, alpha 1, over the
    /// frame's indirect light dimmed to `0.5 L / (1 + L)` (alpha 0). No depth test: lights
    /// behind surfaces are drawn too. Needs HVL or IGI.
    #[default]
    LightPoints,
    /// AAF's samples per pixel n as a heat map from blue (`aaf.spp_min`) through green to red
    /// (`spp_max · μ`), alpha n itself (0 and black on the background). Needs AAF.
    AafSamples,
}

impl DebugView {
    /// Checks that the frame of `p` has what this view shows; the message names the view,
    /// what it needs and what runs.
    pub(crate) fn check(self, p: &FrameParams) -> Result<(), RenderError> {
        let (applies, needs) = match self {
            Self::ReceiverNormals | Self::ReceiverAlbedo => (
                p.hvl.is_some() || p.proxy.is_some(),
                "a receiver-resolution technique (hvl or proxy)",
            ),
            Self::Rsm | Self::LightPoints => (
                p.hvl.is_some() || p.igi.is_some(),
                "virtual lights (hvl or igi)",
            ),
            Self::AafSamples => (p.aaf.is_some(), "aaf"),
        };
        if applies {
            return Ok(());
        }
        let running: Vec<&str> = [
            ("hvl", p.hvl.is_some()),
            ("igi", p.igi.is_some()),
            ("aaf", p.aaf.is_some()),
            ("proxy", p.proxy.is_some()),
        ]
        .into_iter()
        .filter_map(|(name, on)| on.then_some(name))
        .collect();
        Err(RenderError::Invalid(format!(
            "GI dispatch: debug view {self:?} needs {needs}; this context runs {}",
            running.join(",")
        )))
    }
}

/// Virtual light records in a frame's graph: HVL's cache or IGI's VPLs.
#[derive(Debug, Clone, Copy)]
pub struct LightRecords {
    /// The records (layout of [`crate::passes::hvl::Hvl`]).
    pub records: Handle<Buffer>,
    /// How many there are.
    pub count: u32,
}

/// AAF's per-pixel sample counts in a frame's graph.
#[derive(Debug, Clone, Copy)]
pub struct AafSpp {
    /// vec2 per pixel of the G-buffer: β, samples per pixel ([`crate::passes::aaf::AafRecords`]).
    pub widths: Handle<Buffer>,
    /// The least and largest sample counts the parameters allow (`spp_min`, `spp_max · μ`).
    pub range: [f32; 2],
}

/// What a frame's techniques declared that the debug views show; `None` where the frame has
/// none of it.
#[derive(Debug, Clone, Copy, Default)]
pub struct DebugSources {
    /// The receiver buffer (HVL, the proxies, the sky, the cubes).
    pub receivers: Option<Receivers>,
    /// The flux of the primary light's (first) RSM face.
    pub rsm_flux: Option<Handle<Image>>,
    /// HVL's or IGI's virtual lights.
    pub lights: Option<LightRecords>,
    /// AAF's samples per pixel.
    pub aaf: Option<AafSpp>,
    /// The techniques' indirect light on the G-buffer's grid (the light points' background).
    pub indirect: Option<Handle<Image>>,
}

/// Push constants of `shaders/debug_view.comp` (96 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct DebugPush {
    /// World to clip of the frame's camera (the points).
    pub view_proj: [[f32; 4]; 4],
    /// The display size (the debug image's).
    pub extent: [u32; 2],
    /// The source's size: the G-buffer's (receivers, background, samples) or the RSM's.
    pub source: [u32; 2],
    /// The samples' range ([`AafSpp::range`]).
    pub spp_range: [f32; 2],
    /// The receivers' block size.
    pub scale: u32,
    /// Light records (the points).
    pub count: u32,
}

/// Declares `view` of `sources` into a new RGBA16F image of `display` size; `g` is the frame's
/// G-buffer (its grid: the internal size) and `view_proj` the camera's world to clip. What the
/// frame lacks (no light this frame: no RSM, no lights) is left black.
pub fn debug_view(
    rg: &mut RenderGraph,
    view: DebugView,
    sources: &DebugSources,
    g: &GBuffer,
    display: [u32; 2],
    view_proj: Mat4,
) -> Handle<Image> {
    let [w, h] = display;
    let mut out = rg.create_image(
        "debug_view",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let mut push = DebugPush {
        view_proj: view_proj.to_cols_array_2d(),
        extent: display,
        source: g.extent,
        spp_range: [0.0; 2],
        scale: 1,
        count: 0,
    };
    match view {
        DebugView::ReceiverNormals | DebugView::ReceiverAlbedo => match sources.receivers {
            Some(recv) => {
                push.scale = recv.scale;
                let (shader, binding, image) = match view {
                    DebugView::ReceiverNormals => (
                        &shaders::DEBUG_VIEW_COMP_RECEIVER_NORMALS,
                        "recv_normal",
                        recv.normal,
                    ),
                    _ => (
                        &shaders::DEBUG_VIEW_COMP_RECEIVER_ALBEDO,
                        "recv_albedo",
                        recv.albedo,
                    ),
                };
                rg.compute("debug_view receivers", shader)
                    .read("recv_position", &recv.position)
                    .read(binding, &image)
                    .write("debug", &mut out)
                    .push(&push)
                    .dispatch([w, h, 1]);
            }
            None => clear(rg, &mut out),
        },
        DebugView::Rsm => match sources.rsm_flux {
            Some(flux) => {
                let size = flux.desc().extent.width;
                push.source = [size, size];
                rg.compute("debug_view rsm", &shaders::DEBUG_VIEW_COMP_RSM)
                    .read("rsm_flux", &flux)
                    .write("debug", &mut out)
                    .push(&push)
                    .dispatch([w, h, 1]);
            }
            None => clear(rg, &mut out),
        },
        DebugView::LightPoints => {
            match sources.indirect {
                Some(indirect) => {
                    rg.compute(
                        "debug_view background",
                        &shaders::DEBUG_VIEW_COMP_BACKGROUND,
                    )
                    .read("indirect", &indirect)
                    .write("debug", &mut out)
                    .push(&push)
                    .dispatch([w, h, 1]);
                }
                None => clear(rg, &mut out),
            }
            if let Some(lights) = sources.lights {
                push.count = lights.count;
                rg.compute("debug_view points", &shaders::DEBUG_VIEW_COMP_POINTS)
                    .read("lights", &lights.records)
                    .write("debug", &mut out)
                    .push(&push)
                    .dispatch([lights.count, 1, 1]);
            }
        }
        DebugView::AafSamples => match sources.aaf {
            Some(aaf) => {
                push.spp_range = aaf.range;
                rg.compute("debug_view samples", &shaders::DEBUG_VIEW_COMP_SAMPLES)
                    .read("gb_position", &g.position)
                    .read("filter_widths", &aaf.widths)
                    .write("debug", &mut out)
                    .push(&push)
                    .dispatch([w, h, 1]);
            }
            None => clear(rg, &mut out),
        },
    }
    out
}

/// Clears the debug image: the frame has nothing of the view.
fn clear(rg: &mut RenderGraph, out: &mut Handle<Image>) {
    rg.clear_image("debug_view clear", out, [0.0; 4]);
}
