//! A shine-scene [`Scene`] uploaded for rendering: one world-space vertex and index buffer for
//! the whole scene (so every raster view is a single draw), the materials, two texture arrays
//! and the lights.
//!
//! Decisions (first frame): geometry is flattened into world space on the CPU at a time `t`
//! (re-uploaded when the scene moves), textures are resized to one square size per array so
//! that they index a `texture2DArray` (lavapipe indexes arrays of textures only by constants),
//! colour textures live in an sRGB array and data textures (normal, metallic-roughness) in a
//! linear one.

pub mod bvh;
pub mod environment;
pub mod environment_sh;

use glam::{Mat3, Mat4, Vec3};
use shine_gpu::{Buffer, BufferDesc, Device, Image, ImageDesc, MemoryLocation, vk};
use shine_graph::ExternalState;
use shine_scene::{Light, LightKind, Material, NO_TEXTURE, Scene};

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

/// Persistent sampled images (texture arrays, environment): read-only, before and after.
pub const SAMPLED_READ: ExternalState = ExternalState::new(
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::SHADER_READ,
    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
);

/// One vertex of the flattened scene, in world space (64 bytes; locations 0–4 of the raster
/// shaders).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    /// World position (location 0).
    pub position: [f32; 3],
    /// Index into the materials buffer (location 1).
    pub material: u32,
    /// World normal (location 2).
    pub normal: [f32; 3],
    /// Padding.
    pub _pad0: f32,
    /// World tangent, w = bitangent sign (location 3).
    pub tangent: [f32; 4],
    /// Texture coordinate 0 (location 4).
    pub uv: [f32; 2],
    /// Padding.
    pub _pad1: [f32; 2],
}

/// A material as the shaders read it: shine-scene's material with texture indices remapped to
/// layers of the sRGB (base colour, emissive) and linear (metallic-roughness, normal) arrays.
pub type GpuMaterial = Material;

/// What went wrong while preparing a scene for the GPU.
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
}

/// The scene on the GPU at one instant.
pub struct GpuScene {
    /// World-space vertices ([`Vertex`]).
    pub vertices: Buffer,
    /// Triangle-list indices (u32).
    pub indices: Buffer,
    /// Number of indices.
    pub index_count: u32,
    /// Materials ([`GpuMaterial`], 80 bytes each).
    pub materials: Buffer,
    /// sRGB colour textures, one per layer.
    pub srgb_textures: Image,
    /// Linear data textures, one per layer.
    pub linear_textures: Image,
    /// Lights at this instant ([`Light`], 64 bytes each).
    pub lights: Buffer,
    /// The same lights on the CPU (shadow and RSM views are built from them).
    pub light_list: Vec<Light>,
    /// World-space bounds of the geometry.
    pub bounds: (Vec3, Vec3),
    /// Camera-to-world matrix of the scene's first camera at this instant.
    pub camera_world: Mat4,
    /// The first camera's projection.
    pub projection: shine_scene::Projection,
}

