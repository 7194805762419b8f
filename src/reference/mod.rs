//! The path-traced reference: renders the loaded scene with `path_trace` (docs/frame.md) into
//! direct-only, indirect-only and full radiance images — the yardstick every GI technique is
//! compared against ([`crate::capture::image_compare`]).
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use shine::reference::{PathTracer, ReferenceParams};
//! let device = shine::gpu::Device::new(&shine::gpu::DeviceDesc::from_env())?;
//! let scene = shine_scene::Scene::builtin("cornell-box")?;
//! let mut tracer = PathTracer::new(&device, &scene, 0.0, &ReferenceParams::default())?;
//! tracer.accumulate(64)?;
//! let images = tracer.read()?;
//! # Ok(()) }
//! ```

pub mod aaf;
pub mod accumulate;
pub mod denoise;
pub mod hvl;
pub mod hvl_flux;
pub mod igi;
pub mod light_tables;
pub mod proxy;
pub mod resolve;
pub mod sample_history;
pub mod scene_texels;

use crate::capture::image_io::HdrImage;
use crate::frame::RenderError;
use crate::gpu_scene::environment::{ENVIRONMENT_HEIGHT, ENVIRONMENT_WIDTH};
use crate::gpu_scene::geometry::Geometry;
use crate::gpu_scene::{FrameUpdate, GpuScene};
use crate::passes::gbuffer;
use crate::passes::path_trace::{self, PathTraceParams};
use light_tables::LightTables;
use shine_gpu::{Buffer, BufferDesc, Device, Image, MemoryLocation, Sampler, vk};
use shine_graph::{Executor, ExternalState};
use shine_scene::{Material, Scene};

/// Largest image side of a reference (the accumulation buffer stays far below 128 MiB).
pub const MAX_EXTENT: u32 = 2048;
/// Largest number of bounces.
pub const MAX_BOUNCES: u32 = 64;
/// Samples per pixel of one dispatch at most (keeps each submission short on a CPU device).
const MAX_SAMPLES_PER_DISPATCH: u32 = 16;
/// Pixel-samples of one dispatch at most.
const MAX_PIXEL_SAMPLES_PER_DISPATCH: u64 = 1 << 20;

/// What the reference computes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReferenceParams {
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// Scattering vertices after the first (0: direct only; 1: one-bounce indirect, what the
    /// GI techniques compute). Default 1.
    pub bounces: u32,
    /// Jitter camera rays within their pixel (anti-aliased). Off: through pixel centres, as
    /// the raster passes sample (for pixel-exact comparisons with them). Default on.
    pub jitter: bool,
    /// Emissive surfaces light the scene (they are always seen by the camera). Off: only the
    /// punctual lights and the environment light the scene, as the raster GI techniques do.
    /// Default on.
    pub emissive_lighting: bool,
    /// Diagnostic: every surface Lambertian with albedo = base colour (white furnace).
    pub lambert_only: bool,
    /// Sample the emissive triangles and the environment at every path vertex, weighted
    /// against BRDF sampling by multiple importance sampling ([`light_tables`]). Off: their
    /// light is found only by the BRDF's rays (the same mean, more noise). Default on.
    pub light_sampling: bool,
    /// Seed of the random numbers (different seeds give independent estimates).
    pub seed: u32,
    /// `Some(limit)`: the camera's surface reflects through its specular lobe alone, by the
    /// share a GI context's traced specular takes at `specular.limit = limit`
    /// ([`path_trace::FLAG_PRIMARY_SPECULAR`]): the truth of the context's specular output.
    /// `None` (default): the whole BRDF.
    pub primary_specular: Option<f32>,
}

impl Default for ReferenceParams {
    fn default() -> Self {
        Self {
            width: 256,
            height: 256,
            bounces: 1,
            jitter: true,
            emissive_lighting: true,
            lambert_only: false,
            light_sampling: true,
            seed: 0,
            primary_specular: None,
        }
    }
}

