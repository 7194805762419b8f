//! Images holding copies of the scene buffers the path tracer reads at every vertex: its
//! materials, vertices, indices, lights and light tables (`path_trace.comp` defines
//! `SURFACE_MATERIAL_TEXELS` and `PATH_SCENE_TEXELS`). llvmpipe loads a storage buffer lane by
//! lane, one small loop per load, and those loops held 28% of the path tracer's time; an image
//! texel is one gather (docs/pitfalls.md). The copies are made on the device by the first
//! dispatch after the scene is uploaded or moved, so deforming meshes and moving lights stay
//! right; each image's texels follow its buffer's bytes in rows of
//! [`crate::gpu_scene::bvh::TRACE_ROW_TEXELS`].

use shine_gpu::{Buffer, Device, Image, vk};
use shine_graph::{ExternalState, Handle, RenderGraph};

use crate::frame::RenderError;
use crate::gpu_scene::bvh::rows_image;
use crate::gpu_scene::{GpuScene, STORAGE_READ, SceneHandles};
use crate::passes::path_trace::SceneTexels;

/// The five images, sized for their buffers.
pub struct SceneTexelImages {
    materials: Image,
    vertices: Image,
    indices: Image,
    lights: Image,
    light_tables: Image,
}

/// An image of `format` (texels of `texel` bytes) with room for `buffer`'s bytes.
fn mirror(
    device: &Device,
    name: &str,
    buffer: &Buffer,
    format: vk::Format,
    texel: u64,
) -> Result<Image, RenderError> {
    let texels = usize::try_from(buffer.size().div_ceil(texel))
        .map_err(|_| RenderError::Invalid(format!("{name}: too large")))?;
    Ok(rows_image(device, name, texels, format)?)
}

impl SceneTexelImages {
    /// Images for `scene`'s buffers and the path tracer's `light_tables`.
    pub fn new(
        device: &Device,
        scene: &GpuScene,
        light_tables: &Buffer,
    ) -> Result<Self, RenderError> {
        let rgba = vk::Format::R32G32B32A32_SFLOAT;
        let word = vk::Format::R32_UINT;
        Ok(Self {
            materials: mirror(device, "material texels", &scene.materials, rgba, 16)?,
            vertices: mirror(device, "vertex texels", &scene.vertices, rgba, 16)?,
            indices: mirror(device, "index texels", &scene.indices, word, 4)?,
            lights: mirror(device, "light texels", &scene.lights, rgba, 16)?,
            light_tables: mirror(device, "light table texels", light_tables, word, 4)?,
        })
    }

    /// The images for the path tracer to read, imported into `rg`. With `copy` (the scene was
    /// uploaded or moved since the last copy) the five copies are recorded first, after the
    /// frame's scene updates, which `scene`'s handles carry.
    pub fn declare(
        &self,
        rg: &mut RenderGraph,
        scene: &SceneHandles,
        light_tables: &Handle<shine_graph::Buffer>,
        copy: bool,
    ) -> SceneTexels {
        let mut image = |name: &str, image: &Image, src: &Handle<shine_graph::Buffer>| {
            if !copy {
                return rg.import_gpu_image(image, STORAGE_READ, STORAGE_READ);
            }
            let mut handle = rg.import_gpu_image(image, ExternalState::UNDEFINED, STORAGE_READ);
            rg.copy_buffer_to_image(name, src, &mut handle);
            handle
        };
        SceneTexels {
            materials: image("copy material texels", &self.materials, &scene.materials),
            vertices: image("copy vertex texels", &self.vertices, &scene.vertices),
            indices: image("copy index texels", &self.indices, &scene.indices),
            lights: image("copy light texels", &self.lights, &scene.lights),
            light_tables: image("copy light table texels", &self.light_tables, light_tables),
        }
    }
}
