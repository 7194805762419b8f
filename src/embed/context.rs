//! [`GiContext`]: shine as a GI pass inside a host engine's frame.

use super::budget_pick;
use super::host_geometry::{self, HostInstance, HostMesh, MeshId, Registered};
use super::inputs::GiDispatch;
use super::resolution::InternalResolution;
use super::warm_up::{DispatchShape, Placeholders, warm_up_frames};
use crate::frame::RenderError;
use crate::frame::memory::MemoryReport;
use crate::frame::params::FrameParams;
use crate::frame::renderer::HostSide;
use crate::frame::renderer::Renderer;
use crate::gpu_scene::FrameUpdate;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::lab::budget::BudgetChoice;
use crate::passes::environment_sh;
use crate::passes::host_gbuffer::{self, HostFrame, HostImages};
use crate::settings::Settings;
use shine_gpu::{Buffer, Device, Sampler, vk};
use shine_graph::{PassTiming, RenderGraph};
use shine_scene::{Light, Scene};

/// How a [`GiContext`] is made: fixed for its life (make a new context to change them).
#[derive(Clone, Debug, PartialEq)]
pub struct GiContextDesc {
    /// Width and height of the host's G-buffer and of the output.
    pub display: [u32; 2],
    /// How many frames the host records ahead of the GPU (at least 1): per-frame resources
    /// come in that many slots.
    pub frames_in_flight: usize,
    /// The technique and its options, as for a full frame: `gi` picks the technique(s),
    /// `receiver_scale` the internal scale of the receiver-resolution ones (HVL, proxies),
    /// `hvl.count` the HVL budget, `[igi]`, `[proxy]`, `[aaf]`, `[rsm]`, `[upsample]` the
    /// rest. `width`, `height` and everything about direct light and output are not used.
    pub settings: Settings,
    /// The most lights and proxy spheres a scene may bring (a larger one is refused).
    pub budgets: GiBudgets,
    /// The share of the display size the light is computed at, then upsampled to the display
    /// ([`InternalResolution`]; default: the display size).
    pub internal_resolution: InternalResolution,
    /// A frame budget in ms: the context picks the GI configuration with the least error whose
    /// cost fits, from `shine lab`'s results for this device at the internal size (every
    /// scene's, at creation); without results, from a quick lab of a few candidates on the
    /// first scene (`set_scene`, which then takes seconds). The pick replaces `settings`'
    /// technique keys; [`GiContext::budget_choice`] tells what was chosen. Costed at the
    /// internal size (`internal_resolution`; the upsample to the display is not counted).
    /// `None`: `settings` as given.
    pub budget_ms: Option<f64>,
}

/// Upper bounds on what a scene handed to a [`GiContext`] may hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GiBudgets {
    /// Punctual lights.
    pub lights: u32,
    /// Sphere proxies (paper 002).
    pub proxies: u32,
}

impl Default for GiBudgets {
    /// 64 lights and 256 proxy spheres.
    fn default() -> Self {
        Self {
            lights: 64,
            proxies: 256,
        }
    }
}

impl GiContextDesc {
    /// A context of `display` size running `technique` (`"hvl"`, `"igi"`, `"hvl,proxy"` …)
    /// with default options, two frames in flight and default budgets.
    pub fn new(display: [u32; 2], technique: &str) -> Result<Self, RenderError> {
        Ok(Self {
            display,
            frames_in_flight: crate::frame::renderer::DEFAULT_FRAMES_IN_FLIGHT,
            settings: Settings {
                gi: technique.parse()?,
                ..Settings::default()
            },
            budgets: GiBudgets::default(),
            internal_resolution: InternalResolution::default(),
            budget_ms: None,
        })
    }
}

