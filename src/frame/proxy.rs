//! The proxy technique (paper 002) as the frame uses it: the scene's proxy spheres and
//! environment on the GPU, and the passes it adds to a frame (`src/passes/proxy/`).
//!
//! The proxies follow their nodes every frame (placed by the frame's node world matrices,
//! uploaded through a staging ring), with the albedo of their node's first material. With the
//! setting `proxy.fit_count = k > 0`, every node that has proxies gets `k` spheres fitted to its
//! mesh instead ([`shine_scene::proxies::fit`]): the built-in `spheres` scene has 4 proxied
//! objects, so `k` = 2, 8, 32 gives 8, 32, 128 proxies (the profiling cases of issue 8).

use glam::{Mat4, Vec3};
use shine_gpu::{Buffer, Device};
use shine_graph::{Handle, Image, RenderGraph};
use shine_scene::environment::Environment;
use shine_scene::proxies::{self, ProxySphere};
use shine_scene::{Mesh, Scene};

use super::error::RenderError;
use crate::gpu_scene::BUFFER_READ;
use crate::gpu_scene::environment_sh::EnvironmentSh;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::passes::amortise::{self, ResolveHistory, Schedule, Slice};
use crate::passes::brdf_tables::BrdfTables;
use crate::passes::proxy::ProxySettings;
use crate::passes::proxy::{
    self, GpuProxy, MAX_PROXIES, ProxyError, ProxyInputs, ProxyParams, ProxySlice, ProxyTables,
};
use crate::passes::receivers::Receivers;

/// One node's proxies as set up from the scene.
#[derive(Debug, Clone)]
struct ProxySource {
    node: usize,
    spheres: Vec<ProxySphere>,
    mesh: Option<Mesh>,
    albedo: Vec3,
}

/// The proxy technique's persistent state: the scene's proxies and environment, and their GPU
/// buffers, built on demand and kept per setting.
pub struct ProxyTechnique {
    device: Device,
    sources: Vec<ProxySource>,
    environment: Option<Environment>,
    /// The proxies for one `fit_count`.
    proxies: Option<ProxyBuffer>,
    /// Environment SH per band count.
    environments: Vec<(u32, Buffer)>,
    /// Tables per (bands, η shadow, η indirect).
    tables: Vec<(TableKey, ProxyTables, Buffer)>,
    /// Staging of the per-frame proxy uploads.
    ring: UploadRing,
    /// The BRDF SH tables of the glossy receivers, per band count.
    brdf: BrdfTables,
    /// Which frame last resolved into the amortised light's history (`proxy.slices`).
    schedule: Schedule,
}

/// The proxies of one `fit_count`: in their nodes' space, and their device buffer, rewritten
/// in world space every frame.
struct ProxyBuffer {
    fit_count: u32,
    /// (node, sphere in the node's space, albedo) of every proxy.
    local: Vec<(usize, ProxySphere, Vec3)>,
    /// Proxies in the buffer (0: it holds one zero record).
    count: u32,
    buffer: Buffer,
}

/// The α tables' cache key: bands and the bits of both expansion factors.
type TableKey = (u32, u32, u32);

/// A proxy frame ready to be declared: the GPU data of its setup imported into the graph.
pub struct PreparedProxy<'a> {
    params: ProxyParams,
    inputs: ProxyInputs,
    tables: &'a ProxyTables,
    /// Amortised frames (`proxy.slices = 4`): this frame's slice.
    amortised: Option<Slice>,
}

impl ProxyTechnique {
    /// The proxies and environment of `scene`; nothing is uploaded yet.
    pub fn new(device: &Device, scene: &Scene) -> Self {
        let sources = scene
            .proxies
            .iter()
            .filter_map(|p| {
                let node = scene.nodes.get(p.node)?;
                let mesh = node.mesh.and_then(|m| scene.meshes.get(m)).cloned();
                let albedo = mesh
                    .as_ref()
                    .and_then(|m| m.primitives.first())
                    .and_then(|prim| scene.materials.get(prim.material as usize))
                    .map(|m| Vec3::new(m.base_color[0], m.base_color[1], m.base_color[2]))
                    .unwrap_or(Vec3::splat(0.5));
                Some(ProxySource {
                    node: p.node,
                    spheres: p.spheres.clone(),
                    mesh,
                    albedo,
                })
            })
            .collect();
        Self {
            device: device.clone(),
            sources,
            environment: scene.environment.clone(),
            proxies: None,
            environments: Vec::new(),
            tables: Vec::new(),
            ring: UploadRing::new(device),
            brdf: BrdfTables::new(device, "proxy brdf tables"),
            schedule: Schedule::default(),
        }
    }

