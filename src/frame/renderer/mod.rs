//! The renderer: a scene on a device, rendered frame by frame through the render graph.
//!
//! Each frame declares its passes (docs/frame.md) into a fresh graph (`compose`); the
//! executor compiles it (cached while the shape is unchanged), records it and times every
//! pass.

mod compose;
mod host;
mod light_cut;
mod sky_light;

pub(crate) use host::HostSide;

use super::aaf::AafTechnique;
use super::accumulate::AccumulateTechnique;
use super::cubes::CubeTechnique;
use super::error::RenderError;
use super::exposure::ExposureTechnique;
use super::hvl::HvlTechnique;
use super::igi::IgiTechnique;
use super::memory::MemoryReport;
use super::motion::MotionState;
use super::params::FrameParams;
use super::proxy::ProxyTechnique;
use super::shadows::ShadowState;
use crate::capture::image_io::{HdrImage, LdrImage};
use crate::gpu_scene::{FrameUpdate, GpuScene};
use crate::passes::composite;
use crate::profile::report::PassClock;
use crate::settings::Settings;
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, Sampler, vk};
use shine_graph::{
    Executor, ExternalState, Handle, Image, ImageDesc, ImageImport, PassTiming, RenderGraph,
};
use shine_scene::Scene;

/// A linear or nearest sampler without mips, addressing u and v as given.
fn sampler(
    device: &Device,
    filter: vk::Filter,
    u: vk::SamplerAddressMode,
    v: vk::SamplerAddressMode,
) -> Result<Sampler, shine_gpu::Error> {
    Sampler::new(
        device,
        &vk::SamplerCreateInfo::default()
            .mag_filter(filter)
            .min_filter(filter)
            .address_mode_u(u)
            .address_mode_v(v)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0),
    )
}

/// Anisotropy of the scene textures' sampler where the device allows it.
const TEXTURE_ANISOTROPY: f32 = 16.0;

/// Mip LOD bias of the scene textures under TAA: its jittered frames resolve detail a level
/// finer than one frame can (the usual log2 of the samples per pixel along an axis, about one
/// level for TAA's 8 to 16 frames).
const TAA_LOD_BIAS: f32 = -1.0;

/// The scene textures' sampler: trilinear over the mip chain with `lod_bias`, repeating,
/// anisotropic up to [`TEXTURE_ANISOTROPY`] where the device has it enabled.
fn texture_sampler(device: &Device, lod_bias: f32) -> Result<Sampler, shine_gpu::Error> {
    let anisotropy = TEXTURE_ANISOTROPY.min(device.info().max_anisotropy);
    Sampler::new(
        device,
        &vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::REPEAT)
            .address_mode_v(vk::SamplerAddressMode::REPEAT)
            .address_mode_w(vk::SamplerAddressMode::REPEAT)
            .anisotropy_enable(anisotropy > 1.0)
            .max_anisotropy(anisotropy.max(1.0))
            .mip_lod_bias(lod_bias)
            .max_lod(vk::LOD_CLAMP_NONE),
    )
}

/// Frames a renderer lets run ahead of the GPU unless told otherwise
/// ([`Renderer::with_frames_in_flight`]).
pub const DEFAULT_FRAMES_IN_FLIGHT: usize = 2;

/// A rendered frame read back to the CPU.
#[derive(Clone, Debug)]
pub struct FrameImage {
    /// Linear HDR radiance after exposure (what EXR files hold).
    pub hdr: HdrImage,
    /// Tonemapped, sRGB-encoded (what PNG files hold).
    pub ldr: LdrImage,
    /// GPU time of every pass of the frames rendered since the last readback.
    pub timings: Vec<PassTiming>,
}