/// shine's indirect light as a pass of a host engine's frame, the way FidelityFX's GI
/// effects are integrated: made once on the host's device ([`Device::from_raw`]), given a
/// scene ([`GiContext::set_scene`]) and per-frame changes ([`GiContext::update`]), then
/// [`GiContext::dispatch`] records one frame into the host's command buffer from the host's
/// G-buffer. Nothing it does on the frame path submits or waits (docs/embedding.md).
///
/// `GiContext` is `Send` (move it to a render thread) but not `Sync`: calls on one context
/// come from one thread at a time. Contexts on one device are independent.
pub struct GiContext {
    renderer: Renderer,
    /// The device, for the budget's quick lab.
    device: Device,
    display: [u32; 2],
    budgets: GiBudgets,
    /// The share of the display the light is computed at.
    internal: InternalResolution,
    /// The options of the context's description.
    settings: Settings,
    /// What each frame computes, at the internal size.
    params: FrameParams,
    /// The device buffer of the frame's [`HostFrame`], rewritten every dispatch.
    frame_constants: Buffer,
    ring: UploadRing,
    nearest: Sampler,
    /// The last dispatched host frame (frame numbers must increase).
    last_frame: Option<u64>,
    /// The frame budget of the description, and what it chose (`None` until chosen).
    budget: Option<(f64, Option<BudgetChoice>)>,
    /// Frames the host records ahead of the GPU.
    frames_in_flight: usize,
    /// Meshes registered from the host's buffers, by [`MeshId`].
    host_meshes: Vec<Registered>,
    /// The instances, the number of lights and the number of meshes of the last
    /// [`GiContext::set_instances`] (`None` after a [`GiContext::set_scene`] of the host's
    /// own scene).
    host_world: Option<(Vec<HostInstance>, usize, usize)>,
}

impl GiContext {
    /// A context on `device` as `desc` says; nothing of a scene is uploaded yet.
    pub fn new(device: &Device, desc: &GiContextDesc) -> Result<Self, RenderError> {
        let mut settings = desc.settings.clone();
        let budget = match desc.budget_ms {
            Some(ms) if !(ms.is_finite() && ms > 0.0) => {
                return Err(RenderError::Invalid(format!(
                    "GI context: budget_ms {ms} must be a positive number of ms"
                )));
            }
            Some(ms) => {
                let internal = desc.internal_resolution.extent(desc.display);
                let choice = budget_pick::from_results(device, internal, ms)?;
                if let Some(c) = &choice {
                    budget_pick::apply(&mut settings, c)?;
                }
                Some((ms, choice))
            }
            None => None,
        };
        Ok(Self {
            renderer: Renderer::with_frames_in_flight(device, desc.frames_in_flight)?,
            device: device.clone(),
            display: desc.display,
            budgets: desc.budgets,
            internal: desc.internal_resolution,
            params: frame_params(&settings, desc.internal_resolution.extent(desc.display))?,
            settings,
            frame_constants: Buffer::storage_for_uploads(
                device,
                "host frame",
                std::mem::size_of::<HostFrame>() as u64,
            )?,
            ring: UploadRing::new(device),
            nearest: Sampler::new(
                device,
                &vk::SamplerCreateInfo::default()
                    .mag_filter(vk::Filter::NEAREST)
                    .min_filter(vk::Filter::NEAREST)
                    .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
                    .max_lod(0.0),
            )?,
            last_frame: None,
            budget,
            frames_in_flight: desc.frames_in_flight,
            host_meshes: Vec::new(),
            host_world: None,
        })
    }

    /// What the frame budget chose (`GiContextDesc::budget_ms`): `None` without a budget, or
    /// before the first scene when there were no lab results to choose from.
    pub fn budget_choice(&self) -> Option<&BudgetChoice> {
        self.budget.as_ref().and_then(|(_, c)| c.as_ref())
    }

    /// The display size the context was made for.
    pub fn display(&self) -> [u32; 2] {
        self.display
    }

    /// The size the light is computed at: the display size scaled by the description's
    /// [`InternalResolution`].
    pub fn internal_extent(&self) -> [u32; 2] {
        self.internal.extent(self.display)
    }

    /// Changes the display size (the host's swapchain was resized): the next dispatch takes
    /// images of `display` size; histories start over, and the transients of the old size
    /// are released once the frames that used them have completed. Nothing waits.
    pub fn resize(&mut self, display: [u32; 2]) -> Result<(), RenderError> {
        self.params = frame_params(&self.settings, self.internal.extent(display))?;
        self.display = display;
        Ok(())
    }

