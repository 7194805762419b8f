//! The `proxy` GI technique in a frame (paper 002): the scene's proxy spheres and environment
//! on the GPU, and the passes it adds to the frame graph (`src/passes/proxy.rs`).
//!
//! The proxies are taken at the scene time given to [`crate::renderer::Renderer::set_scene`]
//! (`Scene::world_transforms_at`), with the albedo of their node's first material. With the
//! setting `proxy.fit_count = k > 0`, every node that has proxies gets `k` spheres fitted to its
//! mesh instead ([`shine_scene::proxies::fit`]): the built-in `spheres` scene has 4 proxied
//! objects, so `k` = 2, 8, 32 gives 8, 32, 128 proxies (the profiling cases of issue 8).

use glam::{Mat4, Vec3};
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, vk};
use shine_graph::{Handle, Image, RenderGraph};
use shine_scene::environment::Environment;
use shine_scene::proxies::{self, ProxySphere};
use shine_scene::{Mesh, Scene};

use crate::environment_sh::EnvironmentSh;
use crate::passes::proxy::{
    self, Accumulation, GpuProxy, MAX_PROXIES, ProxyInputs, ProxyParams, ProxyTables, Receivers,
};
use crate::renderer::RenderError;
use crate::settings::Settings;

/// One node's proxies as set up from the scene.
#[derive(Debug, Clone)]
struct ProxySource {
    world: Mat4,
    spheres: Vec<ProxySphere>,
    mesh: Option<Mesh>,
    albedo: Vec3,
}

/// The scene side of the proxy technique and its GPU buffers, built on demand and cached.
pub struct ProxyFrame {
    device: Device,
    sources: Vec<ProxySource>,
    environment: Option<Environment>,
    /// Proxies for one `fit_count`: (fit_count, count, buffer).
    proxies: Option<(u32, u32, Buffer)>,
    /// Environment SH per band count.
    environments: Vec<(u32, Buffer)>,
    /// Tables per (bands, η shadow, η indirect).
    tables: Vec<((u32, u32, u32), ProxyTables, Buffer)>,
}

fn storage(device: &Device, name: &'static str, data: &[u8]) -> Result<Buffer, RenderError> {
    Ok(Buffer::with_data(
        device,
        &BufferDesc {
            name,
            size: 0,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
        },
        data,
    )?)
}

impl ProxyFrame {
    /// The proxies and environment of `scene` at time `t`; nothing is uploaded yet.
    pub fn new(device: &Device, scene: &Scene, t: f32) -> Self {
        let world = scene.world_transforms_at(t);
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
                    world: *world.get(p.node)?,
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
        }
    }

    /// The world-space proxies for `fit_count` (0: the scene's own).
    pub fn proxies(&self, fit_count: u32) -> Vec<GpuProxy> {
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
            let w = s.world;
            let scale = w
                .x_axis
                .truncate()
                .length()
                .max(w.y_axis.truncate().length())
                .max(w.z_axis.truncate().length());
            out.extend(spheres.iter().map(|sp| {
                GpuProxy::new(
                    w.transform_point3(Vec3::from(sp.center)),
                    sp.radius * scale,
                    s.albedo,
                )
            }));
        }
        out
    }

    /// Uploads what a frame with `settings` needs (once per distinct setting).
    pub fn prepare(&mut self, settings: &Settings) -> Result<(), RenderError> {
        let p = &settings.proxy;
        let environment = self.environment.as_ref().ok_or_else(|| {
            RenderError::Invalid(
                "--gi proxy needs an environment light: this scene has none (add \
                 `shine_environment` to the glTF root extras, or pass --environment FILE)"
                    .into(),
            )
        })?;
        if !self.environments.iter().any(|(b, _)| *b == p.sh_order) {
            let sh = EnvironmentSh::project(environment, p.sh_order as usize)
                .map_err(proxy::ProxyError::from)?;
            let buffer = storage(
                &self.device,
                "proxy environment sh",
                bytemuck::cast_slice(&sh.gpu_data()),
            )?;
            self.environments.push((p.sh_order, buffer));
        }
        let key = (
            p.sh_order,
            p.shadow_expansion().to_bits(),
            p.indirect_expansion.to_bits(),
        );
        if !self.tables.iter().any(|(k, _, _)| *k == key) {
            let tables =
                ProxyTables::build(p.sh_order, p.shadow_expansion(), p.indirect_expansion)?;
            let buffer = storage(
                &self.device,
                "proxy tables",
                bytemuck::cast_slice(&tables.gpu_data()),
            )?;
            self.tables.push((key, tables, buffer));
        }
        if self.proxies.as_ref().map(|(k, _, _)| *k) != Some(p.fit_count) {
            let list = self.proxies(p.fit_count);
            let count = u32::try_from(list.len())
                .ok()
                .filter(|&c| c <= MAX_PROXIES)
                .ok_or_else(|| {
                    RenderError::Invalid(format!(
                        "{} proxy spheres: at most {MAX_PROXIES} are supported",
                        list.len()
                    ))
                })?;
            // A storage buffer cannot be empty: one zero record stands for "no proxy".
            let data = if list.is_empty() {
                vec![GpuProxy::new(Vec3::ZERO, 0.0, Vec3::ZERO)]
            } else {
                list
            };
            let buffer = storage(&self.device, "proxies", bytemuck::cast_slice(&data))?;
            self.proxies = Some((p.fit_count, count, buffer));
        }
        Ok(())
    }

    /// Adds the proxy passes over `receivers`; returns `proxy_gi` (RGBA16F outgoing radiance
    /// at receiver resolution). [`ProxyFrame::prepare`] must have run with the same settings.
    pub fn declare(
        &self,
        rg: &mut RenderGraph,
        receivers: &Receivers,
        settings: &Settings,
    ) -> Result<Handle<Image>, RenderError> {
        let p = &settings.proxy;
        let missing = || RenderError::Invalid("proxy buffers not prepared".into());
        let environment = self
            .environments
            .iter()
            .find(|(b, _)| *b == p.sh_order)
            .map(|(_, b)| b)
            .ok_or_else(missing)?;
        let key = (
            p.sh_order,
            p.shadow_expansion().to_bits(),
            p.indirect_expansion.to_bits(),
        );
        let (_, tables, table_buffer) = self
            .tables
            .iter()
            .find(|(k, _, _)| *k == key)
            .ok_or_else(missing)?;
        let (_, count, proxy_buffer) = self
            .proxies
            .as_ref()
            .filter(|(k, _, _)| *k == p.fit_count)
            .ok_or_else(missing)?;
        let read = crate::gpu_scene::BUFFER_READ;
        let inputs = ProxyInputs {
            proxies: rg.import_gpu_buffer(proxy_buffer, read, read),
            count: *count,
            tables: rg.import_gpu_buffer(table_buffer, read, read),
            environment: rg.import_gpu_buffer(environment, read, read),
        };
        let params = ProxyParams {
            bands: p.sh_order,
            accumulation: if p.brute_force {
                Accumulation::Product
            } else {
                Accumulation::Splat
            },
            exp: p.exp,
            indirect: p.indirect,
        };
        let sums = proxy::proxy_accumulate(rg, receivers, &inputs, tables, &params)?;
        let out = proxy::proxy_shade(rg, receivers, &sums, &inputs, tables, &params)?;
        Ok(out.radiance)
    }
}
