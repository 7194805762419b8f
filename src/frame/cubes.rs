//! Tiny environment cubes (issue 18, item 3; paper 001) as the frame uses them: one cube per
//! dynamic object of the scene (a node with proxies), placed every frame by the node's world
//! matrix, and the passes of [`crate::passes::cubes`].

use glam::{Mat4, Vec3};
use shine_gpu::{Buffer, Device};
use shine_graph::RenderGraph;
use shine_scene::Scene;
use shine_scene::proxies::ProxySphere;

use super::error::RenderError;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::passes::cubes::{CubeInputs, GpuCube, GpuCubeSphere};
use crate::passes::proxy::MAX_PROXIES;

/// The cubes' persistent state: each dynamic object's proxies in its node's space, and the
/// device buffers their world-space records are uploaded to every frame.
pub struct CubeTechnique {
    /// (node, its proxies in the node's space), one entry per cube.
    objects: Vec<(usize, Vec<ProxySphere>)>,
    /// Device buffers of the cubes and spheres, made on first use.
    buffers: Option<(Buffer, Buffer)>,
    ring: UploadRing,
    device: Device,
}

impl CubeTechnique {
    /// The dynamic objects of `scene`; nothing is uploaded yet.
    pub fn new(device: &Device, scene: &Scene) -> Self {
        Self {
            objects: scene
                .proxies
                .iter()
                .filter(|p| !p.spheres.is_empty())
                .map(|p| (p.node, p.spheres.clone()))
                .collect(),
            buffers: None,
            ring: UploadRing::new(device),
            device: device.clone(),
        }
    }

    /// Bytes of device memory: `(cube and sphere records, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        let records = self
            .buffers
            .iter()
            .map(|(a, b)| a.allocated_bytes() + b.allocated_bytes())
            .sum();
        (records, self.ring.allocated_bytes())
    }

    /// The cubes and spheres placed by the node matrices `world`, uploaded by this frame and
    /// imported into `rg`; `None` when the scene has no dynamic object.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        world: &[Mat4],
    ) -> Result<Option<CubeInputs>, RenderError> {
        if self.objects.is_empty() {
            return Ok(None);
        }
        let (cubes, spheres) = records(&self.objects, world);
        if spheres.len() > MAX_PROXIES as usize {
            return Err(RenderError::Invalid(format!(
                "environment cubes: {} proxy spheres, at most {MAX_PROXIES}",
                spheres.len()
            )));
        }
        let device = &self.device;
        let (cube_buffer, sphere_buffer) = match &self.buffers {
            Some(b) => b,
            None => {
                let make =
                    |name, bytes: usize| Buffer::storage_for_uploads(device, name, bytes as u64);
                let cube_buffer = make("cubes", std::mem::size_of_val(cubes.as_slice()))?;
                let sphere_buffer =
                    make("cube spheres", std::mem::size_of_val(spheres.as_slice()))?;
                self.buffers.insert((cube_buffer, sphere_buffer))
            }
        };
        let cube_handle =
            self.ring
                .upload(rg, "cubes", cube_buffer, bytemuck::cast_slice(&cubes))?;
        let sphere_handle = self.ring.upload(
            rg,
            "cube spheres",
            sphere_buffer,
            bytemuck::cast_slice(&spheres),
        )?;
        Ok(Some(CubeInputs {
            cubes: cube_handle,
            cube_count: cubes.len() as u32,
            spheres: sphere_handle,
            sphere_count: spheres.len() as u32,
        }))
    }
}

/// Each object's bounding sphere (of its proxies, placed by `world`) and every proxy sphere
/// tagged with its object's cube.
fn records(
    objects: &[(usize, Vec<ProxySphere>)],
    world: &[Mat4],
) -> (Vec<GpuCube>, Vec<GpuCubeSphere>) {
    let mut cubes = Vec::with_capacity(objects.len());
    let mut spheres = Vec::new();
    for (index, (node, local)) in objects.iter().enumerate() {
        let matrix = world.get(*node).unwrap_or(&Mat4::IDENTITY);
        let placed: Vec<ProxySphere> = local.iter().map(|s| s.transformed(matrix)).collect();
        let (lo, hi) = placed.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), s| {
                let c = Vec3::from(s.center);
                (lo.min(c - s.radius), hi.max(c + s.radius))
            },
        );
        let centre = 0.5 * (lo + hi);
        let radius = placed
            .iter()
            .map(|s| Vec3::from(s.center).distance(centre) + s.radius)
            .fold(0.0f32, f32::max);
        cubes.push(GpuCube {
            sphere: centre.extend(radius).to_array(),
        });
        spheres.extend(placed.iter().map(|s| GpuCubeSphere {
            sphere: Vec3::from(s.center).extend(s.radius).to_array(),
            cube: [index as f32, 0.0, 0.0, 0.0],
        }));
    }
    (cubes, spheres)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_bounds_its_objects_spheres() {
        let objects = vec![
            (
                0,
                vec![
                    ProxySphere {
                        center: [0.0, 0.0, 0.0],
                        radius: 1.0,
                    },
                    ProxySphere {
                        center: [2.0, 0.0, 0.0],
                        radius: 0.5,
                    },
                ],
            ),
            (
                1,
                vec![ProxySphere {
                    center: [0.0; 3],
                    radius: 0.25,
                }],
            ),
        ];
        let world = [
            Mat4::IDENTITY,
            Mat4::from_scale_rotation_translation(
                Vec3::splat(2.0),
                glam::Quat::IDENTITY,
                Vec3::new(5.0, 1.0, 0.0),
            ),
        ];
        let (cubes, spheres) = records(&objects, &world);
        assert_eq!(cubes.len(), 2);
        assert_eq!(spheres.len(), 3);
        assert_eq!(cubes[0].sphere, [0.75, 0.0, 0.0, 1.75]);
        assert_eq!(cubes[1].sphere, [5.0, 1.0, 0.0, 0.5]);
        assert_eq!(spheres[2].cube[0], 1.0);
        assert_eq!(spheres[2].sphere, [5.0, 1.0, 0.0, 0.5]);
    }
}