/// A host engine's image that shine reads or writes in a frame: the target of a whole frame
/// ([`Renderer::record`]: needs `TRANSFER_DST`; a blit converts the frame's HDR radiance to its
/// format), or an input or the output of a GI dispatch (`crate::embed::GiDispatch`: inputs
/// need `SAMPLED`, the output `TRANSFER_DST`).
#[derive(Clone, Copy, Debug)]
pub struct HostTarget {
    /// The image (2D, one mip, one layer).
    pub image: vk::Image,
    /// A view of the whole image: inputs are sampled through it. An image that is only
    /// written by a blit may pass `vk::ImageView::null()` (a transfer-only image cannot have a
    /// view, VUID-VkImageViewCreateInfo-image-04441).
    pub view: vk::ImageView,
    /// Its format.
    pub format: vk::Format,
    /// Width and height, exactly the image's: Vulkan cannot tell shine a `VkImage`'s size, so
    /// a larger extent than the image's reads and writes outside it (garbage, not an error).
    pub extent: [u32; 2],
    /// Its usage flags, as created: an access needing more is refused.
    pub usage: vk::ImageUsageFlags,
    /// Layout, stage and access of the host's last use before the frame.
    pub before: ExternalState,
    /// Layout, stage and access of the host's next use: the frame leaves it so.
    pub after: ExternalState,
}

impl HostTarget {
    /// The image in a frame's graph as `name`, entering in `before` and left in `after`;
    /// `read_only` for the host's inputs.
    pub(crate) fn import(
        &self,
        rg: &mut RenderGraph,
        name: &str,
        read_only: bool,
    ) -> Handle<Image> {
        rg.import_vk_image(
            name,
            ImageDesc::new_2d(self.format, self.extent[0], self.extent[1]),
            ImageImport {
                initial: self.before,
                final_state: self.after,
                usage: self.usage,
                read_only,
            },
            self.image,
            self.view,
        )
    }
}

/// Renders scenes on a [`Device`]: the scene's resources, the techniques' persistent state, and
/// the composition of every frame's passes (`Renderer::declare_frame`).
pub struct Renderer {
    device: Device,
    executor: Executor,
    /// Frames the caller lets run ahead of the GPU.
    frames_in_flight: usize,
    /// Trilinear, repeating: the scene textures' sampler.
    textures: Sampler,
    /// The scene textures' sampler under TAA: trilinear, a level finer ([`TAA_LOD_BIAS`]).
    textures_taa: Sampler,
    /// Bilinear on level 0, repeating: the scene textures' sampler without mipmaps, and at ray
    /// hits.
    textures_level0: Sampler,
    nearest: Sampler,
    /// Linear, repeating in u and clamped in v: the environment texture's sampler.
    environment_sampler: Sampler,
    /// The current scene on the device.
    scene: Option<SceneState>,
    /// The shadow atlas layout of the current scene and its records.
    shadows: Option<ShadowState>,
    /// Harmonics Virtual Lights (paper 003).
    hvl: HvlTechnique,
    /// Instant GI (paper 000).
    igi: IgiTechnique,
    /// Axis-aligned filtering of path-traced indirect light (paper 004).
    aaf: AafTechnique,
    /// The previous frame's camera, for motion vectors.
    motion: MotionState,
    /// The indirect light's history (issue 23).
    accumulate: AccumulateTechnique,
    /// The direct light's history under TAA (issue 21).
    taa: AccumulateTechnique,
    /// The automatic exposure's history (issue 21).
    exposure: ExposureTechnique,
    /// Readback buffers of [`Renderer::render`].
    readback: Option<Readback>,
}

/// A scene on the device: what every frame of it reads.
struct SceneState {
    /// Geometry, materials, textures, the two-level BVH and the current frame's state.
    gpu: GpuScene,
    /// The environment baked for the background (black without one).
    environment: shine_gpu::Image,
    /// Whether the scene has an environment (it lights the specular pass's ray hits).
    has_environment: bool,
    /// Sphere proxies under the environment (paper 002): scene-bound state.
    proxy: ProxyTechnique,
    /// Tiny environment cubes of the dynamic objects (paper 001): scene-bound state.
    cubes: CubeTechnique,
}

/// The buffers a rendered frame is copied into, kept while the frame size is unchanged.
struct Readback {
    extent: [u32; 2],
    hdr: Buffer,
    ldr: Buffer,
}

impl Readback {
    fn new(device: &Device, extent: [u32; 2]) -> Result<Self, RenderError> {
        let pixels = u64::from(extent[0]) * u64::from(extent[1]);
        let buffer = |name, bytes_per_texel: u64| {
            Buffer::new(
                device,
                &BufferDesc {
                    name,
                    size: pixels * bytes_per_texel,
                    usage: vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::GpuOnly,
                },
            )
        };
        Ok(Self {
            extent,
            hdr: buffer("hdr readback", 16)?,
            ldr: buffer("ldr readback", 4)?,
        })
    }
}

