//! A shine-scene [`Scene`] living on the GPU across frames.
//!
//! [`GpuScene::new`] uploads what never changes once: the flattened mesh-space vertices and
//! the index buffer of the whole scene (so every raster view is a single draw), the
//! materials, the texture arrays and the bottom levels of the BVH. [`GpuScene::update`]
//! evaluates a [`FrameUpdate`] on the CPU (animation, host overrides: a [`FrameState`]);
//! [`GpuScene::declare`] then records the frame's `update …` passes — the instance records,
//! lights and top-level BVH copied from a staging ring ([`upload_ring`]), the world vertices
//! rewritten by a compute pass — and returns the handles every later pass reads
//! ([`SceneHandles`]). Nothing on the frame path waits for the queue.

pub mod bvh;
mod deformers;
pub mod environment;
pub mod environment_sh;
pub mod frame_update;
pub mod geometry;
mod morph_edit;
mod textures;
pub mod upload_ring;

use glam::Mat4;
use shine_gpu::{Buffer, BufferDesc, Device, Image, MemoryLocation, vk};
use shine_graph::{ExternalState, Handle, RenderGraph};
use shine_scene::{Light, LightKind, Material, Scene};

use crate::passes::update_vertices::{DeformInputs, update_vertices};
use bvh::{BottomLevels, GpuBvh, TopInstance, TopLevel, TraceImages};
use deformers::Deformers;
pub use frame_update::{CameraPose, FrameState, FrameUpdate};
use geometry::{DeformFrame, DeformInstance, Geometry, InstanceRange};
use upload_ring::UploadRing;

/// Edge of every layer of the texture arrays, in texels.
pub const TEXTURE_SIZE: u32 = 256;

/// Mip levels of the texture arrays: the full chain down to 1×1, built by linear blits at
/// upload (the raster passes sample them trilinearly; ray hits read level 0).
pub const TEXTURE_MIP_LEVELS: u32 = TEXTURE_SIZE.ilog2() + 1;

/// Persistent buffers the frame reads (scene, BVH, tables, shadow records): read by any stage,
/// before and after the frame.
pub const BUFFER_READ: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::MEMORY_READ,
    vk::ImageLayout::UNDEFINED,
);

/// Persistent storage images the frame reads (the BVH's): `GENERAL` layout, read by any stage,
/// before and after the frame.
pub const STORAGE_READ: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::MEMORY_READ,
    vk::ImageLayout::GENERAL,
);

/// Persistent sampled images (texture arrays, environment): read-only, before and after.
pub const SAMPLED_READ: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::SHADER_READ,
    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
);

/// One vertex of the flattened scene (64 bytes; locations 0–4 of the raster shaders): in mesh
/// space as uploaded, in world space after the `update vertices` pass.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// Position (location 0).
    pub position: [f32; 3],
    /// Index into the materials buffer (location 1).
    pub material: u32,
    /// Normal (location 2).
    pub normal: [f32; 3],
    /// Index of the instance the vertex belongs to (in [`GpuScene::instances`]).
    pub instance: u32,
    /// Tangent, w = bitangent sign (location 3).
    pub tangent: [f32; 4],
    /// Texture coordinate 0 (location 4).
    pub uv: [f32; 2],
    /// Padding.
    pub _pad1: [f32; 2],
}

/// A material as the shaders read it: shine-scene's material with texture indices remapped to
/// layers of the sRGB (base colour, emissive) and linear (metallic-roughness, normal) arrays.
pub type GpuMaterial = Material;