    /// Bytes of device memory: `(tables and proxies, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        let caches = self
            .environments
            .iter()
            .map(|(_, b)| b)
            .chain(self.tables.iter().map(|(_, _, b)| b))
            .chain(self.proxies.iter().map(|p| &p.buffer))
            .map(Buffer::allocated_bytes)
            .sum::<u64>();
        let (brdf, brdf_staging) = self.brdf.allocated_bytes();
        (caches + brdf, self.ring.allocated_bytes() + brdf_staging)
    }

    /// Forgets the history (the amortised schedule); the uploaded tables stay.
    pub fn reset(&mut self) {
        self.schedule.reset();
    }

    /// Forgets the uploaded tables: a frame that may have uploaded them was dropped unrun.
    pub fn forget_uploads(&mut self) {
        self.schedule.reset();
        self.environments.clear();
        self.tables.clear();
        self.brdf.clear();
    }

    /// The scene environment's SH at `bands` bands in `rg`: imported, or projected on the CPU
    /// and uploaded by this frame (once per band count).
    pub(crate) fn environment_sh(
        &mut self,
        rg: &mut RenderGraph,
        bands: u32,
    ) -> Result<Handle<shine_graph::Buffer>, RenderError> {
        if let Some((_, buffer)) = self.environments.iter().find(|(b, _)| *b == bands) {
            return Ok(rg.import_gpu_buffer(buffer, BUFFER_READ, BUFFER_READ));
        }
        let environment = self.environment.as_ref().ok_or(ProxyError::NoEnvironment)?;
        let sh = EnvironmentSh::project(environment, bands as usize).map_err(ProxyError::from)?;
        let data = sh.gpu_data();
        let buffer = Buffer::storage_for_uploads(
            &self.device,
            "proxy environment sh",
            std::mem::size_of_val(data.as_slice()) as u64,
        )?;
        let handle = self.ring.upload_once(
            rg,
            "proxy environment sh",
            &buffer,
            bytemuck::cast_slice(&data),
        )?;
        self.environments.push((bands, buffer));
        Ok(handle)
    }

    /// The proxies for `fit_count` (0: the scene's own) in their nodes' space.
    fn local_proxies(&self, fit_count: u32) -> Vec<(usize, ProxySphere, Vec3)> {
        let mut out = Vec::new();
        for s in &self.sources {
            let fitted;
            let spheres = match (&s.mesh, fit_count) {
                (Some(mesh), k) if k > 0 => {
                    fitted = proxies::fit(mesh, k as usize).spheres;
                    &fitted
                }
                _ => &s.spheres,
            };
            out.extend(spheres.iter().map(|sp| (s.node, *sp, s.albedo)));
        }
        out
    }

    /// Uploads what `setup` needs (tables once per distinct setup; the proxies, placed by
    /// the frame's node matrices `world`, every frame) and imports it into `rg`. The
    /// environment's SH is `environment` when given (a host's map projected this frame),
    /// else the scene's, projected on the CPU once per band count.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        setup: &ProxySettings,
        world: &[Mat4],
        environment: Option<Handle<shine_graph::Buffer>>,
        receiver_extent: [u32; 2],
    ) -> Result<PreparedProxy<'_>, RenderError> {
        let bands = setup.sh_order;
        let amortised = self
            .schedule
            .next(rg.frame(), receiver_extent, setup.slices, 0);
        let environment = match environment {
            Some(host) => host,
            None => self.environment_sh(rg, bands)?,
        };
        let key = (
            bands,
            setup.shadow_expansion().to_bits(),
            setup.indirect_expansion.to_bits(),
        );
        let (table_index, uploaded_tables) = match self
            .tables
            .iter()
            .position(|(k, _, _)| *k == key)
        {
            Some(i) => (i, None),
            None => {
                let tables =
                    ProxyTables::build(bands, setup.shadow_expansion(), setup.indirect_expansion)?;
                let data = tables.gpu_data();
                let buffer = Buffer::storage_for_uploads(
                    &self.device,
                    "proxy tables",
                    std::mem::size_of_val(data.as_slice()) as u64,
                )?;
                let handle = self.ring.upload_once(
                    rg,
                    "proxy tables",
                    &buffer,
                    bytemuck::cast_slice(&data),
                )?;
                self.tables.push((key, tables, buffer));
                (self.tables.len() - 1, Some(handle))
            }
        };
        let brdf = self.brdf.import(rg, bands)?;
        let proxies = match self.proxies.take() {
            Some(cached) if cached.fit_count == setup.fit_count => cached,
            _ => self.proxy_buffer(setup.fit_count)?,
        };
        let placed: Vec<GpuProxy> = proxies
            .local
            .iter()
            .map(|(node, sphere, albedo)| {
                let w = sphere.transformed(world.get(*node).unwrap_or(&Mat4::IDENTITY));
                GpuProxy::new(Vec3::from(w.center), w.radius, *albedo)
            })
            .collect();
        let proxies = self.proxies.insert(proxies);
        let proxy_handle = self.ring.upload(
            rg,
            "proxies",
            &proxies.buffer,
            bytemuck::cast_slice(&placed),
        )?;
        let (_, tables, table_buffer) = &self.tables[table_index];
        let inputs = ProxyInputs {
            proxies: proxy_handle,
            count: proxies.count,
            tables: uploaded_tables
                .unwrap_or_else(|| rg.import_gpu_buffer(table_buffer, BUFFER_READ, BUFFER_READ)),
            environment,
            brdf,
        };
        Ok(PreparedProxy {
            params: setup.pass(),
            inputs,
            tables,
            amortised,
        })
    }

    /// The proxies for `fit_count` and a device buffer for them.
    fn proxy_buffer(&self, fit_count: u32) -> Result<ProxyBuffer, RenderError> {
        let local = self.local_proxies(fit_count);
        let count = u32::try_from(local.len())
            .ok()
            .filter(|&c| c <= MAX_PROXIES)
            .ok_or(ProxyError::TooMany(local.len()))?;
        // A storage buffer cannot be empty: room for one record even without proxies (the
        // passes read `count` records; the proxies are uploaded every frame).
        let buffer = Buffer::storage_for_uploads(
            &self.device,
            "proxies",
            (local.len().max(1) * std::mem::size_of::<GpuProxy>()) as u64,
        )?;
        Ok(ProxyBuffer {
            fit_count,
            local,
            count,
            buffer,
        })
    }
}

