//! Tiny environment cubes (issue 18, item 3; paper 001) as the frame uses them: one cube per
//! dynamic object of the scene (a node with proxies), placed every frame by the node's world
//! matrix, its texels kept on the device from frame to frame, and the passes of
//! [`crate::passes::cubes`].
//!
//! Which cubes a frame refreshes (`cubes.slices = k`; paper 001: "update one object at the
//! time"): all of them without a history (the first frame, a frame dropped before, another
//! weighting), when a light changed, or when anything else the cubes see changed (a node with
//! a mesh that is not a cube's object, morph weights, skin joints); else the cubes with
//! `i ≡ frame (mod k)`, every cube whose object's node moved since its last refresh, and every
//! cube that an object moving this frame is, or was last frame, near enough to show in
//! (`r / d ≥` [`NEIGHBOUR_ALPHA`]). Matrices count as moved past a relative change of
//! [`MOVE_TOLERANCE`], so rounding in a still node's matrix does not refresh its neighbours.

use glam::{Mat4, Vec3};
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, vk};
use shine_graph::{ExternalState, RenderGraph};
use shine_scene::proxies::ProxySphere;
use shine_scene::{Pose, Scene};

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
    /// The other nodes with a mesh: what the cubes see besides each other.
    scenery: Vec<usize>,
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
    /// The scenery's world matrices, every morph weight and joint matrix at that frame.
    scenery: Vec<f32>,
    /// Each cube's bounding sphere at that frame.
    previous: Vec<[f32; 4]>,
    /// Each cube's object's world matrix at that frame.
    world: Vec<Mat4>,
    /// Each cube's object's world matrix when the cube was last refreshed.
    refreshed: Vec<Mat4>,
}

/// Largest change of a matrix element, relative to the matrix's largest element, that still
/// counts as standing still.
pub const MOVE_TOLERANCE: f32 = 1e-6;

