//! The environment light on the GPU: an equirectangular RGBA32F texture baked from
//! [`Environment::radiance`] (the contract every environment kind implements), sampled by
//! `environment_radiance(dir)` in `shaders/include/environment.glsl`. No environment → black.
//!
//! Mapping (shared with the shader): for a unit direction `d` (+Y up),
//! `u = atan2(d.x, -d.z) / 2π + 1/2`, `v = acos(d.y) / π`; texel `(i, j)` holds the radiance
//! at its centre `((i + ½) / W, (j + ½) / H)`. Bilinear filtering, `u` wraps, `v` clamps.

use glam::Vec3;
use shine_gpu::{Device, Image, ImageDesc, vk};
use shine_scene::environment::Environment;

/// Width of the baked environment texture (height is half of it).
pub const ENVIRONMENT_WIDTH: u32 = 256;
/// Height of the baked environment texture.
pub const ENVIRONMENT_HEIGHT: u32 = 128;

/// The direction at texture coordinates `(u, v)` (the inverse of the module's mapping).
pub fn direction(u: f32, v: f32) -> Vec3 {
    let phi = (u - 0.5) * std::f32::consts::TAU;
    let theta = v * std::f32::consts::PI;
    Vec3::new(
        theta.sin() * phi.sin(),
        theta.cos(),
        -theta.sin() * phi.cos(),
    )
}

/// Texture coordinates of a unit direction (the module's mapping, `environment_radiance` in
/// environment.glsl; the inverse of [`direction`]).
pub fn texcoord(d: Vec3) -> glam::Vec2 {
    let u = if d.x.abs() + d.z.abs() > 0.0 {
        d.x.atan2(-d.z) / std::f32::consts::TAU + 0.5
    } else {
        0.5
    };
    glam::Vec2::new(u, d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI)
}

/// Bakes `environment` (or black) into RGBA32F texels, rows from +Y (v = 0) down.
pub fn bake(environment: Option<&Environment>) -> Vec<[f32; 4]> {
    let (w, h) = (ENVIRONMENT_WIDTH, ENVIRONMENT_HEIGHT);
    (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| {
            let d = direction((i as f32 + 0.5) / w as f32, (j as f32 + 0.5) / h as f32);
            environment.map_or([0.0; 4], |e| e.radiance(d).extend(1.0).to_array())
        })
        .collect()
}

/// Uploads the baked environment as a sampled image (left in `SHADER_READ_ONLY_OPTIMAL`).
pub fn upload(
    device: &Device,
    environment: Option<&Environment>,
) -> Result<Image, shine_gpu::Error> {
    upload_baked(device, &bake(environment))
}

/// Uploads texels [`bake`] made (for a caller that reads them too, like the path tracer's
/// light tables).
pub fn upload_baked(device: &Device, texels: &[[f32; 4]]) -> Result<Image, shine_gpu::Error> {
    let image = Image::new(
        device,
        &ImageDesc::new_2d(
            "environment",
            [ENVIRONMENT_WIDTH, ENVIRONMENT_HEIGHT],
            vk::Format::R32G32B32A32_SFLOAT,
            vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
        ),
    )?;
    device.upload_image(
        &image,
        bytemuck::cast_slice(texels),
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    )?;
    Ok(image)
}