impl Renderer {
    /// A renderer on `device` (shine's own, or a host's wrapped with `Device::from_raw`)
    /// letting [`DEFAULT_FRAMES_IN_FLIGHT`] frames run ahead of the GPU.
    pub fn new(device: &Device) -> Result<Self, RenderError> {
        Self::with_frames_in_flight(device, DEFAULT_FRAMES_IN_FLIGHT)
    }

    /// A renderer whose caller lets up to `frames_in_flight` (at least 1) recorded frames run
    /// ahead of the GPU: per-frame resources (transients, descriptor sets, timestamps, staging
    /// rings) come in that many slots.
    pub fn with_frames_in_flight(
        device: &Device,
        frames_in_flight: usize,
    ) -> Result<Self, RenderError> {
        use vk::SamplerAddressMode as A;
        Ok(Self {
            device: device.clone(),
            executor: Executor::new(device, frames_in_flight)?,
            frames_in_flight: frames_in_flight.max(1),
            textures: texture_sampler(device, 0.0)?,
            textures_taa: texture_sampler(device, TAA_LOD_BIAS)?,
            textures_level0: sampler(device, vk::Filter::LINEAR, A::REPEAT, A::REPEAT)?,
            nearest: sampler(
                device,
                vk::Filter::NEAREST,
                A::CLAMP_TO_EDGE,
                A::CLAMP_TO_EDGE,
            )?,
            environment_sampler: sampler(device, vk::Filter::LINEAR, A::REPEAT, A::CLAMP_TO_EDGE)?,
            scene: None,
            shadows: None,
            hvl: HvlTechnique::new(device),
            igi: IgiTechnique::new(device),
            aaf: AafTechnique::new(device),
            motion: MotionState::new(device)?,
            accumulate: AccumulateTechnique::new("accumulate", "accumulated indirect"),
            taa: AccumulateTechnique::new("taa", "taa direct"),
            exposure: ExposureTechnique::default(),
            readback: None,
        })
    }

    /// Uploads the static data of `scene` (meshes, materials, textures, the BVH's bottom
    /// levels) and poses it at time `t` (seconds); later frames change only what
    /// [`Renderer::update`] sends. The upload itself waits for its copies (a load-time call);
    /// the scene it replaces is destroyed only once the frames that read it have completed
    /// (shine's own submissions, or the host frames of [`Renderer::record`]), without waiting.
    pub fn set_scene(&mut self, scene: &Scene, t: f32) -> Result<(), RenderError> {
        let state = SceneState {
            gpu: GpuScene::upload(&self.device, scene, t)?,
            environment: crate::gpu_scene::environment::upload(
                &self.device,
                scene.environment.as_ref(),
            )?,
            has_environment: scene.environment.is_some(),
            proxy: ProxyTechnique::new(&self.device, scene),
            cubes: CubeTechnique::new(&self.device, scene),
        };
        self.scene = Some(state);
        self.shadows = None;
        self.motion.reset();
        self.hvl.reset();
        self.igi.reset();
        self.aaf.reset();
        self.accumulate.reset();
        self.taa.reset();
        self.exposure.reset();
        Ok(())
    }

    /// Sets what the next frames show: scene time (animation), camera, node transforms,
    /// lights, jitter. CPU work only; the next frame uploads the result through its own
    /// `update …` passes, without waiting for the GPU. A bad update is refused (nothing
    /// changes).
    ///
    /// A light cut (`LIGHT_CUT_RATIO`: a light switched on or off, or its power
    /// changed more than that) restarts the indirect light's histories.
    pub fn update(&mut self, update: &FrameUpdate) -> Result<(), RenderError> {
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        let before = scene.gpu.state.lights.clone();
        scene.gpu.update(update)?;
        if light_cut::is_light_cut(&before, &scene.gpu.state.lights) {
            self.restart_indirect();
        }
        Ok(())
    }

    /// Replaces the deltas of morph target `[mesh, primitive, target]` for the next frame on
    /// ([`GpuScene::set_morph_target`](crate::gpu_scene::GpuScene::set_morph_target)): how
    /// a host's deformed vertices arrive. CPU work; the next frame uploads them.
    pub fn set_morph_target(
        &mut self,
        [mesh, primitive, target]: [usize; 3],
        positions: &[glam::Vec3],
        normals: &[glam::Vec3],
    ) -> Result<(), RenderError> {
        let scene = self.scene.as_mut().ok_or(RenderError::NoScene)?;
        Ok(scene
            .gpu
            .set_morph_target(mesh, primitive, target, positions, normals)?)
    }

