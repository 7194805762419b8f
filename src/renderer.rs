//! The renderer: a scene on a device, rendered frame by frame through the render graph.
//!
//! Each frame declares its passes (docs/frame.md) into a fresh graph; the executor compiles it
//! (cached while the shape is unchanged), records it and times every pass.

use crate::gpu_scene::{GpuScene, SceneUploadError};
use crate::passes::direct::{self, ShadowParams};
use crate::passes::gbuffer::{self, SceneHandles};
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, Sampler, vk};
use shine_graph::{
    ExecuteError, Executor, ExternalState, Handle, Image, ImageDesc, ImageImport, PassTiming,
    RenderGraph,
};
use shine_scene::Scene;

/// Frames the executor lets run ahead (transient sets and timestamp pools rotate over them).
const FRAMES_IN_FLIGHT: usize = 2;

/// What can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A device-layer failure.
    #[error(transparent)]
    Gpu(#[from] shine_gpu::Error),
    /// The frame graph could not be compiled or recorded.
    #[error("frame graph: {0}")]
    Graph(#[from] ExecuteError),
    /// The scene could not be uploaded.
    #[error(transparent)]
    Scene(#[from] SceneUploadError),
    /// `render` was called before `set_scene`.
    #[error("no scene: call set_scene first")]
    NoScene,
    /// A parameter is out of range.
    #[error("{0}")]
    Invalid(String),
}

/// Per-frame parameters of the first frame (direct light, RSM, shadows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// Edge of the reflective shadow map (and shadow map) in texels.
    pub rsm_size: u32,
    /// Shadow filtering.
    pub shadow: ShadowParams,
}

impl Default for FrameParams {
    fn default() -> Self {
        Self {
            width: 256,
            height: 256,
            rsm_size: 512,
            shadow: ShadowParams {
                pcf_radius: 2,
                bias: 1e-4,
                normal_offset: 1.5,
            },
        }
    }
}

/// A rendered frame read back to the CPU.
#[derive(Clone, Debug)]
pub struct FrameImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear HDR radiance, RGBA, row-major from the top-left.
    pub rgba: Vec<f32>,
    /// GPU time of every pass of the frames rendered since the last readback.
    pub timings: Vec<PassTiming>,
}

/// A host engine's image that a frame is recorded into (see [`Renderer::record`]).
#[derive(Clone, Copy, Debug)]
pub struct HostTarget {
    /// The image (2D, one mip, one layer); needs `TRANSFER_DST`.
    pub image: vk::Image,
    /// A view of it (kept for the graph's bookkeeping; not sampled).
    pub view: vk::ImageView,
    /// Its format (a blit converts the frame's HDR radiance to it).
    pub format: vk::Format,
    /// Width and height; the frame is rendered at this size.
    pub extent: [u32; 2],
    /// Its usage flags.
    pub usage: vk::ImageUsageFlags,
    /// Layout, stage and access of the host's last use before the frame.
    pub before: ExternalState,
    /// Layout, stage and access of the host's next use: the frame leaves it so.
    pub after: ExternalState,
}

/// Renders scenes on a [`Device`].
pub struct Renderer {
    device: Device,
    executor: Executor,
    linear: Sampler,
    nearest: Sampler,
    scene: Option<GpuScene>,
}