/// Whether `a` and `b` differ past [`MOVE_TOLERANCE`] of their largest element.
fn moved(a: &[f32], b: &[f32]) -> bool {
    if a.len() != b.len() {
        return true;
    }
    let scale = a.iter().chain(b).fold(1.0f32, |m, x| m.max(x.abs()));
    a.iter()
        .zip(b)
        .any(|(x, y)| (x - y).abs() > MOVE_TOLERANCE * scale)
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
        let objects: Vec<(usize, Vec<ProxySphere>)> = scene
            .proxies
            .iter()
            .filter(|p| !p.spheres.is_empty())
            .map(|p| (p.node, p.spheres.clone()))
            .collect();
        let scenery = (0..scene.nodes.len())
            .filter(|&i| scene.nodes[i].mesh.is_some() && objects.iter().all(|(n, _)| *n != i))
            .collect();
        Self {
            objects,
            scenery,
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

    /// The cubes and spheres placed by the frame's `pose`, this frame's refresh list
    /// (`params.slices`, what moved in `pose`, the `lights` records), uploaded by this frame
    /// and imported into `rg` with the persistent texels; `None` when the scene has no dynamic
    /// object.
    pub fn prepare(
        &mut self,
        rg: &mut RenderGraph,
        pose: &Pose,
        lights: &[u8],
        params: &CubeParams,
    ) -> Result<Option<CubeInputs>, RenderError> {
        if self.objects.is_empty() {
            return Ok(None);
        }
        let world = &pose.world;
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
        let object_world: Vec<Mat4> = self
            .objects
            .iter()
            .map(|(node, _)| world.get(*node).copied().unwrap_or(Mat4::IDENTITY))
            .collect();
        let scenery: Vec<f32> = self
            .scenery
            .iter()
            .filter_map(|&n| world.get(n))
            .flat_map(|m| m.to_cols_array())
            .chain(pose.weights.iter().flatten().copied())
            .chain(pose.joints.iter().flatten().flat_map(|m| m.to_cols_array()))
            .collect();
        let (refresh, refreshed) = match self.history.take() {
            Some(h)
                if h.frame.wrapping_add(1) == frame
                    && h.solid_angle == params.solid_angle
                    && h.lights == lights
                    && !moved(&h.scenery, &scenery) =>
            {
                let changed = |a: &[Mat4], i: usize| {
                    moved(&a[i].to_cols_array(), &object_world[i].to_cols_array())
                };
                let moving: Vec<bool> = (0..bounds.len()).map(|i| changed(&h.world, i)).collect();
                let stale: Vec<bool> = (0..bounds.len())
                    .map(|i| changed(&h.refreshed, i))
                    .collect();
                let refresh =
                    refresh_list(&bounds, &h.previous, &moving, &stale, frame, params.slices);
                let mut refreshed = h.refreshed;
                for &i in &refresh {
                    refreshed[i as usize] = object_world[i as usize];
                }
                (refresh, refreshed)
            }
            _ => ((0..bounds.len() as u32).collect(), object_world.clone()),
        };
        self.history = Some(History {
            frame,
            solid_angle: params.solid_angle,
            lights: lights.to_vec(),
            scenery,
            previous: bounds,
            world: object_world,
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

/// The cubes a frame with a history refreshes: slice `frame mod slices`, every `stale` cube
/// (its object moved since its last refresh), and every cube in which a `moving` object (moved
/// since last frame) subtends `r / d ≥` [`NEIGHBOUR_ALPHA`] now (`bounds`) or last frame
/// (`previous`).
fn refresh_list(
    bounds: &[[f32; 4]],
    previous: &[[f32; 4]],
    moving: &[bool],
    stale: &[bool],
    frame: u64,
    slices: u32,
) -> Vec<u32> {
    let movers: Vec<usize> = (0..bounds.len()).filter(|&i| moving[i]).collect();
    let slice = frame % u64::from(slices.max(1));
    let shows_in = |sphere: &[f32; 4], centre: Vec3| {
        sphere[3] >= NEIGHBOUR_ALPHA * centre.distance(Vec3::from_slice(&sphere[..3]))
    };
    (0..bounds.len())
        .filter(|&i| {
            let centre = Vec3::from_slice(&bounds[i][..3]);
            i as u64 % u64::from(slices.max(1)) == slice
                || stale[i]
                || movers
                    .iter()
                    .any(|&m| shows_in(&bounds[m], centre) || shows_in(&previous[m], centre))
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

    /// Slice 1 of 4 holds cubes 1 and 5; cube 3 is stale; cube 6 moves this frame, so cube 7
    /// refreshes when it stands close to where cube 6 is, or was, and cube 0 (far) does not.
    #[test]
    fn a_frame_refreshes_its_slice_and_what_moved() {
        let at = |x: f32| [x, 0.0, 0.0, 0.5];
        let mut bounds: Vec<[f32; 4]> = (0..8).map(|i| at(100.0 * i as f32)).collect();
        let mut previous = bounds.clone();
        let mut moving = vec![false; 8];
        let mut stale = vec![false; 8];
        stale[3] = true;
        moving[6] = true;
        stale[6] = true;
        previous[6] = at(601.0);
        assert_eq!(
            refresh_list(&bounds, &previous, &moving, &stale, 5, 4),
            [1, 3, 5, 6]
        );
        for b in [&mut bounds, &mut previous] {
            b[7] = at(602.0);
        }
        assert_eq!(
            refresh_list(&bounds, &previous, &moving, &stale, 5, 4),
            [1, 3, 5, 6, 7]
        );
        // cube 6 jumps far away: cube 7 still sees where it was
        bounds[6] = at(5000.0);
        previous[6] = at(602.5);
        assert_eq!(
            refresh_list(&bounds, &previous, &moving, &stale, 5, 4),
            [1, 3, 5, 6, 7]
        );
        let none = vec![false; 8];
        assert_eq!(refresh_list(&bounds, &bounds, &none, &none, 5, 1).len(), 8);
    }

    #[test]
    fn rounding_is_not_motion() {
        let a = Mat4::from_translation(Vec3::new(3.0, 1.0, -2.0)).to_cols_array();
        let mut b = a;
        b[12] += 1e-7;
        assert!(!moved(&a, &b));
        b[12] += 1e-3;
        assert!(moved(&a, &b));
        assert!(moved(&a, &a[..8]));
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