    /// Numbers the next frame `frame` (forward only), as frame `frame` of a sequence whose
    /// earlier frames another process renders: what depends on the frame number (TAA's
    /// jitter, amortised slices, IGI's interleaving) then matches a one-process run. The
    /// histories stay empty until this renderer's own frames fill them.
    pub fn skip_to_frame(&mut self, frame: u64) -> Result<(), RenderError> {
        if self.executor.skip_to_frame(frame) {
            Ok(())
        } else {
            Err(RenderError::Invalid(format!(
                "cannot number the next frame {frame}: frame {} is next already",
                self.executor.frame()
            )))
        }
    }

    /// Renders one frame with `settings` and reads its HDR and LDR images back.
    pub fn render(&mut self, settings: &Settings) -> Result<FrameImage, RenderError> {
        settings.validate()?;
        let (width, height) = (settings.width, settings.height);
        let readback = match self.readback.take() {
            Some(r) if r.extent == [width, height] => r,
            _ => Readback::new(&self.device, [width, height])?,
        };
        let mut rg = self.executor.begin_frame();
        let frame = self.declare_frame(&mut rg, &FrameParams::from_settings(settings))?;
        let read_by_copy = ExternalState::new(
            vk::PipelineStageFlags2::COPY,
            vk::AccessFlags2::TRANSFER_READ,
            vk::ImageLayout::UNDEFINED,
        );
        let mut hdr_out =
            rg.import_gpu_buffer(&readback.hdr, ExternalState::UNDEFINED, read_by_copy);
        let mut ldr_out =
            rg.import_gpu_buffer(&readback.ldr, ExternalState::UNDEFINED, read_by_copy);
        rg.copy_image_to_buffer("readback hdr", &frame.hdr, &mut hdr_out);
        rg.copy_image_to_buffer("readback ldr", &frame.ldr, &mut ldr_out);
        self.run(rg)?;
        let timings = self.executor.timings()?;
        let image = FrameImage {
            hdr: HdrImage::from_rgba32f_bytes(
                width,
                height,
                &self.device.read_buffer(&readback.hdr)?,
            )?,
            ldr: LdrImage::from_rgba8_bytes(
                width,
                height,
                &self.device.read_buffer(&readback.ldr)?,
            )?,
            timings,
        };
        self.readback = Some(readback);
        Ok(image)
    }

    /// Renders `count` frames without reading them back (profiling), frame `k` after
    /// [`Renderer::update`] with `update(k)` (the update path, as a host drives it); returns
    /// the pass timings of every frame, from GPU timestamps or, with [`PassClock::Host`], from
    /// the host clock around each pass submitted alone.
    pub fn render_timed(
        &mut self,
        settings: &Settings,
        count: u32,
        clock: PassClock,
        update: &dyn Fn(u32) -> FrameUpdate,
    ) -> Result<Vec<PassTiming>, RenderError> {
        settings.validate()?;
        // The frame's outputs must reach something outside the graph, or every pass is culled:
        // the LDR image is handed to a throw-away import.
        let sink = self.sink(settings)?;
        let params = FrameParams::from_settings(settings);
        let mut timings = Vec::new();
        for k in 0..count {
            self.update(&update(k))?;
            let mut rg = self.executor.begin_frame();
            let frame = self.declare_frame(&mut rg, &params)?;
            let mut out = rg.import_gpu_image(
                &sink,
                ExternalState::UNDEFINED,
                ExternalState::new(
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    vk::AccessFlags2::MEMORY_READ,
                    vk::ImageLayout::GENERAL,
                ),
            );
            rg.blit_image("present", &frame.ldr, &mut out, vk::Filter::NEAREST);
            match clock {
                PassClock::Gpu => {
                    self.run(rg)?;
                    timings.extend(self.executor.timings()?);
                }
                PassClock::Host => timings.extend(self.executor.execute_serialized(rg)?.1),
            }
        }
        Ok(timings)
    }