impl Renderer {
    /// A renderer on `device` (shine's own, or a host's wrapped with `Device::from_raw`).
    pub fn new(device: &Device) -> Result<Self, RenderError> {
        let sampler = |filter| {
            Sampler::new(
                device,
                &vk::SamplerCreateInfo::default()
                    .mag_filter(filter)
                    .min_filter(filter)
                    .address_mode_u(vk::SamplerAddressMode::REPEAT)
                    .address_mode_v(vk::SamplerAddressMode::REPEAT)
                    .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .max_lod(0.0),
            )
        };
        Ok(Self {
            device: device.clone(),
            executor: Executor::new(device, FRAMES_IN_FLIGHT)?,
            linear: sampler(vk::Filter::LINEAR)?,
            nearest: Sampler::new(
                device,
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::NEAREST)
                    .min_filter(vk::Filter::NEAREST)
                    .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .max_lod(0.0),
            )?,
            scene: None,
        })
    }

    /// Uploads `scene` as it is at time `t` (seconds). Replacing a scene first waits for the
    /// queue to go idle: frames a host recorded with [`Renderer::record`] may still read the
    /// old one, and shine cannot see host submissions.
    pub fn set_scene(&mut self, scene: &Scene, t: f32) -> Result<(), RenderError> {
        let uploaded = GpuScene::upload(&self.device, scene, t)?;
        if self.scene.is_some() {
            self.device.wait_idle()?;
        }
        self.scene = Some(uploaded);
        Ok(())
    }

    /// Renders one frame and reads its HDR radiance back.
    pub fn render(&mut self, params: &FrameParams) -> Result<FrameImage, RenderError> {
        let FrameParams { width, height, .. } = *params;
        if width == 0 || height == 0 || params.rsm_size == 0 {
            return Err(RenderError::Invalid(format!(
                "image {width}×{height} and RSM size {} must be positive",
                params.rsm_size
            )));
        }
        let texel_bytes = 8u64; // RGBA16F
        let readback = Buffer::new(
            &self.device,
            &BufferDesc {
                name: "frame readback",
                size: u64::from(width) * u64::from(height) * texel_bytes,
                usage: vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let mut rg = self.executor.begin_frame();
        let output = self.declare_frame(&mut rg, params)?;
        let mut out = rg.import_gpu_buffer(
            &readback,
            ExternalState::UNDEFINED,
            ExternalState::new(
                vk::PipelineStageFlags2::COPY,
                vk::AccessFlags2::TRANSFER_READ,
                vk::ImageLayout::UNDEFINED,
            ),
        );
        rg.copy_image_to_buffer("readback", &output, &mut out);

        let mut commands = self.device.begin_commands()?;
        let cb = commands.raw();
        self.executor.execute(cb, rg)?;
        self.device.submit(commands)?.wait()?;
        let timings = self.executor.timings()?;
        let bytes = self.device.read_buffer(&readback)?;
        let halves: &[u16] = bytemuck::cast_slice(&bytes);
        Ok(FrameImage {
            width,
            height,
            rgba: halves.iter().map(|h| f16_to_f32(*h)).collect(),
            timings,
        })
    }

    /// Records a frame into a host command buffer, ending with the frame blitted into the
    /// host's image, which is left in `target.after`. The host submits `cb`; it must not record
    /// more than the executor's frames in flight (2) ahead of the GPU, and must keep the scene
    /// and this renderer alive until its submissions complete. Per-pass GPU times of earlier
    /// frames come from [`Renderer::timings`].
    pub fn record(
        &mut self,
        cb: vk::CommandBuffer,
        target: &HostTarget,
        params: &FrameParams,
    ) -> Result<(), RenderError> {
        let [width, height] = target.extent;
        let params = FrameParams {
            width,
            height,
            ..*params
        };
        let mut rg = self.executor.begin_frame();
        let frame = self.declare_frame(&mut rg, &params)?;
        let mut host = rg.import_vk_image(
            "host target",
            ImageDesc::new_2d(target.format, width, height),
            ImageImport {
                initial: target.before,
                final_state: target.after,
                usage: target.usage,
                read_only: false,
            },
            target.image,
            target.view,
        );
        rg.blit_image("to host", &frame, &mut host, vk::Filter::NEAREST);
        self.executor.execute(cb, rg)?;
        Ok(())
    }

    /// GPU times of the passes of frames whose timestamps are available.
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, RenderError> {
        Ok(self.executor.timings()?)
    }

    /// Declares every pass of a frame; returns the final HDR image.
    fn declare_frame(
        &self,
        rg: &mut RenderGraph,
        params: &FrameParams,
    ) -> Result<Handle<Image>, RenderError> {
        let scene = self.scene.as_ref().ok_or(RenderError::NoScene)?;
        let read_only = ExternalState::new(
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::AccessFlags2::SHADER_READ,
            vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
        );
        let buffer_read = ExternalState::new(
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::AccessFlags2::MEMORY_READ,
            vk::ImageLayout::UNDEFINED,
        );
        let handles = SceneHandles {
            vertices: rg.import_gpu_buffer(&scene.vertices, buffer_read, buffer_read),
            indices: rg.import_gpu_buffer(&scene.indices, buffer_read, buffer_read),
            materials: rg.import_gpu_buffer(&scene.materials, buffer_read, buffer_read),
            lights: rg.import_gpu_buffer(&scene.lights, buffer_read, buffer_read),
            srgb_textures: rg.import_gpu_image(&scene.srgb_textures, read_only, read_only),
            linear_textures: rg.import_gpu_image(&scene.linear_textures, read_only, read_only),
            index_count: scene.index_count,
        };
        let camera = gbuffer::camera_view(scene, params.width, params.height);
        let g = gbuffer::gbuffer(
            rg,
            &handles,
            &camera,
            [params.width, params.height],
            self.linear.raw(),
        );
        let rsm = scene
            .primary_light()
            .and_then(|i| Some((i, gbuffer::light_view(scene, i)?)))
            .map(|(i, view)| {
                gbuffer::rsm(
                    rg,
                    &handles,
                    view,
                    i as u32,
                    params.rsm_size,
                    self.linear.raw(),
                )
            });
        let light_count = u32::try_from(scene.light_list.len())
            .map_err(|_| RenderError::Invalid("too many lights".into()))?;
        Ok(direct::direct(
            rg,
            &g,
            &handles,
            light_count,
            rsm.as_ref(),
            camera.eye,
            params.shadow,
            self.nearest.raw(),
        ))
    }
}

/// IEEE 754 half to single precision (RGBA16F readback).
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        e => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}