impl ReferenceParams {
    fn validate(&self) -> Result<(), RenderError> {
        if self.width == 0
            || self.height == 0
            || self.width > MAX_EXTENT
            || self.height > MAX_EXTENT
        {
            return Err(RenderError::Invalid(format!(
                "reference size {}×{} is out of range (1..={MAX_EXTENT} per side)",
                self.width, self.height
            )));
        }
        if let Some(limit) = self.primary_specular
            && !(limit.is_finite() && limit > 0.0 && limit <= 1.0)
        {
            return Err(RenderError::Invalid(format!(
                "primary specular limit {limit} is out of range (0, 1]"
            )));
        }
        if self.bounces > MAX_BOUNCES {
            return Err(RenderError::Invalid(format!(
                "{} bounces is out of range (0..={MAX_BOUNCES})",
                self.bounces
            )));
        }
        Ok(())
    }

    fn flags(&self) -> u32 {
        let bit = |on: bool, flag: u32| if on { flag } else { 0 };
        bit(self.jitter, path_trace::FLAG_JITTER)
            | bit(self.emissive_lighting, path_trace::FLAG_EMISSIVE_LIGHTING)
            | bit(self.lambert_only, path_trace::FLAG_LAMBERT_ONLY)
            | bit(self.light_sampling, path_trace::FLAG_LIGHT_SAMPLING)
            | bit(
                self.primary_specular.is_some(),
                path_trace::FLAG_PRIMARY_SPECULAR,
            )
    }
}

/// A reference read back: mean radiance per pixel over `samples` samples.
#[derive(Clone, Debug, PartialEq)]
pub struct ReferenceImages {
    /// Light that scattered once (plus emission and background seen by the camera).
    pub direct: HdrImage,
    /// Light that scattered more than once (up to `bounces + 1` times).
    pub indirect: HdrImage,
    /// `direct + indirect`.
    pub full: HdrImage,
    /// Samples per pixel averaged.
    pub samples: u32,
}

/// A progressive path tracer of one scene at one instant ([`PathTracer::update`] moves it
/// to another and restarts the accumulation).
pub struct PathTracer {
    device: Device,
    executor: Executor,
    scene: GpuScene,
    environment: Image,
    light_tables: Buffer,
    /// Copies of the scene's buffers as images, for the shader's reads.
    texels: scene_texels::SceneTexelImages,
    /// Whether `texels` hold the scene as the next dispatch sees it (false after an upload
    /// or an update, until a dispatch copies it).
    texels_current: bool,
    /// [`LightTables::environment`] of `light_tables`.
    environment_sampling: bool,
    /// Whether any material of the scene has a texture ([`PathTraceParams::textures`]).
    textures: bool,
    texture_sampler: Sampler,
    environment_sampler: Sampler,
    accumulation: Buffer,
    params: ReferenceParams,
    /// Global index of the first sample accumulated ([`PathTracer::start_at_sample`]).
    first_sample: u32,
    samples: u32,
}

impl PathTracer {
    /// Uploads `scene` at time `t` (its geometry, BVH and environment) for references of
    /// `params`.
    pub fn new(
        device: &Device,
        scene: &Scene,
        t: f32,
        params: &ReferenceParams,
    ) -> Result<Self, RenderError> {
        params.validate()?;
        let gpu_scene = GpuScene::upload(device, scene, t)?;
        let texels = crate::gpu_scene::environment::bake(scene.environment.as_ref());
        let environment = crate::gpu_scene::environment::upload_baked(device, &texels)?;
        let tables = light_tables_of(scene, &gpu_scene, &texels)?;
        // TRANSFER_SRC: copied into an image (scene_texels).
        let light_tables = Buffer::with_data(
            device,
            &BufferDesc {
                name: "light tables",
                size: 0,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::GpuOnly,
            },
            bytemuck::cast_slice(tables.words()),
        )?;
        let scene_texels = scene_texels::SceneTexelImages::new(device, &gpu_scene, &light_tables)?;
        let sampler = |u, v| {
            Sampler::new(
                device,
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::LINEAR)
                    .min_filter(vk::Filter::LINEAR)
                    .address_mode_u(u)
                    .address_mode_v(v)
                    .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .max_lod(0.0),
            )
        };
        let pixels = u64::from(params.width) * u64::from(params.height);
        let size = pixels * path_trace::ACCUMULATION_PLANES * path_trace::ACCUMULATION_TEXEL;
        let accumulation = Buffer::with_data(
            device,
            &BufferDesc {
                name: "path trace accumulation",
                size,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC
                    | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
            &vec![0u8; size as usize],
        )?;
        Ok(Self {
            device: device.clone(),
            executor: Executor::new(device, 1)?,
            scene: gpu_scene,
            environment,
            light_tables,
            texels: scene_texels,
            texels_current: false,
            environment_sampling: tables.environment,
            textures: scene.materials.iter().any(Material::has_textures),
            texture_sampler: sampler(
                vk::SamplerAddressMode::REPEAT,
                vk::SamplerAddressMode::REPEAT,
            )?,
            environment_sampler: sampler(
                vk::SamplerAddressMode::REPEAT,
                vk::SamplerAddressMode::CLAMP_TO_EDGE,
            )?,
            accumulation,
            params: *params,
            first_sample: 0,
            samples: 0,
        })
    }

