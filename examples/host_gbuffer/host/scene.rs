//! The host's copy of a scene's geometry (flattened by `Scene::flatten_at`) and its camera
//! code.

use super::HostDevice;
use super::resources::HostBuffer;
use glam::{Mat4, Vec3};
use gpu_allocator::MemoryLocation;
use shine::gpu::ash::vk;
use shine_scene::Scene;
use std::error::Error;

/// The host's copy of a scene's geometry: world-space vertices (position, normal), indices,
/// and one draw per primitive with its material.
pub struct HostScene {
    pub vertices: HostBuffer,
    pub indices: HostBuffer,
    pub draws: Vec<shine_scene::FlatDraw>,
    /// The first light (the host lights with it directly).
    pub light: Option<shine_scene::Light>,
}

impl HostScene {
    /// `scene` at time 0 in host-visible vertex and index buffers.
    pub fn new(host: &HostDevice, scene: &Scene) -> Result<Self, Box<dyn Error>> {
        Self::posed(host, scene, &scene.world_transforms_at(0.0))
    }

    /// `scene` with its nodes placed by `world` (one matrix per node).
    pub fn posed(host: &HostDevice, scene: &Scene, world: &[Mat4]) -> Result<Self, Box<dyn Error>> {
        let flat = scene.flatten(world);
        let upload = |name, bytes: &[u8], usage| -> Result<HostBuffer, Box<dyn Error>> {
            let mut buffer = HostBuffer::new(
                host,
                name,
                bytes.len() as u64,
                usage,
                MemoryLocation::CpuToGpu,
            )?;
            buffer.bytes()[..bytes.len()].copy_from_slice(bytes);
            Ok(buffer)
        };
        Ok(Self {
            vertices: upload(
                "host vertices",
                bytemuck::cast_slice(&flat.vertices),
                // TRANSFER_SRC: a host that registers them with shine (`GiContext::register_mesh`).
                vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            indices: upload(
                "host indices",
                bytemuck::cast_slice(&flat.indices),
                vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            draws: flat.draws,
            light: scene.lights_at(world).into_iter().next(),
        })
    }

    /// Destroys the buffers.
    pub fn destroy(self, host: &HostDevice) {
        self.vertices.destroy(host);
        self.indices.destroy(host);
    }
}

/// The view and (unjittered, Vulkan y-down) projection of `scene`'s first camera for an
/// `extent` image, with the camera turned by `orbit` radians about the vertical axis through
/// the scene's centre: the host's own camera code.
pub fn camera(scene: &Scene, extent: [u32; 2], orbit: f32) -> (Mat4, Mat4) {
    let world = scene.rest_world_transforms();
    let camera_world = scene.camera_world(0, &world).unwrap_or(Mat4::IDENTITY);
    let bounds = world
        .iter()
        .zip(&scene.nodes)
        .filter_map(|(m, n)| Some((m, scene.meshes.get(n.mesh?)?)))
        .flat_map(|(m, mesh)| {
            mesh.primitives
                .iter()
                .flat_map(|p| p.positions.iter().map(|v| m.transform_point3(*v)))
        })
        .fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(p), hi.max(p)),
        );
    let centre = (bounds.0 + bounds.1) * 0.5;
    let turn = Mat4::from_translation(centre)
        * Mat4::from_rotation_y(orbit)
        * Mat4::from_translation(-centre);
    let view = (turn * camera_world).inverse();
    let aspect = extent[0] as f32 / extent[1].max(1) as f32;
    let (yfov, znear, zfar) = match scene.cameras.first().map(|c| c.projection) {
        Some(shine_scene::Projection::Perspective {
            yfov, znear, zfar, ..
        }) => (yfov, znear, zfar),
        _ => (0.8, 0.05, None),
    };
    let mut projection = match zfar {
        Some(far) => Mat4::perspective_rh(yfov, aspect, znear, far),
        None => Mat4::perspective_infinite_rh(yfov, aspect, znear),
    };
    projection.y_axis.y = -projection.y_axis.y;
    (view, projection)
}
