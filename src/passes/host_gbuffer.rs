//! `host gbuffer`: a host engine's G-buffer images, in its formats and encodings, turned into
//! the G-buffer the GI techniques read (docs/frame.md, docs/embedding.md). The GI context
//! (`crate::embed`) imports the host's images and calls [`host_gbuffer`]; the emissive and
//! hardware-depth images of a shine G-buffer are not read by any GI pass and stay unwritten.

use super::gbuffer::GBuffer;
use crate::graph::{Buffer, Handle, Image, RenderGraph, vk};
use crate::shaders;

/// The per-frame constants of `shaders/host_gbuffer.comp` (std430, 304 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HostFrame {
    /// Clip space of the host's (jittered) projection to world.
    pub inverse_view_proj: [[f32; 4]; 4],
    /// World to clip, unjittered, this frame.
    pub view_proj: [[f32; 4]; 4],
    /// World to clip, unjittered, the previous frame.
    pub previous_view_proj: [[f32; 4]; 4],
    /// Linear view depth of p is `dot(xyz, p) + w`.
    pub depth_plane: [f32; 4],
    /// Eye position (xyz).
    pub eye: [f32; 4],
    /// Normal unpack: n = normalize(texel.xyz · x + y).
    pub normal_unpack: [f32; 4],
    /// x: depth of an empty pixel; y, z: motion scale; w: 1 when roughness is squared.
    pub params: [f32; 4],
    /// x: roughness channel, y: metallic channel ([`NO_CHANNEL`]: none), z: 1 with host
    /// motion.
    pub channels: [u32; 4],
    /// Width and height (z, w unused).
    pub extent: [u32; 4],
}

/// [`HostFrame::channels`] value for "this quantity is not in the image" (read as 0).
pub const NO_CHANNEL: u32 = 4;

/// The host's images, imported into the frame's graph (sampled, display size).
#[derive(Clone, Copy, Debug)]
pub struct HostImages {
    /// Depth, through a depth-only view.
    pub depth: Handle<Image>,
    /// Encoded world-space normals.
    pub normal: Handle<Image>,
    /// Linear base colour (rgb).
    pub albedo: Handle<Image>,
    /// Roughness and metallic in the channels [`HostFrame::channels`] names.
    pub material: Handle<Image>,
    /// Motion vectors, scaled by [`HostFrame::params`] y, z; `None`: from the camera.
    pub motion: Option<Handle<Image>>,
}

/// Push constants of `shaders/host_gbuffer.comp` (8 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct HostGbufferPush {
    /// Width and height of the G-buffer written.
    pub extent: [u32; 2],
}

/// Converts the host's images into a new G-buffer of `extent` in a pass named `name`;
/// `frame` holds the frame's [`HostFrame`], `sampler` is a nearest sampler (the images are
/// fetched texel by texel). At the display size each pixel is its host texel; a smaller
/// `extent` (a context's internal resolution) takes, for each pixel, the host texel under its
/// centre `(x + 0.5)·display/extent`: one whole host sample, so position, normal and material
/// stay consistent (as the receivers do, paper 002 §4.2).
pub fn host_gbuffer(
    rg: &mut RenderGraph,
    name: &str,
    host: &HostImages,
    frame: &Handle<Buffer>,
    extent: [u32; 2],
    sampler: vk::Sampler,
) -> GBuffer {
    let [w, h] = extent;
    // Emission and hardware depth stay unwritten: no GI pass reads them.
    let mut g = GBuffer::create(rg, extent);
    rg.compute(name, &shaders::HOST_GBUFFER_COMP)
        .read("host_depth", &host.depth)
        .read("host_normal", &host.normal)
        .read("host_albedo", &host.albedo)
        .read("host_material", &host.material)
        // Without host motion the binding holds the normals, which the shader does not read.
        .read("host_motion", host.motion.as_ref().unwrap_or(&host.normal))
        .sampler("host_sampler", sampler)
        .read("frame", frame)
        .write("gb_position", &mut g.position)
        .write("gb_normal", &mut g.normal)
        .write("gb_albedo", &mut g.albedo)
        .write("gb_material", &mut g.material)
        .write("gb_geometric_normal", &mut g.geometric_normal)
        .write("gb_motion", &mut g.motion)
        .push(&HostGbufferPush { extent })
        .dispatch([w, h, 1]);
    g
}