    /// Moves the scene to the instant `update` describes (the update path of the renderer:
    /// static data stays, the frame's state is uploaded by the next dispatch) and restarts
    /// the accumulation.
    pub fn update(&mut self, update: &FrameUpdate) -> Result<(), RenderError> {
        self.scene.update(update)?;
        self.texels_current = false;
        self.samples = 0;
        Ok(())
    }

    /// Restarts the accumulation at global sample index `first`: every pixel's random numbers
    /// are keyed by (seed, pixel, global sample index), so the samples `first..first + k` are
    /// those a tracer started at 0 draws after `first` samples (a shard of a reference:
    /// [`crate::farm::partial`]).
    pub fn start_at_sample(&mut self, first: u32) {
        self.first_sample = first;
        self.samples = 0;
    }

    /// Samples per pixel accumulated so far.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Samples per pixel [`PathTracer::accumulate`] adds per submission at most (a progress
    /// bar's step).
    pub fn samples_per_dispatch(&self) -> u32 {
        let pixels = u64::from(self.params.width) * u64::from(self.params.height);
        let by_pixels = (MAX_PIXEL_SAMPLES_PER_DISPATCH / pixels.max(1)).max(1);
        u32::try_from(by_pixels)
            .unwrap_or(u32::MAX)
            .min(MAX_SAMPLES_PER_DISPATCH)
    }

    /// Adds `samples` samples per pixel (in submissions of at most
    /// [`PathTracer::samples_per_dispatch`]), waiting for the GPU.
    pub fn accumulate(&mut self, samples: u32) -> Result<(), RenderError> {
        let mut left = samples;
        while left > 0 {
            let now = left.min(self.samples_per_dispatch());
            self.dispatch(now)?;
            left -= now;
        }
        Ok(())
    }

    fn dispatch(&mut self, samples: u32) -> Result<(), RenderError> {
        let sampled = crate::gpu_scene::SAMPLED_READ;
        let accumulated = ExternalState::new(
            vk::PipelineStageFlags2::ALL_COMMANDS,
            vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE,
            vk::ImageLayout::UNDEFINED,
        );
        let mut rg = self.executor.begin_frame();
        let handles = self.scene.declare(&mut rg)?;
        let frame = &self.scene.state;
        let environment = rg.import_gpu_image(&self.environment, sampled, sampled);
        let light_tables = rg.import_gpu_buffer(
            &self.light_tables,
            crate::gpu_scene::BUFFER_READ,
            crate::gpu_scene::BUFFER_READ,
        );
        let mut accumulation = rg.import_gpu_buffer(&self.accumulation, accumulated, accumulated);
        if self.samples == 0 {
            rg.fill_buffer("clear accumulation", &mut accumulation, 0);
        }
        let light_count = u32::try_from(frame.lights.len())
            .map_err(|_| RenderError::Invalid("too many lights".into()))?;
        let camera = gbuffer::camera_view(frame, self.params.width, self.params.height);
        let params = PathTraceParams {
            extent: [self.params.width, self.params.height],
            view_proj: camera.view_proj(),
            bounces: self.params.bounces,
            light_count,
            flags: self.params.flags(),
            specular_limit: self.params.primary_specular.unwrap_or(0.0),
            seed: self.params.seed,
            first_sample: self.first_sample.saturating_add(self.samples),
            samples,
            environment_sampling: self.environment_sampling,
            textures: self.textures,
        };
        let texels = self
            .texels
            .declare(&mut rg, &handles, &light_tables, !self.texels_current);
        path_trace::path_trace(
            &mut rg,
            &handles,
            &texels,
            &environment,
            &mut accumulation,
            &params,
            self.texture_sampler.raw(),
            self.environment_sampler.raw(),
        );
        let mut commands = self.device.begin_commands()?;
        self.executor.execute(commands.raw(), rg)?;
        self.device.submit(commands)?.wait()?;
        self.texels_current = true;
        self.samples = self.samples.saturating_add(samples);
        Ok(())
    }