impl PreparedProxy<'_> {
    /// Adds `proxy_tiles`, `proxy_accumulate` and `proxy_shade` over `receivers` seen from
    /// `camera`; returns `proxy_gi` (RGBA16F outgoing radiance at receiver resolution). With
    /// `proxy.slices = 4` they shade one receiver per 2×2 cell, `proxy_regather_mask`,
    /// `proxy_reaccumulate` and `proxy_reshade` those whose history `motion` rejects, and
    /// `proxy_resolve` the rest (src/passes/amortise.rs).
    pub fn declare(
        self,
        rg: &mut RenderGraph,
        receivers: &Receivers,
        camera: Vec3,
        motion: &Handle<Image>,
    ) -> Result<Handle<Image>, RenderError> {
        let params = &self.params;
        let (inputs, tables) = (&self.inputs, self.tables);
        let first = ProxySlice {
            slice: self.amortised.map_or(0, |s| s.slice),
            ..ProxySlice::default()
        };
        let (sums, masks) =
            proxy::proxy_accumulate_slice(rg, receivers, inputs, tables, params, first)?;
        let mut light =
            proxy::proxy_shade_slice(rg, receivers, &sums, inputs, tables, params, camera, first)?
                .radiance;
        let Some(amortised) = self.amortised else {
            return Ok(light);
        };
        let surfaces = receivers.into();
        let mut history = ResolveHistory::declare(rg, "proxy", receivers.extent);
        if amortised.slice != 0 {
            // The receivers whose history was rejected, or whose changed cell's refreshed
            // receiver shows another surface, are shaded now (what moved first).
            amortise::regather_mask(rg, surfaces, &mut light, motion, &history, amortised)?;
            let again = ProxySlice {
                slice: amortise::REGATHER_SLICE,
                marks: Some(light),
                masks,
            };
            let (sums, _) =
                proxy::proxy_accumulate_slice(rg, receivers, inputs, tables, params, again)?;
            light = proxy::proxy_shade_slice(
                rg, receivers, &sums, inputs, tables, params, camera, again,
            )?
            .radiance;
        }
        Ok(amortise::resolve(
            rg,
            surfaces,
            &light,
            motion,
            &mut history,
            amortised,
        )?)
    }
}