    /// Hands over the scene the GI is computed from (geometry for the RSM and the BVH, lights,
    /// proxies, the environment), posed at time `t`: a load-time call that uploads and waits
    /// for its copies. A scene over the budgets is refused (the old one stays).
    pub fn set_scene(&mut self, scene: &Scene, t: f32) -> Result<(), RenderError> {
        let lights = scene.lights.len();
        let proxies: usize = scene.proxies.iter().map(|p| p.spheres.len()).sum();
        if lights > self.budgets.lights as usize || proxies > self.budgets.proxies as usize {
            return Err(RenderError::Invalid(format!(
                "GI context: the scene has {lights} lights and {proxies} proxy spheres, the \
                 budgets are {} and {}",
                self.budgets.lights, self.budgets.proxies
            )));
        }
        if let Some((ms, None)) = self.budget {
            let internal = self.internal.extent(self.display);
            let choice = budget_pick::from_quick_lab(&self.device, scene, t, internal, ms)?;
            budget_pick::apply(&mut self.settings, &choice)?;
            self.params = frame_params(&self.settings, self.internal.extent(self.display))?;
            self.budget = Some((ms, Some(choice)));
        }
        self.renderer.set_scene(scene, t)?;
        // A scene of the host's own is not the registered meshes' world (set_instances sets
        // it again after this).
        self.host_world = None;
        Ok(())
    }

    /// Registers a triangle mesh from the host's own buffers: reads them back once (a
    /// load-time call: submits a copy on shine's queue and waits), after checking that every
    /// range fits its buffer, and refuses indices past the vertices and non-finite positions.
    /// Place it with [`GiContext::set_instances`].
    pub fn register_mesh(&mut self, mesh: &HostMesh) -> Result<MeshId, RenderError> {
        let primitive = host_geometry::read_mesh(&self.device, mesh)?;
        let id = u32::try_from(self.host_meshes.len())
            .map_err(|_| RenderError::Invalid("host geometry: too many meshes".into()))?;
        self.host_meshes.push(Registered {
            primitive,
            material: mesh.material,
            deformable: mesh.deformable,
            deltas: None,
        });
        Ok(MeshId(id))
    }

    /// Gives a deformable mesh's new shape (skinned, simulated) from host memory: one
    /// position per registered vertex, in the mesh's own space, and optionally normals (else
    /// area-weighted ones). A per-frame call: CPU work (the deltas from the registered
    /// vertices), uploaded by the next dispatch, whose BVH refit follows the new triangles
    /// (same topology). The shape holds until the next call, through `set_instances` too.
    /// Refused: a rigid or unknown mesh, a wrong count, a non-finite number.
    pub fn deform_mesh(
        &mut self,
        mesh: MeshId,
        positions: &[[f32; 3]],
        normals: Option<&[[f32; 3]]>,
    ) -> Result<(), RenderError> {
        let index = mesh.0 as usize;
        let registered = self.host_meshes.get(index).ok_or_else(|| {
            RenderError::Invalid(format!("host geometry: no mesh {} is registered", mesh.0))
        })?;
        let (deltas, normals) = host_geometry::deform(registered, mesh.0, positions, normals)?;
        // In the current world: rewrite the scene's target now (else at set_instances).
        if let Some((_, _, meshes)) = &self.host_world
            && index < *meshes
        {
            self.renderer
                .set_morph_target([index, 0, 0], &deltas, &normals)?;
        }
        // Kept only once taken: a refused shape leaves the last one.
        self.host_meshes[index].deltas = Some((deltas, normals));
        Ok(())
    }

    /// The host's world: registered meshes placed by `instances` (3×4 transforms) and lit by
    /// `lights` (world space). Builds the scene the GI is computed from (BVH, RSMs) and hands
    /// it over as [`GiContext::set_scene`] does (uploads and waits): call it when instances
    /// come or go or the number of lights changes; [`GiContext::move_instances`] moves them
    /// per frame. A bad transform, mesh id or light is refused and the old world stays.
    pub fn set_instances(
        &mut self,
        instances: &[HostInstance],
        lights: &[Light],
    ) -> Result<(), RenderError> {
        let scene = host_geometry::scene(&self.host_meshes, instances, lights)?;
        self.set_scene(&scene, 0.0)?;
        self.host_world = Some((instances.to_vec(), lights.len(), self.host_meshes.len()));
        Ok(())
    }

