//! Tiny environment cubes (issue 18, item 3; paper 001) as the frame uses them: one cube per
//! dynamic object of the scene (a node with proxies), placed every frame by the node's world
//! matrix, its texels kept on the device from frame to frame, and the passes of
//! [`crate::passes::cubes`].
//!
//! Which cubes a frame refreshes (`cubes.slices = k`; paper 001: "update one object at the
//! time"): all of them without a history (the first frame, a frame dropped before, another
//! weighting, another object count) or when a light changed; else the cubes with `i ≡ frame
//! (mod k)`, every cube whose object moved since its last refresh, and every cube that an
//! object moving this frame is near enough to show in (`r / d ≥` [`NEIGHBOUR_ALPHA`]).

use glam::{Mat4, Vec3};
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, vk};
use shine_graph::{ExternalState, RenderGraph};
use shine_scene::Scene;
use shine_scene::proxies::ProxySphere;

use super::error::RenderError;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::passes::cubes::{
    CubeInputs, CubeParams, GpuCube, GpuCubeSphere, NEIGHBOUR_ALPHA, TEXELS,
};
use crate::passes::proxy::MAX_PROXIES;

/// The cubes' persistent state: each dynamic object's proxies in its node's space, the device
/// buffers of their records and texels, and what the last frame refreshed from.
pub struct CubeTechnique {
    /// (node, its proxies in the node's space), one entry per cube.
    objects: Vec<(usize, Vec<ProxySphere>)>,
    /// Device buffers, made on first use.
    buffers: Option<CubeBuffers>,
    ring: UploadRing,
    device: Device,
    /// What the texels in `buffers` were made from; `None`: they are stale.
    history: Option<History>,
}

/// The device buffers of the cubes.
struct CubeBuffers {
    cubes: Buffer,
    spheres: Buffer,
    refresh: Buffer,
    radiance: Buffer,
    smoothed: Buffer,
}

/// What the texels on the device were made from.
struct History {
    /// The frame that last declared the cubes.
    frame: u64,
    /// The smoothing weights of the texels (solid angle or plain).
    solid_angle: bool,
    /// The lights' records at that frame.
    lights: Vec<u8>,
    /// Each cube's bounding sphere at that frame.
    previous: Vec<[f32; 4]>,
    /// Each cube's bounding sphere when it was last refreshed.
    refreshed: Vec<[f32; 4]>,
}

/// Device access of the texel buffers between frames: written and read by compute passes.
const TEXELS_STATE: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::MEMORY_READ.as_raw() | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
    ),
    vk::ImageLayout::UNDEFINED,
);

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
            history: None,
        }
    }

    /// Bytes of device memory: `(records and texels, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        let owned = self.buffers.iter().map(|b| {
            [&b.cubes, &b.spheres, &b.refresh, &b.radiance, &b.smoothed]
                .iter()
                .map(|x| x.allocated_bytes())
                .sum::<u64>()
        });
        (owned.sum(), self.ring.allocated_bytes())
    }

    /// Forgets the texels: a frame that may have written them was dropped unrun.
    pub fn reset(&mut self) {
        self.history = None;
    }

    /// The cubes and spheres placed by the node matrices `world`, this frame's refresh list
    /// (`params.slices`, the moving objects, the `lights` records), uploaded by this frame and
    /// imported into `rg` with the persistent texels; `None` when the scene has no dynamic
    /// object.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        world: &[Mat4],
        lights: &[u8],
        params: &CubeParams,
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
        if self.buffers.is_none() {
            self.buffers = Some(self.make_buffers(cubes.len(), spheres.len())?);
            self.history = None;
        }
        let frame = rg.frame();
        let bounds: Vec<[f32; 4]> = cubes.iter().map(|c| c.sphere).collect();
        let (refresh, refreshed) = match self.history.take() {
            Some(h)
                if h.frame.wrapping_add(1) == frame
                    && h.solid_angle == params.solid_angle
                    && h.lights == lights
                    && h.previous.len() == bounds.len() =>
            {
                let refresh =
                    refresh_list(&bounds, &h.previous, &h.refreshed, frame, params.slices);
                let mut refreshed = h.refreshed;
                for &i in &refresh {
                    refreshed[i as usize] = bounds[i as usize];
                }
                (refresh, refreshed)
            }
            _ => ((0..bounds.len() as u32).collect(), bounds.clone()),
        };
        self.history = Some(History {
            frame,
            solid_angle: params.solid_angle,
            lights: lights.to_vec(),
            previous: bounds,
            refreshed,
        });
        let buffers = self.buffers.as_ref().ok_or(RenderError::NoScene)?;
        let cube_handle =
            self.ring
                .upload(rg, "cubes", &buffers.cubes, bytemuck::cast_slice(&cubes))?;
        let sphere_handle = self.ring.upload(
            rg,
            "cube spheres",
            &buffers.spheres,
            bytemuck::cast_slice(&spheres),
        )?;
        // The list's buffer holds every cube; only the first `refresh.len()` entries are read.
        let mut list = refresh.clone();
        list.resize(cubes.len(), 0);
        let refresh_handle = self.ring.upload(
            rg,
            "cube refresh",
            &buffers.refresh,
            bytemuck::cast_slice(&list),
        )?;
        Ok(Some(CubeInputs {
            cubes: cube_handle,
            spheres: sphere_handle,
            sphere_count: spheres.len() as u32,
            refresh: refresh_handle,
            refresh_count: refresh.len() as u32,
            radiance: rg.import_gpu_buffer(&buffers.radiance, TEXELS_STATE, TEXELS_STATE),
            smoothed: rg.import_gpu_buffer(&buffers.smoothed, TEXELS_STATE, TEXELS_STATE),
        }))
    }

    /// The device buffers for `cubes` objects with `spheres` proxy spheres.
    fn make_buffers(&self, cubes: usize, spheres: usize) -> Result<CubeBuffers, RenderError> {
        let device = &self.device;
        let upload = |name, bytes: usize| Buffer::storage_for_uploads(device, name, bytes as u64);
        let texels = |name| {
            Buffer::new(
                device,
                &BufferDesc {
                    name,
                    size: (cubes * TEXELS as usize * 16) as u64,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::GpuOnly,
                },
            )
        };
        Ok(CubeBuffers {
            cubes: upload("cubes", cubes * std::mem::size_of::<GpuCube>())?,
            spheres: upload(
                "cube spheres",
                spheres * std::mem::size_of::<GpuCubeSphere>(),
            )?,
            refresh: upload("cube refresh", cubes * 4)?,
            radiance: texels("cube radiance")?,
            smoothed: texels("cube smoothed")?,
        })
    }
}