    /// Reads the running means back (black before the first sample).
    pub fn read(&self) -> Result<ReferenceImages, RenderError> {
        let sums = self.read_sums()?;
        Ok(ReferenceImages::from_sums(
            [self.params.width, self.params.height],
            &sums,
            self.samples,
        ))
    }

    /// Reads the running sums back: the planes direct, indirect and full, each row-major, of
    /// (sum of r, g, b, samples) per pixel.
    pub fn read_sums(&self) -> Result<Vec<[f32; 4]>, RenderError> {
        let bytes = self.device.read_buffer(&self.accumulation)?;
        let sums: &[[f32; 4]] = bytemuck::try_cast_slice(&bytes)
            .map_err(|e| RenderError::Invalid(format!("accumulation readback: {e}")))?;
        Ok(sums.to_vec())
    }

    /// The scene the tracer renders.
    pub fn scene(&self) -> &GpuScene {
        &self.scene
    }
}

impl ReferenceImages {
    /// The means of `sums` ([`PathTracer::read_sums`]'s planes) over an image of `extent`,
    /// from `samples` samples per pixel.
    pub fn from_sums(extent: [u32; 2], sums: &[[f32; 4]], samples: u32) -> Self {
        let [width, height] = extent;
        let pixels = width as usize * height as usize;
        let plane = |k: usize| -> HdrImage {
            let texels = sums
                .iter()
                .skip(k * pixels)
                .take(pixels)
                .map(|s| {
                    let n = s[3].max(1.0);
                    [s[0] / n, s[1] / n, s[2] / n, 1.0]
                })
                .collect();
            HdrImage {
                width,
                height,
                texels,
            }
        };
        Self {
            direct: plane(0),
            indirect: plane(1),
            full: plane(2),
            samples,
        }
    }
}

/// The light-sampling tables of `scene` as `gpu_scene` holds it (its instances where they
/// are now; skinning and morphs only move the triangles' areas, which the shader measures
/// itself) under its baked environment `env`.
fn light_tables_of(
    scene: &Scene,
    gpu_scene: &GpuScene,
    env: &[[f32; 4]],
) -> Result<LightTables, RenderError> {
    let geometry = Geometry::flatten(scene)?;
    let emissive: Vec<[f32; 3]> = scene.materials.iter().map(|m| m.emissive).collect();
    Ok(LightTables::new(
        &geometry.source,
        &geometry.indices,
        &gpu_scene.instance_matrices(),
        &emissive,
        env,
        [ENVIRONMENT_WIDTH, ENVIRONMENT_HEIGHT],
    ))
}

/// Renders a reference of `scene` at time `t` with `samples` samples per pixel.
pub fn render_reference(
    device: &Device,
    scene: &Scene,
    t: f32,
    params: &ReferenceParams,
    samples: u32,
) -> Result<ReferenceImages, RenderError> {
    let mut tracer = PathTracer::new(device, scene, t, params)?;
    tracer.accumulate(samples)?;
    tracer.read()
}