    /// Moves the instances of the last [`GiContext::set_instances`] (the same meshes, in the
    /// same order) and replaces its lights (as many) for the next dispatch: CPU work only, a
    /// per-frame call. Anything else is refused: a new instance list goes through
    /// `set_instances`.
    pub fn move_instances(
        &mut self,
        instances: &[HostInstance],
        lights: &[Light],
    ) -> Result<(), RenderError> {
        let Some((set, light_count, _)) = &self.host_world else {
            return Err(RenderError::Invalid(
                "host geometry: move_instances before set_instances".into(),
            ));
        };
        if instances.len() != set.len()
            || instances.iter().zip(set).any(|(a, b)| a.mesh != b.mesh)
            || lights.len() != *light_count
        {
            return Err(RenderError::Invalid(format!(
                "host geometry: move_instances takes the {} instances (same meshes, same \
                 order) and {light_count} lights of set_instances; {} instances and {} lights \
                 given",
                set.len(),
                instances.len(),
                lights.len()
            )));
        }
        let nodes = instances
            .iter()
            .enumerate()
            .map(|(i, instance)| Ok((i, host_geometry::instance_transform(&instance.transform)?)))
            .collect::<Result<Vec<_>, RenderError>>()?;
        self.update(&FrameUpdate {
            nodes,
            lights: lights.iter().copied().enumerate().collect(),
            ..FrameUpdate::default()
        })
    }

    /// Sets the scene's time, node transforms, lights and morph weights for the next
    /// dispatch (CPU work only; the dispatch uploads them). The camera of a `FrameUpdate` is
    /// not used: each dispatch brings the host's. A bad update is refused.
    pub fn update(&mut self, update: &FrameUpdate) -> Result<(), RenderError> {
        self.renderer.update(update)
    }

    /// Records one frame into `cb` (recording, outside a render pass): the host's G-buffer
    /// converted, the technique's passes, and the indirect light written to
    /// `dispatch.diffuse`, left in its `after` state. Never submits or waits; the host
    /// submits `cb` and keeps the images alive until it completes. After an error nothing
    /// usable was recorded: do not submit `cb`.
    pub fn dispatch(
        &mut self,
        cb: vk::CommandBuffer,
        dispatch: &GiDispatch,
    ) -> Result<(), RenderError> {
        dispatch.validate(self.display)?;
        if dispatch.debug.is_some() {
            dispatch.debug_view.check(&self.params)?;
        }
        if self
            .last_frame
            .is_some_and(|last| dispatch.frame_index <= last)
        {
            return Err(RenderError::Invalid(format!(
                "GI dispatch: frame {} after frame {}: frame numbers must increase",
                dispatch.frame_index,
                self.last_frame.unwrap_or_default()
            )));
        }
        self.record(cb, dispatch, Some(dispatch.frame_index))?;
        self.last_frame = Some(dispatch.frame_index);
        Ok(())
    }

    /// Records `dispatch` into `cb` as the host's frame `host_frame` (`None`: a warm-up frame
    /// shine submits and waits for itself).
    fn record(
        &mut self,
        cb: vk::CommandBuffer,
        dispatch: &GiDispatch,
        host_frame: Option<u64>,
    ) -> Result<(), RenderError> {
        let display = self.display;
        let internal = self.internal.extent(display);
        let constants = dispatch.host_frame(display);
        let camera = dispatch.camera.view_for(display);
        // The proxies read the environment's SH at their order, the sky (frames without
        // proxies) at its own.
        let proxy_bands = self
            .params
            .proxy
            .map(|p| p.sh_order)
            .or(self.params.sky.map(|_| crate::passes::sky::BANDS));
        let (frame_constants, ring, sampler) =
            (&self.frame_constants, &mut self.ring, self.nearest.raw());
        self.renderer.record_indirect(
            cb,
            host_frame,
            &self.params,
            &camera,
            &mut |rg: &mut RenderGraph| {
                let frame = ring.upload(
                    rg,
                    "host frame",
                    frame_constants,
                    bytemuck::bytes_of(&constants),
                )?;
                let host = HostImages {
                    depth: dispatch.depth.import(rg, "host depth", true),
                    normal: dispatch.normals.import(rg, "host normals", true),
                    albedo: dispatch.albedo.import(rg, "host albedo", true),
                    material: dispatch.material.import(rg, "host material", true),
                    motion: dispatch
                        .motion
                        .map(|m| m.image.import(rg, "host motion", true)),
                };
                let g = host_gbuffer::host_gbuffer(
                    rg,
                    "host gbuffer",
                    &host,
                    &frame,
                    internal,
                    sampler,
                );
                // Below the display size, the display's depth and normals guide the upsample.
                let guide = (internal != display).then(|| {
                    host_gbuffer::host_gbuffer(rg, "host guide", &host, &frame, display, sampler)
                });
                // Only the proxies and the sky read an environment.
                let environment = match (dispatch.environment, proxy_bands) {
                    (Some(env), Some(bands)) => {
                        let map = env.image.import(rg, "host environment", true);
                        Some(environment_sh::environment_sh(
                            rg,
                            &map,
                            env.image.extent,
                            env.intensity,
                            bands,
                            sampler,
                        )?)
                    }
                    _ => None,
                };
                Ok(HostSide {
                    g,
                    guide,
                    diffuse: dispatch
                        .diffuse
                        .map(|d| d.import(rg, "host diffuse gi", false)),
                    specular: dispatch
                        .specular
                        .map(|s| s.import(rg, "host specular gi", false)),
                    environment,
                    debug: dispatch
                        .debug
                        .map(|d| (d.import(rg, "host debug", false), dispatch.debug_view)),
                })
            },
        )
    }

