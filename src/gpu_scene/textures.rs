//! The scene's texture arrays: every used texture resized to one square size per array so
//! that they index a `texture2DArray` (lavapipe indexes arrays of textures only by
//! constants); colour textures live in an sRGB array, data textures (normal,
//! metallic-roughness) in a linear one, each with its full mip chain.

use shine_gpu::{Device, Image, ImageDesc, vk};
use shine_scene::{NO_TEXTURE, Scene};

use super::{GpuMaterial, TEXTURE_MIP_LEVELS, TEXTURE_SIZE};

/// Remaps texture indices to layers of the sRGB and linear arrays, and resizes every used
/// texture to [`TEXTURE_SIZE`]².
pub(super) fn remap_textures(scene: &Scene) -> (Vec<GpuMaterial>, Vec<Vec<u8>>, Vec<Vec<u8>>) {
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

pub(super) fn texture_array(
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
