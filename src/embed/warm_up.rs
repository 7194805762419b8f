//! The inputs of a [`super::GiContext::warm_up`]: display-sized placeholder G-buffer images
//! of the context's own, cleared to a plain lit floor, so that warm-up frames build the graph
//! a host's dispatch builds (every pipeline, plan and transient set) before the host's first
//! frame.

use super::inputs::{
    DepthConvention, GiCamera, GiDispatch, HostEnvironment, HostMotion, MaterialChannels,
    NormalEncoding,
};
use crate::frame::renderer::HostTarget;
use crate::passes::debug_view::DebugView;
use glam::Vec3;
use shine_gpu::{Commands, Device, Image, ImageDesc, format_aspect, vk};
use shine_graph::ExternalState;

/// What a host's dispatches bring beyond the required G-buffer images: each adds to the
/// frame's graph, so [`super::GiContext::warm_up`] builds the graph of the shape the host
/// will dispatch.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DispatchShape {
    /// Dispatches bring motion vectors ([`GiDispatch::motion`]).
    pub motion: bool,
    /// Dispatches bring an environment map ([`GiDispatch::environment`]).
    pub environment: bool,
    /// Dispatches ask for a separate specular output ([`GiDispatch::specular`]).
    pub specular: bool,
}

/// Frames a warm-up records: one per frame-in-flight slot, plus one so that every slot also
/// sees a frame with history (the first frame after a reset has none, and builds a smaller
/// graph).
pub(super) fn warm_up_frames(frames_in_flight: usize) -> usize {
    frames_in_flight.max(1) + 1
}

/// Width and height of the placeholder environment map (its size changes no pipeline).
const ENVIRONMENT_EXTENT: [u32; 2] = [16, 8];

/// Placeholder inputs and output of a context's warm-up frames.
pub(super) struct Placeholders {
    depth: Image,
    normal: Image,
    albedo: Image,
    material: Image,
    motion: Image,
    environment: Image,
    output: Image,
    specular: Image,
    display: [u32; 2],
}

/// What a cleared placeholder holds: a floor at mid depth facing the camera, grey, rough.
const CLEARS: [(&str, vk::Format, [f32; 4]); 7] = [
    (
        "warm-up normal",
        vk::Format::R8G8B8A8_UNORM,
        [0.5, 0.5, 1.0, 0.0],
    ),
    (
        "warm-up albedo",
        vk::Format::R8G8B8A8_UNORM,
        [0.5, 0.5, 0.5, 1.0],
    ),
    (
        "warm-up material",
        vk::Format::R8G8B8A8_UNORM,
        [0.5, 0.0, 0.0, 0.0],
    ),
    ("warm-up motion", vk::Format::R16G16_SFLOAT, [0.0; 4]),
    (
        "warm-up environment",
        vk::Format::R16G16B16A16_SFLOAT,
        [0.1, 0.1, 0.1, 1.0],
    ),
    ("warm-up output", vk::Format::R16G16B16A16_SFLOAT, [0.0; 4]),
    (
        "warm-up specular",
        vk::Format::R16G16B16A16_SFLOAT,
        [0.0; 4],
    ),
];

/// The depth a placeholder pixel holds (standard convention: mid-way into the scene).
const CLEAR_DEPTH: f32 = 0.5;

/// Where every placeholder is left after its clear.
const CLEARED: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::CLEAR,
    vk::AccessFlags2::TRANSFER_WRITE,
    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
);

impl Placeholders {
    /// Placeholders for a `display`-sized context.
    pub(super) fn new(device: &Device, display: [u32; 2]) -> Result<Self, shine_gpu::Error> {
        let usage = vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST;
        let image = |i: usize, extent: [u32; 2]| {
            let (name, format, _) = CLEARS[i];
            Image::new(device, &ImageDesc::new_2d(name, extent, format, usage))
        };
        Ok(Self {
            depth: Image::new(
                device,
                &ImageDesc::new_2d("warm-up depth", display, vk::Format::D32_SFLOAT, usage),
            )?,
            normal: image(0, display)?,
            albedo: image(1, display)?,
            material: image(2, display)?,
            motion: image(3, display)?,
            environment: image(4, ENVIRONMENT_EXTENT)?,
            output: image(5, display)?,
            specular: image(6, display)?,
            display,
        })
    }

    /// Records the clears of every placeholder, leaving each in [`CLEARED`].
    pub(super) fn clear(&self, cmd: &mut Commands) {
        let colours = [
            &self.normal,
            &self.albedo,
            &self.material,
            &self.motion,
            &self.environment,
            &self.output,
            &self.specular,
        ];
        for image in colours.iter().copied().chain([&self.depth]) {
            cmd.image_barrier(
                image.raw(),
                range(image.format()),
                (
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                ),
                (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE),
                (CLEARED.stage, CLEARED.access),
            );
        }
        let raw = cmd.raw();
        let device = cmd.device().raw().clone();
        for (image, (_, _, value)) in colours.into_iter().zip(CLEARS) {
            let colour = vk::ClearColorValue { float32: value };
            // SAFETY: the image is in TRANSFER_DST_OPTIMAL (the barrier above) and has
            // TRANSFER_DST usage.
            unsafe {
                device.cmd_clear_color_image(
                    raw,
                    image.raw(),
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &colour,
                    &[range(image.format())],
                );
            }
        }
        let depth = vk::ClearDepthStencilValue {
            depth: CLEAR_DEPTH,
            stencil: 0,
        };
        // SAFETY: as above.
        unsafe {
            device.cmd_clear_depth_stencil_image(
                raw,
                self.depth.raw(),
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &depth,
                &[range(self.depth.format())],
            );
        }
    }

    /// A dispatch of the placeholders (cleared in the same command buffer) of `shape`.
    pub(super) fn dispatch(&self, frame_index: u64, shape: DispatchShape) -> GiDispatch {
        let [w, h] = self.display;
        let camera = GiCamera::look_at(
            Vec3::new(0.0, 1.0, 3.0),
            Vec3::ZERO,
            1.0,
            w as f32 / h as f32,
            0.1,
            100.0,
        );
        let sampled = ExternalState::new(
            vk::PipelineStageFlags2::COMPUTE_SHADER,
            vk::AccessFlags2::SHADER_SAMPLED_READ,
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        );
        // Every frame clears again, so each enters as the clear left it.
        let target = |image: &Image, after: ExternalState| HostTarget {
            image: image.raw(),
            view: image.view(),
            format: image.format(),
            extent: image.extent(),
            usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
            before: CLEARED,
            after,
        };
        GiDispatch {
            frame_index,
            camera,
            depth: target(&self.depth, sampled),
            depth_convention: DepthConvention::Standard,
            normals: target(&self.normal, sampled),
            normal_encoding: NormalEncoding::UNORM,
            albedo: target(&self.albedo, sampled),
            material: target(&self.material, sampled),
            material_channels: MaterialChannels::default(),
            motion: shape.motion.then(|| HostMotion {
                image: target(&self.motion, sampled),
                scale: [-1.0, -1.0],
            }),
            environment: shape.environment.then(|| HostEnvironment {
                image: target(&self.environment, sampled),
                intensity: 1.0,
            }),
            diffuse: Some(target(&self.output, ExternalState::UNDEFINED)),
            specular: shape
                .specular
                .then(|| target(&self.specular, ExternalState::UNDEFINED)),
            debug: None,
            debug_view: DebugView::default(),
        }
    }
}

/// The whole of an image of `format` (one mip, one layer).
fn range(format: vk::Format) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange::default()
        .aspect_mask(format_aspect(format))
        .level_count(1)
        .layer_count(1)
}