    /// Builds, ahead of the host's first frame, everything a frame needs: every pipeline
    /// (through the device's pipeline cache), the graph's plans, transient memory and
    /// descriptor pools. It records `frames_in_flight + 1` frames of placeholder inputs at the
    /// display size, submits them to shine's queue and waits, then starts the histories over,
    /// so the host's first dispatch costs about what a steady one does. `shape`: what the
    /// host's dispatches will bring (motion vectors, an environment map, a specular output),
    /// which decides the graph that is built. The placeholders are released afterwards. A
    /// load-time call, after [`GiContext::set_scene`]; call it again after a
    /// [`GiContext::resize`] to warm the new size. The host must have no frame of this
    /// context in flight.
    pub fn warm_up(&mut self, shape: DispatchShape) -> Result<(), RenderError> {
        // Made for the warm-up and released after it (at 1080p they would hold ~75 MB).
        let placeholders = Placeholders::new(&self.device, self.display)?;
        for _ in 0..warm_up_frames(self.frames_in_flight) {
            self.warm_up_frame(&placeholders, shape)?;
        }
        // The warm-up's pass times are not the host's.
        self.renderer.timings()?;
        self.reset_history();
        Ok(())
    }

    /// One warm-up frame of `placeholders`, submitted and waited for (not submitted when it
    /// could not be recorded).
    fn warm_up_frame(
        &mut self,
        placeholders: &Placeholders,
        shape: DispatchShape,
    ) -> Result<(), RenderError> {
        let device = self.device.clone();
        let mut recorded = Ok(());
        let submitted = device.run_once(|cmd| {
            placeholders.clear(cmd);
            recorded = self.record(cmd.raw(), &placeholders.dispatch(0, shape), None);
            match recorded {
                Ok(()) => Ok(()),
                Err(_) => Err(shine_gpu::Error::InvalidUsage(
                    "warm-up frame abandoned".into(),
                )),
            }
        });
        recorded?;
        Ok(submitted.map(drop)?)
    }

    /// Starts every history over, for a camera cut or a teleport: the next dispatch computes
    /// its indirect light as a first frame does, with nothing carried from earlier frames
    /// (accumulation, reprojection, amortised caches, the previous frame's transforms).
    pub fn reset_history(&mut self) {
        self.renderer.reset_history();
    }

    /// The device memory the context holds, by category: the scene, the technique's caches,
    /// per-frame data, staging, the graph's transients and histories, and objects waiting for
    /// the host's frames to complete.
    pub fn memory_report(&self) -> MemoryReport {
        let mut report = self.renderer.memory_report();
        report.frame_data += self.frame_constants.allocated_bytes();
        report.staging += self.ring.allocated_bytes();
        report
    }

    /// GPU times of the passes of dispatched frames whose timestamps are available (call
    /// once those frames have completed).
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, RenderError> {
        self.renderer.timings()
    }
}

/// The frame parameters of `settings` at the `internal` size: indirect light only (direct
/// light and the composite are the host's).
fn frame_params(settings: &Settings, internal: [u32; 2]) -> Result<FrameParams, RenderError> {
    let [width, height] = internal;
    let settings = Settings {
        width,
        height,
        ..settings.clone()
    };
    settings.validate()?;
    if settings.gi.is_none() {
        return Err(RenderError::Invalid(
            "GI context: settings.gi names no technique".into(),
        ));
    }
    let mut params = FrameParams::from_settings(&settings);
    params.component = crate::passes::composite::Component::Indirect;
    // The technique shades the host's G-buffer at its size: nothing to supersample.
    params.composite.ssaa = 1;
    Ok(params)
}