/// The cubes a frame with a history refreshes: slice `frame mod slices`, every cube whose
/// bounding sphere differs from `refreshed` (its last refresh), and every cube in which an
/// object whose sphere differs from `previous` (last frame) subtends `r / d ≥`
/// [`NEIGHBOUR_ALPHA`].
fn refresh_list(
    bounds: &[[f32; 4]],
    previous: &[[f32; 4]],
    refreshed: &[[f32; 4]],
    frame: u64,
    slices: u32,
) -> Vec<u32> {
    let moving: Vec<usize> = (0..bounds.len())
        .filter(|&i| bounds[i] != previous[i])
        .collect();
    let slice = frame % u64::from(slices.max(1));
    (0..bounds.len())
        .filter(|&i| {
            let centre = Vec3::from_slice(&bounds[i][..3]);
            i as u64 % u64::from(slices.max(1)) == slice
                || bounds[i] != refreshed[i]
                || moving.iter().any(|&m| {
                    let other = Vec3::from_slice(&bounds[m][..3]);
                    bounds[m][3] >= NEIGHBOUR_ALPHA * centre.distance(other)
                })
        })
        .map(|i| i as u32)
        .collect()
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
            spheres: [spheres.len() as u32, placed.len() as u32, 0, 0],
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

    /// Slice 1 of 4 holds cubes 1 and 5; cube 3 moved since its last refresh; cube 6 moves
    /// this frame, so cube 7 refreshes when it stands close to it, cube 0 (far) does not.
    #[test]
    fn a_frame_refreshes_its_slice_and_what_moved() {
        let at = |x: f32| [x, 0.0, 0.0, 0.5];
        let mut bounds: Vec<[f32; 4]> = (0..8).map(|i| at(100.0 * i as f32)).collect();
        let mut previous = bounds.clone();
        let mut refreshed = bounds.clone();
        refreshed[3] = at(1.0);
        previous[6] = at(601.0);
        refreshed[6] = at(601.0);
        assert_eq!(
            refresh_list(&bounds, &previous, &refreshed, 5, 4),
            [1, 3, 5, 6]
        );
        for b in [&mut bounds, &mut previous, &mut refreshed] {
            b[7] = at(602.0);
        }
        assert_eq!(
            refresh_list(&bounds, &previous, &refreshed, 5, 4),
            [1, 3, 5, 6, 7]
        );
        assert_eq!(refresh_list(&bounds, &bounds, &bounds, 5, 1).len(), 8);
    }

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
        assert_eq!(cubes[0].spheres, [0, 2, 0, 0]);
        assert_eq!(cubes[1].spheres, [2, 1, 0, 0]);
        assert_eq!(spheres[2].sphere, [5.0, 1.0, 0.0, 0.5]);
    }
}
