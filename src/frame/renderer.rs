//! The renderer: a scene on a device, rendered frame by frame through the render graph.
//!
//! Each frame declares its passes (docs/frame.md) into a fresh graph; the executor compiles it
//! (cached while the shape is unchanged), records it and times every pass.

use crate::gpu_bvh::GpuBvh;
use crate::gpu_scene::{BUFFER_READ, GpuScene, SAMPLED_READ, SceneUploadError};
use crate::image_io::{HdrImage, ImageIoError, LdrImage};
use crate::passes::composite::{self, CompositeOutputs, CompositeParams};
use crate::passes::direct::{self, ShadowParams};
use crate::passes::gbuffer::{self, SceneHandles};
use crate::passes::hvl::{self, GatherBrdf, HvlError, HvlParams};
use crate::passes::igi::{self, IgiError, IgiParams};
use crate::passes::proxy::ProxyError;
use crate::passes::receivers::{self, ReceiverError};
use crate::passes::shadows::{self, ShadowLayout, ShadowLayoutError};
use crate::passes::upsample::{self, UpsampleParams};
use crate::profile_report::PassClock;
use crate::proxy_frame::ProxyFrame;
use crate::settings::{Component, GiTechnique, IgiFilter, IgiGlossy};
use crate::settings::{Settings, SettingsError};
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, Sampler, vk};
use shine_graph::{
    ExecuteError, Executor, ExternalState, ImageDesc, ImageImport, PassTiming, RenderGraph,
};
use shine_scene::Scene;
use shine_sh::brdf_table::HemisphereSampling;

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