    fn sink(&self, settings: &Settings) -> Result<shine_gpu::Image, RenderError> {
        Ok(shine_gpu::Image::new(
            &self.device,
            &shine_gpu::ImageDesc::new_2d(
                "profile sink",
                [settings.width, settings.height],
                composite::LDR_FORMAT,
                vk::ImageUsageFlags::TRANSFER_DST,
            ),
        )?)
    }

    /// Records, submits and waits for one frame graph.
    fn run(&mut self, rg: RenderGraph) -> Result<(), RenderError> {
        let mut commands = self.device.begin_commands()?;
        let cb = commands.raw();
        self.executor.execute(cb, rg)?;
        self.device.submit(commands)?.wait()?;
        Ok(())
    }

    /// Records a frame into a host command buffer, ending with the frame blitted into the
    /// host's image, which is left in `target.after`. Neither submits nor waits. The host
    /// submits `cb` as its frame `frame_index` (increasing), promising that its frame
    /// `frame_index − frames in flight` has completed ([`Device::begin_host_frame`]: what
    /// shine drops is destroyed only after the host frames that may use it). Per-pass GPU
    /// times of earlier frames come from [`Renderer::timings`].
    pub fn record(
        &mut self,
        cb: vk::CommandBuffer,
        frame_index: u64,
        target: &HostTarget,
        settings: &Settings,
    ) -> Result<(), RenderError> {
        let [width, height] = target.extent;
        let settings = Settings {
            width,
            height,
            ..settings.clone()
        };
        settings.validate()?;
        self.begin_host_frame(frame_index);
        let mut rg = self.executor.begin_frame();
        let frame = self.declare_frame(&mut rg, &FrameParams::from_settings(&settings))?;
        let mut host = target.import(&mut rg, "host target", false);
        // The tonemapped image for a UNORM/sRGB target, the HDR one for a float target.
        let source = if is_float(target.format) {
            frame.hdr
        } else {
            frame.ldr
        };
        rg.blit_image("to host", &source, &mut host, vk::Filter::NEAREST);
        self.executor.execute(cb, rg)?;
        Ok(())
    }

    /// What the last frame had to compromise on (e.g. shadow tiles shrunk to fit the device),
    /// for the caller to report.
    pub fn warnings(&self) -> Vec<String> {
        self.shadows
            .iter()
            .filter_map(|s| s.warning().map(str::to_owned))
            .collect()
    }

    /// The device memory this renderer holds, by category (see [`MemoryReport`]); objects
    /// waiting for destruction are the device's, shared by every renderer on it.
    pub fn memory_report(&self) -> MemoryReport {
        let mut report = MemoryReport::default();
        let mut add = |(owned, staging): (u64, u64), gi: bool| {
            if gi {
                report.gi_caches += owned;
            } else {
                report.frame_data += owned;
            }
            report.staging += staging;
        };
        add(self.hvl.allocated_bytes(), true);
        add(self.igi.allocated_bytes(), true);
        add(self.motion.allocated_bytes(), false);
        if let Some(shadows) = &self.shadows {
            add(shadows.allocated_bytes(), false);
        }
        if let Some(scene) = &self.scene {
            add(scene.proxy.allocated_bytes(), true);
            add(scene.cubes.allocated_bytes(), true);
            let (data, staging) = scene.gpu.allocated_bytes();
            report.scene += data + scene.environment.allocated_bytes();
            report.staging += staging;
        }
        if let Some(r) = &self.readback {
            report.frame_data += r.hdr.allocated_bytes() + r.ldr.allocated_bytes();
        }
        (report.transients, report.history) = self.executor.memory();
        report.pending_release = self.device.pending_destruction_bytes();
        report
    }

    /// Tells the device a host frame is being recorded (deferred destruction follows the
    /// host's frames from now on).
    pub(crate) fn begin_host_frame(&self, frame_index: u64) {
        self.device
            .begin_host_frame(frame_index, self.frames_in_flight as u32);
    }

    /// GPU times of the passes of frames whose timestamps are available.
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, RenderError> {
        Ok(self.executor.timings()?)
    }
}

/// Whether a format holds floats (the HDR image is blitted to it) rather than normalised
/// integers (the tonemapped image is).
fn is_float(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::R16G16B16A16_SFLOAT
            | vk::Format::R32G32B32A32_SFLOAT
            | vk::Format::B10G11R11_UFLOAT_PACK32
            | vk::Format::R16G16B16_SFLOAT
            | vk::Format::R32G32B32_SFLOAT
    )
}