impl GpuScene {
    /// Flattens `scene` at time `t` (seconds, animations applied) and uploads it.
    pub fn upload(device: &Device, scene: &Scene, t: f32) -> Result<Self, SceneUploadError> {
        let world = scene.world_transforms_at(t);
        let mut vertices = Vec::new();
        let mut indices: Vec<u32> = Vec::new();
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for instance in scene.instances(&world) {
            let model = Mat4::from_cols_array_2d(&instance.world);
            let normal_matrix = Mat3::from_mat4(model).inverse().transpose();
            let Some(mesh) = scene.meshes.get(instance.mesh as usize) else {
                continue;
            };
            for primitive in &mesh.primitives {
                let base = u32::try_from(vertices.len())
                    .map_err(|_| SceneUploadError::TooLarge("over 4G vertices".into()))?;
                for (i, p) in primitive.positions.iter().enumerate() {
                    let position = model.transform_point3(*p);
                    lo = lo.min(position);
                    hi = hi.max(position);
                    let normal = primitive
                        .normals
                        .get(i)
                        .map_or(Vec3::Y, |n| (normal_matrix * *n).normalize_or(Vec3::Y));
                    let tangent = primitive.tangents.get(i).map_or([1.0, 0.0, 0.0, 1.0], |t| {
                        let v = model.transform_vector3(t.truncate()).normalize_or(Vec3::X);
                        [v.x, v.y, v.z, t.w]
                    });
                    vertices.push(Vertex {
                        position: position.to_array(),
                        material: primitive.material,
                        normal: normal.to_array(),
                        tangent,
                        uv: primitive.uvs.get(i).map_or([0.0; 2], |uv| uv.to_array()),
                        ..Vertex::default()
                    });
                }
                indices.extend(primitive.indices.iter().map(|i| base + i));
            }
        }
        if indices.is_empty() {
            return Err(SceneUploadError::Empty);
        }
        let index_count = u32::try_from(indices.len())
            .map_err(|_| SceneUploadError::TooLarge("over 4G indices".into()))?;

        let (materials, srgb_layers, linear_layers) = remap_textures(scene);
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
        let light_list = scene.lights_at(&world);
        let lights_bytes: &[u8] = if light_list.is_empty() {
            &[0; 64]
        } else {
            bytemuck::cast_slice(&light_list)
        };
        let camera_world = scene.camera_world(0, &world).unwrap_or(Mat4::IDENTITY);
        let projection = scene.cameras.first().map(|c| c.projection).unwrap_or(
            shine_scene::Projection::Perspective {
                yfov: 0.8,
                aspect_ratio: None,
                znear: 0.05,
                zfar: None,
            },
        );
        Ok(Self {
            vertices: storage(
                "scene vertices",
                bytemuck::cast_slice(&vertices),
                vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            indices: storage(
                "scene indices",
                bytemuck::cast_slice(&indices),
                vk::BufferUsageFlags::INDEX_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            index_count,
            materials: storage(
                "scene materials",
                bytemuck::cast_slice(&materials),
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            srgb_textures: texture_array(
                device,
                "srgb textures",
                vk::Format::R8G8B8A8_SRGB,
                &srgb_layers,
            )?,
            linear_textures: texture_array(
                device,
                "linear textures",
                vk::Format::R8G8B8A8_UNORM,
                &linear_layers,
            )?,
            lights: storage(
                "scene lights",
                lights_bytes,
                vk::BufferUsageFlags::STORAGE_BUFFER,
            )?,
            light_list,
            bounds: (lo, hi),
            camera_world,
            projection,
        })
    }

    /// Index of the primary light (the one with a shadow map and an RSM): the first spot or
    /// directional light, else the first light.
    pub fn primary_light(&self) -> Option<usize> {
        let kind = |l: &Light| l.light_kind();
        self.light_list
            .iter()
            .position(|l| matches!(kind(l), Some(LightKind::Spot | LightKind::Directional)))
            .or_else(|| (!self.light_list.is_empty()).then_some(0))
    }
}

/// Remaps texture indices to layers of the sRGB and linear arrays, and resizes every used
/// texture to [`TEXTURE_SIZE`]².
fn remap_textures(scene: &Scene) -> (Vec<GpuMaterial>, Vec<Vec<u8>>, Vec<Vec<u8>>) {
    let mut srgb: Vec<(u32, Vec<u8>)> = Vec::new();
    let mut linear: Vec<(u32, Vec<u8>)> = Vec::new();
    let mut layer = |index: u32, into_srgb: bool| -> u32 {
        let Some(texture) = scene.textures.get(index as usize) else {
            return NO_TEXTURE;
        };
        let list = if into_srgb { &mut srgb } else { &mut linear };
        if let Some(found) = list.iter().position(|(i, _)| *i == index) {
            return found as u32;
        }
        list.push((index, resize(texture)));
        (list.len() - 1) as u32
    };
    let materials = scene
        .materials
        .iter()
        .map(|m| GpuMaterial {
            base_color_texture: layer(m.base_color_texture, true),
            emissive_texture: layer(m.emissive_texture, true),
            metallic_roughness_texture: layer(m.metallic_roughness_texture, false),
            normal_texture: layer(m.normal_texture, false),
            ..*m
        })
        .collect::<Vec<_>>();
    let materials = if materials.is_empty() {
        vec![GpuMaterial {
            base_color: [0.8, 0.8, 0.8, 1.0],
            roughness: 1.0,
            base_color_texture: NO_TEXTURE,
            emissive_texture: NO_TEXTURE,
            metallic_roughness_texture: NO_TEXTURE,
            normal_texture: NO_TEXTURE,
            ..bytemuck::Zeroable::zeroed()
        }]
    } else {
        materials
    };
    let strip = |v: Vec<(u32, Vec<u8>)>| v.into_iter().map(|(_, t)| t).collect();
    (materials, strip(srgb), strip(linear))
}

fn resize(texture: &shine_scene::Texture) -> Vec<u8> {
    let image = image::RgbaImage::from_raw(texture.width, texture.height, texture.rgba8.clone());
    match image {
        Some(img) if texture.width == TEXTURE_SIZE && texture.height == TEXTURE_SIZE => {
            img.into_raw()
        }
        Some(img) => image::imageops::resize(
            &img,
            TEXTURE_SIZE,
            TEXTURE_SIZE,
            image::imageops::FilterType::Triangle,
        )
        .into_raw(),
        // A texture whose bytes do not match its size reads as white (shine-scene validates
        // sizes, so this is defensive).
        None => vec![255; (TEXTURE_SIZE * TEXTURE_SIZE * 4) as usize],
    }
}

fn texture_array(
    device: &Device,
    name: &str,
    format: vk::Format,
    layers: &[Vec<u8>],
) -> Result<Image, shine_gpu::Error> {
    // A scene without textures still binds a (white) layer: the shaders read it only through
    // a texture index, which is NO_TEXTURE then.
    let layer_bytes = (TEXTURE_SIZE * TEXTURE_SIZE * 4) as usize;
    let data = if layers.is_empty() {
        vec![255u8; layer_bytes]
    } else {
        layers.concat()
    };
    let layer_count = (data.len() / layer_bytes) as u32;
    let image = Image::new(
        device,
        &ImageDesc {
            name,
            extent: [TEXTURE_SIZE, TEXTURE_SIZE],
            format,
            usage: vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::TRANSFER_DST
                | vk::ImageUsageFlags::TRANSFER_SRC,
            mip_levels: TEXTURE_MIP_LEVELS,
            array_layers: layer_count,
            // The shaders declare `texture2DArray`, also for a single layer.
            array_view: true,
        },
    )?;
    device.upload_image(&image, &data, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)?;
    Ok(image)
}