/// Frames the executor lets run ahead (transient sets and timestamp pools rotate over them).
const FRAMES_IN_FLIGHT: usize = 2;
/// Shadow-map depth bias in NDC depth units, on top of the raster slope bias.
const SHADOW_DEPTH_BIAS: f32 = 1e-4;
/// Receiver offset along its normal in shadow-map texels (removes acne at grazing angles).
const SHADOW_NORMAL_OFFSET: f32 = 1.5;

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
    /// The settings are invalid.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A read-back frame did not match its expected size.
    #[error(transparent)]
    Image(#[from] ImageIoError),
    /// The HVL passes refused their inputs or parameters.
    #[error(transparent)]
    Hvl(#[from] HvlError),
    /// The IGI passes refused their inputs or parameters.
    #[error(transparent)]
    Igi(#[from] IgiError),
    /// The proxy passes refused their inputs or parameters.
    #[error(transparent)]
    Proxy(#[from] ProxyError),
    /// The receiver or upsample pass refused its inputs.
    #[error(transparent)]
    Receivers(#[from] ReceiverError),
    /// The scene's lights do not fit one shadow atlas.
    #[error(transparent)]
    Shadows(#[from] ShadowLayoutError),
    /// `render` was called before `set_scene`.
    #[error("no scene: call set_scene first")]
    NoScene,
    /// A parameter is out of range.
    #[error("{0}")]
    Invalid(String),
}

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
    /// The scene's BVH for shadow rays (HVL visibility, IGI's VPL visibility), uploaded with
    /// the scene.
    bvh: Option<GpuBvh>,
    /// The scene's environment baked for the background (black without one).
    environment: Option<shine_gpu::Image>,
    /// Linear, repeating in u and clamped in v: the environment texture's sampler.
    environment_sampler: Sampler,
    /// The gather's BRDF SH tables on the GPU, built once per convolution band count.
    brdf_tables: Vec<(u32, Buffer)>,
    /// The shadow atlas layout of the current scene and its GPU records, for one
    /// `(shadow.size, PCF radius)`.
    shadow_layout: Option<ShadowCache>,
    /// Readback buffers of [`Renderer::render`].
    readback: Option<Readback>,
    /// The scene's proxies and environment for `--gi proxy` (paper 002).
    proxy: Option<ProxyFrame>,
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

/// A [`ShadowLayout`] and its records on the GPU.
struct ShadowCache {
    key: (u32, u32),
    layout: ShadowLayout,
    views: Buffer,
    lights: Buffer,
}

impl Renderer {
    /// A renderer on `device` (shine's own, or a host's wrapped with `Device::from_raw`).
    pub fn new(device: &Device) -> Result<Self, RenderError> {
        use vk::SamplerAddressMode as A;
        Ok(Self {
            device: device.clone(),
            executor: Executor::new(device, FRAMES_IN_FLIGHT)?,
            linear: sampler(device, vk::Filter::LINEAR, A::REPEAT, A::REPEAT)?,
            nearest: sampler(
                device,
                vk::Filter::NEAREST,
                A::CLAMP_TO_EDGE,
                A::CLAMP_TO_EDGE,
            )?,
            scene: None,
            bvh: None,
            environment: None,
            environment_sampler: sampler(device, vk::Filter::LINEAR, A::REPEAT, A::CLAMP_TO_EDGE)?,
            brdf_tables: Vec::new(),
            shadow_layout: None,
            readback: None,
            proxy: None,
        })
    }

    /// Uploads `scene` as it is at time `t` (seconds). Replacing a scene first waits for the
    /// queue to go idle: frames a host recorded with [`Renderer::record`] may still read the
    /// old one, and shine cannot see host submissions.
    pub fn set_scene(&mut self, scene: &Scene, t: f32) -> Result<(), RenderError> {
        let uploaded = GpuScene::upload(&self.device, scene, t)?;
        let bvh = GpuBvh::upload(&self.device, scene, t)?;
        let environment = crate::gpu_environment::upload(&self.device, scene.environment.as_ref())?;
        if self.scene.is_some() {
            self.device.wait_idle()?;
        }
        self.scene = Some(uploaded);
        self.bvh = Some(bvh);
        self.environment = Some(environment);
        self.shadow_layout = None;
        self.proxy = Some(ProxyFrame::new(&self.device, scene, t));
        Ok(())
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
        let frame = self.declare_frame(&mut rg, settings)?;
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

    /// Renders `count` frames without reading them back (profiling); returns the pass timings
    /// of every frame, from GPU timestamps or, with [`PassClock::Host`], from the host clock
    /// around each pass submitted alone.
    pub fn render_timed(
        &mut self,
        settings: &Settings,
        count: u32,
        clock: PassClock,
    ) -> Result<Vec<PassTiming>, RenderError> {
        settings.validate()?;
        // The frame's outputs must reach something outside the graph, or every pass is culled:
        // the LDR image is handed to a throw-away import.
        let sink = self.sink(settings)?;
        let mut timings = Vec::new();
        for _ in 0..count {
            let mut rg = self.executor.begin_frame();
            let frame = self.declare_frame(&mut rg, settings)?;
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
    /// host's image, which is left in `target.after`. The host submits `cb`; it must not record
    /// more than the executor's frames in flight (2) ahead of the GPU, and must keep the scene
    /// and this renderer alive until its submissions complete. Per-pass GPU times of earlier
    /// frames come from [`Renderer::timings`].
    pub fn record(
        &mut self,
        cb: vk::CommandBuffer,
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
        let mut rg = self.executor.begin_frame();
        let frame = self.declare_frame(&mut rg, &settings)?;
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
        self.shadow_layout
            .iter()
            .filter_map(|c| c.layout.warning.clone())
            .collect()
    }

    /// GPU times of the passes of frames whose timestamps are available.
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, RenderError> {
        Ok(self.executor.timings()?)
    }

    /// Lays out the shadow atlas of the current scene for `settings` and uploads its records,
    /// unless the cached layout already matches.
    fn prepare_shadows(&mut self, settings: &Settings) -> Result<(), RenderError> {
        let scene = self.scene.as_ref().ok_or(RenderError::NoScene)?;
        let pcf_radius = settings.shadow.filter_radius.round() as u32;
        let key = (settings.shadow.size, pcf_radius);
        if self.shadow_layout.as_ref().is_some_and(|c| c.key == key) {
            return Ok(());
        }
        let max_dimension = self.device.limits().max_image_dimension2_d;
        let layout = ShadowLayout::new(scene, settings.shadow.size, pcf_radius, max_dimension)?;
        let upload = |name, bytes: &[u8]| {
            Buffer::with_data(
                &self.device,
                &BufferDesc {
                    name,
                    size: 0,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
                bytes,
            )
        };
        let views = upload("shadow views", bytemuck::cast_slice(&layout.view_records()))?;
        let lights = upload(
            "shadow lights",
            bytemuck::cast_slice(&layout.light_records()),
        )?;
        if self.shadow_layout.is_some() {
            // Frames a host recorded with `record` may still read the old records, and shine
            // cannot see host submissions (as in `set_scene`).
            self.device.wait_idle()?;
        }
        self.shadow_layout = Some(ShadowCache {
            key,
            layout,
            views,
            lights,
        });
        Ok(())
    }

    /// Builds and uploads the BRDF SH tables ([`GatherBrdf`]) at `bands` bands unless cached.
    fn prepare_brdf_tables(&mut self, bands: u32) -> Result<(), RenderError> {
        if self.brdf_tables.iter().any(|(b, _)| *b == bands) {
            return Ok(());
        }
        let tables = GatherBrdf::build(bands, HemisphereSampling::default())?;
        let buffer = Buffer::with_data(
            &self.device,
            &BufferDesc {
                name: "brdf tables",
                size: 0,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
            bytemuck::cast_slice(&tables.gpu_data()),
        )?;
        self.brdf_tables.push((bands, buffer));
        Ok(())
    }

    /// The cached BRDF SH tables at `bands` bands, imported into `rg`.
    fn import_brdf_tables(
        &self,
        rg: &mut RenderGraph,
        bands: u32,
    ) -> Result<shine_graph::Handle<shine_graph::Buffer>, RenderError> {
        let table = self
            .brdf_tables
            .iter()
            .find(|(b, _)| *b == bands)
            .map(|(_, buffer)| buffer)
            .ok_or_else(|| RenderError::Invalid("BRDF tables missing".into()))?;
        Ok(rg.import_gpu_buffer(table, BUFFER_READ, BUFFER_READ))
    }

    /// Declares every pass of a frame; returns its HDR and LDR images.
    fn declare_frame(
        &mut self,
        rg: &mut RenderGraph,
        settings: &Settings,
    ) -> Result<CompositeOutputs, RenderError> {
        let hvl = settings.gi.contains(GiTechnique::Hvl);
        let conv_bands = settings.hvl.convolution_bands;
        if hvl {
            self.prepare_brdf_tables(conv_bands)?;
        }
        let igi_params = igi_params(settings);
        if settings.gi.contains(GiTechnique::Igi) && igi_params.needs_brdf_tables() {
            self.prepare_brdf_tables(igi_params.sh_order)?;
        }
        self.prepare_shadows(settings)?;
        let proxy = settings.gi.contains(GiTechnique::Proxy);
        if proxy {
            self.proxy
                .as_mut()
                .ok_or(RenderError::NoScene)?
                .prepare(settings)?;
        }
        let scene = self.scene.as_ref().ok_or(RenderError::NoScene)?;
        let handles = SceneHandles::import(rg, scene);
        let extent = [settings.width, settings.height];
        let camera = gbuffer::camera_view(scene, settings.width, settings.height);
        let g = gbuffer::gbuffer(rg, &handles, &camera, extent, self.linear.raw());
        let primary = scene
            .primary_light()
            .and_then(|i| Some((i as u32, gbuffer::light_view(scene, i)?)));
        let light_count = u32::try_from(scene.light_list.len())
            .map_err(|_| RenderError::Invalid("too many lights".into()))?;
        let shadow = ShadowParams {
            // The setting is a radius in texels; the kernel covers whole texels around it.
            pcf_radius: settings.shadow.filter_radius.round() as u32,
            bias: SHADOW_DEPTH_BIAS,
            normal_offset: SHADOW_NORMAL_OFFSET,
        };
        let cache = self.shadow_layout.as_ref().ok_or(RenderError::NoScene)?;
        let shadow_views = rg.import_gpu_buffer(&cache.views, BUFFER_READ, BUFFER_READ);
        let shadow_lights = rg.import_gpu_buffer(&cache.lights, BUFFER_READ, BUFFER_READ);
        let atlas = shadows::shadow_atlas(rg, &handles, &cache.layout, shadow_views, shadow_lights);
        let environment = self.environment.as_ref().ok_or(RenderError::NoScene)?;
        let background = direct::Background {
            environment: rg.import_gpu_image(environment, SAMPLED_READ, SAMPLED_READ),
            sampler: self.environment_sampler.raw(),
        };
        let direct = direct::direct(
            rg,
            &g,
            &handles,
            light_count,
            &atlas,
            &camera,
            &background,
            shadow,
            self.nearest.raw(),
        );
        let igi = settings.gi.contains(GiTechnique::Igi);
        // Receiver-resolution techniques (HVL, proxies) share one receiver buffer and one
        // upsample; `hvl,proxy` sums both at receiver resolution first.
        let recv = if hvl || proxy {
            Some(receivers::receivers(rg, &g, settings.receiver_scale)?)
        } else {
            None
        };
        let hvl_low = match (primary, &recv) {
            (Some((light, view)), Some(recv)) if hvl => {
                let params = hvl_params(settings);
                let rsm = gbuffer::rsm(
                    rg,
                    &handles,
                    view,
                    light,
                    settings.rsm.size,
                    self.linear.raw(),
                );
                let hvls = hvl::hvl_cache(rg, &rsm, &params)?;
                let brdf = self.import_brdf_tables(rg, conv_bands)?;
                let bvh = match (params.visibility, self.bvh.as_ref()) {
                    (true, Some(b)) => Some(b.import(rg, BUFFER_READ)),
                    _ => None,
                };
                Some(hvl::hvl_gather(
                    rg,
                    recv,
                    &hvls,
                    &brdf,
                    bvh.as_ref(),
                    camera.eye,
                    &params,
                )?)
            }
            _ => None,
        };
        let proxy_low = match (&self.proxy, &recv) {
            (Some(frame), Some(recv)) if proxy => Some(frame.declare(rg, recv, settings)?),
            _ => None,
        };
        let low = match (hvl_low, proxy_low) {
            (Some(a), Some(b)) => Some(crate::passes::proxy::gi_add(rg, &a, &b)?),
            (a, b) => a.or(b),
        };
        let upsampled = match (low, &recv) {
            (Some(low), Some(recv)) => {
                let upsample_params = UpsampleParams {
                    depth_sigma: settings.upsample.depth_epsilon,
                    normal_power: settings.upsample.normal_power,
                    ..UpsampleParams::default()
                };
                Some(upsample::upsample(rg, &low, recv, &g, &upsample_params)?)
            }
            _ => None,
        };
        // IGI runs at full resolution (its interleaving needs the pixel grid).
        let igi_full = match primary {
            Some((light, view)) if igi => {
                let rsm = gbuffer::rsm(
                    rg,
                    &handles,
                    view,
                    light,
                    settings.rsm.size,
                    self.linear.raw(),
                );
                let brdf = if igi_params.needs_brdf_tables() {
                    Some(self.import_brdf_tables(rg, igi_params.sh_order)?)
                } else {
                    None
                };
                let bvh = self.bvh.as_ref().ok_or(RenderError::NoScene)?;
                Some(igi_indirect(
                    rg,
                    &igi_params,
                    &g,
                    &rsm,
                    bvh,
                    brdf.as_ref(),
                    camera.eye,
                )?)
            }
            _ => None,
        };
        // `igi,proxy`: both full-resolution indirect terms summed.
        let indirect = match (upsampled, igi_full) {
            (Some(a), Some(b)) => Some(crate::passes::proxy::gi_add(rg, &a, &b)?),
            (a, b) => a.or(b),
        };
        // `[output] component`: the composite sums its two inputs; one of them alone shows a part.
        let (first, second) = match (settings.output.component, indirect.as_ref()) {
            (Component::Full, indirect) => (&direct, indirect),
            (Component::Direct, _) => (&direct, None),
            (Component::Indirect, Some(indirect)) => (indirect, None),
            (Component::Indirect, None) => {
                return Err(RenderError::Invalid(
                    "output.component = indirect needs a GI technique (this frame has none)".into(),
                ));
            }
        };
        Ok(composite::composite(
            rg,
            first,
            second,
            extent,
            &CompositeParams::from_settings(&settings.output),
        ))
    }
}

/// Paper 000's branch of the frame: VPLs from the primary light's RSM, per-pixel incident
/// radiance SH with shadow rays through `bvh`, the discontinuity filter and the BRDF; returns the
/// full-resolution indirect image (no receiver buffer: the interleaving needs the pixel grid).
fn igi_indirect(
    rg: &mut RenderGraph,
    params: &IgiParams,
    g: &gbuffer::GBuffer,
    rsm: &hvl::Rsm,
    bvh: &GpuBvh,
    brdf: Option<&shine_graph::Handle<shine_graph::Buffer>>,
    camera: glam::Vec3,
) -> Result<shine_graph::Handle<shine_graph::Image>, RenderError> {
    let trace = bvh.import(rg, BUFFER_READ);
    Ok(igi::igi(rg, g, rsm, &trace, brdf, camera, params)?)
}

/// The IGI parameters of `settings.igi` (paper 000).
pub fn igi_params(settings: &Settings) -> IgiParams {
    let i = &settings.igi;
    IgiParams {
        pattern: [i.n, i.m],
        vpl_count: i.vpl_count,
        sh_order: i.sh_order,
        filter_radius: i.filter_radius,
        mode: match i.filter {
            IgiFilter::Sh => igi::FilterMode::Sh,
            IgiFilter::Irradiance => igi::FilterMode::Irradiance,
        },
        glossy: match i.glossy {
            IgiGlossy::Ggx => igi::Glossy::Ggx,
            IgiGlossy::Phong => igi::Glossy::Phong,
        },
        clamp_distance: i.clamp_distance,
        depth_tolerance: i.depth_tolerance,
        normal_threshold: i.normal_threshold,
    }
}

/// The HVL parameters of `settings.hvl` (paper 003).
fn hvl_params(settings: &Settings) -> HvlParams {
    let h = &settings.hvl;
    HvlParams {
        count: h.count,
        radius: h.radius,
        radius_scale: h.radius_scale,
        conv_bands: h.convolution_bands,
        emission_bands: h.emission_bands,
        path: h.gather,
        visibility: h.visibility,
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