/// What went wrong while preparing a scene for the GPU or updating it.
#[derive(Debug, thiserror::Error)]
pub enum SceneUploadError {
    /// The scene has no triangles to draw.
    #[error("the scene has no triangles")]
    Empty,
    /// A GPU operation failed.
    #[error(transparent)]
    Gpu(#[from] shine_gpu::Error),
    /// The scene is too large for 32-bit indices or one storage buffer.
    #[error("the scene is too large: {0}")]
    TooLarge(String),
    /// A frame update names something the scene lacks or holds non-finite numbers.
    #[error("frame update: {0}")]
    Update(String),
}

/// The scene's resources imported into one frame graph, after its `update …` passes.
#[derive(Clone, Copy, Debug)]
pub struct SceneHandles {
    /// World-space vertices ([`Vertex`]), written by `update vertices`.
    pub vertices: Handle<shine_graph::Buffer>,
    /// The previous frame's world-space vertices (this frame's on a scene's first frame):
    /// the G-buffer's motion vectors start from them.
    pub prev_vertices: Handle<shine_graph::Buffer>,
    /// Index buffer.
    pub indices: Handle<shine_graph::Buffer>,
    /// Materials.
    pub materials: Handle<shine_graph::Buffer>,
    /// Lights of this frame.
    pub lights: Handle<shine_graph::Buffer>,
    /// sRGB texture array.
    pub srgb_textures: Handle<shine_graph::Image>,
    /// Linear texture array.
    pub linear_textures: Handle<shine_graph::Image>,
    /// The two-level BVH of this frame.
    pub trace: TraceImages,
    /// Index count of the single draw.
    pub index_count: u32,
}

/// The scene on the GPU: static data uploaded once, per-frame data from the last update.
pub struct GpuScene {
    /// Mesh-space vertices ([`Vertex`]), uploaded once.
    pub source_vertices: Buffer,
    /// World-space vertices ([`Vertex`]), rewritten every frame.
    pub vertices: Buffer,
    /// The previous frame's world-space vertices.
    pub prev_vertices: Buffer,
    /// Whether a frame was declared since upload (`prev_vertices` holds something).
    has_previous: bool,
    /// Triangle-list indices (u32), shared by both vertex buffers.
    pub indices: Buffer,
    /// Number of indices.
    pub index_count: u32,
    /// Number of vertices.
    pub vertex_count: u32,
    /// Materials ([`GpuMaterial`], 80 bytes each).
    pub materials: Buffer,
    /// sRGB colour textures, one per layer.
    pub srgb_textures: Image,
    /// Linear data textures, one per layer.
    pub linear_textures: Image,
    /// Lights of the current frame ([`Light`], 64 bytes each).
    pub lights: Buffer,
    /// The two-level BVH (bottom levels static, top level per frame).
    pub bvh: GpuBvh,
    /// Per instance: where its vertices and triangles lie.
    pub instances: Vec<InstanceRange>,
    /// The scene at the last update.
    pub state: FrameState,
    /// Per instance: [`DeformInstance`] records of the current frame.
    deform_instances: Buffer,
    /// Per vertex: skin influences ([`geometry::SkinVertex`]), static.
    skin_vertices: Buffer,
    /// Morph deltas: static, unless a host rewrites a target ([`GpuScene::set_morph_target`]).
    morph_deltas: Buffer,
    /// The CPU copy of `morph_deltas`, as the last set target left it.
    deltas: Vec<[f32; 4]>,
    /// `deltas` changed since `morph_deltas` was last written: the next frame uploads them.
    deltas_pending: bool,
    /// A target was ever set ([`GpuScene::set_morph_target`]).
    deltas_edited: bool,
    /// The frame's joint matrices.
    joint_matrices: Buffer,
    /// The frame's morph weights.
    morph_weights: Buffer,
    /// Bottom levels of the deforming instances, refitted every frame.
    deformers: Deformers,
    /// The scene's CPU data that frames are evaluated from (textures dropped).
    rig: Scene,
    /// Staging buffers of the per-frame uploads.
    ring: UploadRing,
}

impl GpuScene {
    /// Uploads the static data of `scene`, posed at time 0 until the first
    /// [`GpuScene::update`].
    pub fn new(device: &Device, scene: &Scene) -> Result<Self, SceneUploadError> {
        let geometry = Geometry::flatten(scene)?;
        let (materials, srgb_layers, linear_layers) = textures::remap_textures(scene);
        let storage = |name, data: &[u8], usage| {
            Buffer::with_data(
                device,
                &BufferDesc {
                    name,
                    size: data.len().max(16) as u64,
                    usage,
                    location: MemoryLocation::GpuOnly,
                },
                data,
            )
        };
        let dynamic = |name, size: usize, usage| {
            Buffer::new(
                device,
                &BufferDesc {
                    name,
                    size: size.max(16) as u64,
                    usage: usage | vk::BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuOnly,
                },
            )
        };
        let vertex_bytes = std::mem::size_of_val(geometry.source.as_slice());
        let instance_count = geometry.instances.len();
        let rig = Scene {
            textures: Vec::new(),
            ..scene.clone()
        };
        let state = FrameState::evaluate(&rig, &FrameUpdate::default());
        let mut bottom = BottomLevels::default();
        let (deformers, _) = Deformers::build(&rig, &geometry.instances, &state.pose, &mut bottom);
        bottom.add_meshes(scene);
        let joint_count: usize = state.pose.joints.iter().map(Vec::len).sum();
        let weight_count: usize = geometry
            .instances
            .iter()
            .map(|r| r.target_count as usize)
            .sum();
        Ok(Self {
            source_vertices: storage(
                "scene source vertices",
                bytemuck::cast_slice(&geometry.source),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            // TRANSFER_SRC: hosts and tests may copy the frame's vertices out.
            vertices: dynamic(
                "scene vertices",
                vertex_bytes,
                vk::BufferUsageFlags::VERTEX_BUFFER
                    | vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            prev_vertices: dynamic(
                "scene previous vertices",
                vertex_bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            has_previous: false,
            indices: storage(
                "scene indices",
                bytemuck::cast_slice(&geometry.indices),
                // TRANSFER_SRC: the path tracer copies indices, materials and lights into
                // images (src/reference/scene_texels.rs).
                vk::BufferUsageFlags::INDEX_BUFFER
                    | vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            index_count: geometry.indices.len() as u32,
            vertex_count: geometry.source.len() as u32,
            materials: storage(
                "scene materials",
                bytemuck::cast_slice(&materials),
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            srgb_textures: textures::texture_array(
                device,
                "srgb textures",
                vk::Format::R8G8B8A8_SRGB,
                &srgb_layers,
            )?,
            linear_textures: textures::texture_array(
                device,
                "linear textures",
                vk::Format::R8G8B8A8_UNORM,
                &linear_layers,
            )?,
            lights: dynamic(
                "scene lights",
                scene.lights.len().max(1) * std::mem::size_of::<Light>(),
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
            )?,
            bvh: GpuBvh::new(device, bottom, instance_count)?,
            deform_instances: dynamic(
                "deform instances",
                instance_count * std::mem::size_of::<DeformInstance>(),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            skin_vertices: storage(
                "scene skin vertices",
                bytemuck::cast_slice(&geometry.skin),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            // TRANSFER_DST: a host's new shape is copied in (`set_morph_target`).
            morph_deltas: storage(
                "scene morph deltas",
                bytemuck::cast_slice(&geometry.deltas),
                vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            )?,
            deltas: geometry.deltas.clone(),
            deltas_pending: false,
            deltas_edited: false,
            joint_matrices: dynamic(
                "joint matrices",
                joint_count * std::mem::size_of::<Mat4>(),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            morph_weights: dynamic(
                "morph weights",
                weight_count * std::mem::size_of::<f32>(),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            deformers,
            instances: geometry.instances,
            state,
            rig,
            ring: UploadRing::new(device),
        })
    }

    /// Uploads `scene` and poses it at time `t` (a cold start).
    pub fn upload(device: &Device, scene: &Scene, t: f32) -> Result<Self, SceneUploadError> {
        let mut gpu = Self::new(device, scene)?;
        gpu.update(&FrameUpdate::at(t))?;
        Ok(gpu)
    }

    /// Evaluates `update` for the next frame (CPU only: the GPU is written when the frame is
    /// declared). A bad update is refused and the previous state kept.
    pub fn update(&mut self, update: &FrameUpdate) -> Result<(), SceneUploadError> {
        update
            .validate(&self.rig)
            .map_err(SceneUploadError::Update)?;
        self.state = FrameState::evaluate(&self.rig, update);
        Ok(())
    }

    /// Bytes of device memory: `(scene data, staging)`: geometry, materials, textures,
    /// lights, the BVH and the deformers' data, and the staging ring of its updates.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        let buffers = [
            &self.source_vertices,
            &self.vertices,
            &self.prev_vertices,
            &self.indices,
            &self.materials,
            &self.lights,
            &self.deform_instances,
            &self.skin_vertices,
            &self.morph_deltas,
            &self.joint_matrices,
            &self.morph_weights,
        ];
        let scene = buffers.iter().map(|b| b.allocated_bytes()).sum::<u64>()
            + self.bvh.allocated_bytes()
            + self.srgb_textures.allocated_bytes()
            + self.linear_textures.allocated_bytes();
        (scene, self.ring.allocated_bytes())
    }

    /// Forgets the previous frame's vertices (a declared frame was not run): the next frame
    /// starts its motion from itself.
    pub fn forget_previous(&mut self) {
        self.has_previous = false;
    }

    /// The scene's CPU data (without textures), as frames are evaluated from it.
    pub fn rig(&self) -> &Scene {
        &self.rig
    }

    /// Mesh-to-world matrix of every instance in the current frame.
    pub fn instance_matrices(&self) -> Vec<Mat4> {
        self.instances
            .iter()
            .map(|r| {
                self.state
                    .pose
                    .world
                    .get(r.node as usize)
                    .copied()
                    .unwrap_or(Mat4::IDENTITY)
            })
            .collect()
    }

    /// Records this frame's `update …` passes (instance records, lights and top-level BVH
    /// copied from the staging ring; the world vertices rewritten) and imports everything the
    /// frame reads.
    pub fn declare(&mut self, rg: &mut RenderGraph) -> Result<SceneHandles, SceneUploadError> {
        self.refresh_edited_bounds();
        let frame = DeformFrame::new(&self.instances, &self.state.pose);
        let (nodes, triangles, deformer_roots) = self.declare_bottom_levels(rg)?;
        let bottom = &self.bvh.bottom;
        let top = TopLevel::build(
            &self
                .instances
                .iter()
                .zip(&deformer_roots)
                .map(|(r, deformer)| match deformer {
                    // Deforming: its own bottom level, already in world space.
                    Some((root, bounds)) => TopInstance {
                        world: Mat4::IDENTITY,
                        root: *root,
                        bounds: *bounds,
                        triangle_base: r.first_triangle,
                    },
                    None => TopInstance {
                        world: self
                            .state
                            .pose
                            .world
                            .get(r.node as usize)
                            .copied()
                            .unwrap_or(Mat4::IDENTITY),
                        root: bottom
                            .roots
                            .get(r.mesh as usize)
                            .copied()
                            .unwrap_or(u32::MAX),
                        bounds: bottom
                            .bounds
                            .get(r.mesh as usize)
                            .copied()
                            .unwrap_or(shine_scene::Aabb::EMPTY),
                        triangle_base: r.first_triangle,
                    },
                })
                .collect::<Vec<_>>(),
        );
        let ring = &mut self.ring;
        let deform = ring.upload(
            rg,
            "instances",
            &self.deform_instances,
            bytemuck::cast_slice(&frame.instances),
        )?;
        let joints = ring.upload(
            rg,
            "joints",
            &self.joint_matrices,
            bytemuck::cast_slice(&frame.joints),
        )?;
        let weights = ring.upload(
            rg,
            "weights",
            &self.morph_weights,
            bytemuck::cast_slice(&frame.weights),
        )?;
        let lights = ring.upload(
            rg,
            "lights",
            &self.lights,
            bytemuck::cast_slice(&self.state.lights),
        )?;
        let top_nodes = ring.upload_image_rows(
            rg,
            "bvh top",
            &self.bvh.top,
            &bvh::leading_rows(
                bytemuck::cast_slice(&top.nodes),
                &[],
                self.bvh.top.extent()[0],
            ),
        )?;
        let top_instances = ring.upload_image_rows(
            rg,
            "bvh instances",
            &self.bvh.instances,
            &bvh::leading_rows(
                bytemuck::cast_slice(&top.instances),
                &[],
                self.bvh.instances.extent()[0],
            ),
        )?;
        let inputs = DeformInputs {
            source: rg.import_gpu_buffer(&self.source_vertices, BUFFER_READ, BUFFER_READ),
            skin: rg.import_gpu_buffer(&self.skin_vertices, BUFFER_READ, BUFFER_READ),
            deltas: if std::mem::take(&mut self.deltas_pending) {
                ring.upload(
                    rg,
                    "morph deltas",
                    &self.morph_deltas,
                    bytemuck::cast_slice(&self.deltas),
                )?
            } else {
                rg.import_gpu_buffer(&self.morph_deltas, BUFFER_READ, BUFFER_READ)
            },
            instances: deform,
            joints,
            weights,
            vertex_count: self.vertex_count,
        };
        let mut vertices = rg.import_gpu_buffer(&self.vertices, BUFFER_READ, BUFFER_READ);
        let mut prev_vertices = rg.import_gpu_buffer(&self.prev_vertices, BUFFER_READ, BUFFER_READ);
        // The last frame's vertices become the previous ones before they are rewritten; on
        // the first frame the previous ones are this frame's (no motion).
        if self.has_previous {
            rg.copy_buffer("update previous vertices", &vertices, &mut prev_vertices);
            update_vertices(rg, &inputs, &mut vertices);
        } else {
            update_vertices(rg, &inputs, &mut vertices);
            rg.copy_buffer("update previous vertices", &vertices, &mut prev_vertices);
            self.has_previous = true;
        }
        Ok(SceneHandles {
            vertices,
            prev_vertices,
            indices: rg.import_gpu_buffer(&self.indices, BUFFER_READ, BUFFER_READ),
            materials: rg.import_gpu_buffer(&self.materials, BUFFER_READ, BUFFER_READ),
            lights,
            srgb_textures: rg.import_gpu_image(&self.srgb_textures, SAMPLED_READ, SAMPLED_READ),
            linear_textures: rg.import_gpu_image(&self.linear_textures, SAMPLED_READ, SAMPLED_READ),
            trace: TraceImages {
                nodes,
                triangles,
                top: top_nodes,
                instances: top_instances,
            },
            index_count: self.index_count,
        })
    }

    /// The bottom-level images of this frame: the deformers refitted and their prefix
    /// uploaded (when there are any), and per instance its deformer's root and bounds.
    #[allow(clippy::type_complexity)]
    fn declare_bottom_levels(
        &mut self,
        rg: &mut RenderGraph,
    ) -> Result<
        (
            Handle<shine_graph::Image>,
            Handle<shine_graph::Image>,
            Vec<Option<(u32, shine_scene::Aabb)>>,
        ),
        SceneUploadError,
    > {
        if self.deformers.is_empty() {
            return Ok((
                rg.import_gpu_image(&self.bvh.nodes, STORAGE_READ, STORAGE_READ),
                rg.import_gpu_image(&self.bvh.triangles, STORAGE_READ, STORAGE_READ),
                vec![None; self.instances.len()],
            ));
        }
        let (prefix, roots) = self
            .deformers
            .refit(&self.rig, &self.instances, &self.state.pose);
        // The deformers' levels come first; the copies rewrite the rows they touch, the rest
        // of the last one from the static levels.
        let bottom = &self.bvh.bottom;
        let nodes = self.ring.upload_image_rows(
            rg,
            "bvh deformer nodes",
            &self.bvh.nodes,
            &bvh::leading_rows(
                bytemuck::cast_slice(&prefix.nodes),
                bytemuck::cast_slice(&bottom.nodes),
                self.bvh.nodes.extent()[0],
            ),
        )?;
        let triangles = self.ring.upload_image_rows(
            rg,
            "bvh deformer triangles",
            &self.bvh.triangles,
            &bvh::leading_rows(
                bytemuck::cast_slice(&prefix.triangles),
                bytemuck::cast_slice(&bottom.triangles),
                self.bvh.triangles.extent()[0],
            ),
        )?;
        Ok((nodes, triangles, roots))
    }

    /// Index of the primary light (the one with a shadow map and an RSM): the first spot or
    /// directional light, else the first light.
    pub fn primary_light(&self) -> Option<usize> {
        let kind = |l: &Light| l.light_kind();
        self.state
            .lights
            .iter()
            .position(|l| matches!(kind(l), Some(LightKind::Spot | LightKind::Directional)))
            .or_else(|| (!self.state.lights.is_empty()).then_some(0))
    }
}
