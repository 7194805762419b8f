//! `receivers`: the G-buffer at 1/s resolution, the "receiver buffer" where the expensive GI
//! runs (paper 002 §4.2; docs/frame.md "Receiver buffer").
//!
//! Each receiver pixel copies ONE full-resolution G-buffer sample of its s×s block, so its
//! position, normal, albedo and material stay consistent: the valid sample (`w > 0`) with the
//! smallest linear depth (foreground-biased), the first in row-major order on ties, or the
//! block's first sample when the whole block is background. A size not divisible by s gives
//! `ceil(W/s)×ceil(H/s)` receivers whose right and bottom blocks are clipped to the image.

use super::gbuffer::GBuffer;
use crate::graph::{Handle, Image, ImageDesc, RenderGraph, vk};
use crate::shaders;

/// Receiver scales s the passes accept: 1/1, 1/2 and 1/4 of the resolution (paper 002 §4.2).
pub const SCALES: [u32; 3] = [1, 2, 4];

/// [`SCALES`] in words: `1, 2 or 4`.
pub fn scale_list() -> String {
    match SCALES.split_last() {
        Some((last, rest)) if !rest.is_empty() => {
            let rest: Vec<String> = rest.iter().map(u32::to_string).collect();
            format!("{} or {last}", rest.join(", "))
        }
        _ => SCALES.map(|s| s.to_string()).join(", "),
    }
}

/// Bad input to the `receivers` or `upsample` pass.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReceiverError {
    /// The scale is not one of [`SCALES`].
    #[error("receiver scale {0} is not supported: use {scales}", scales = scale_list())]
    Scale(u32),
    /// An extent has a zero side.
    #[error("image extent {0:?} is empty: both sides must be at least 1")]
    EmptyExtent([u32; 2]),
    /// Two images that must match in size do not.
    #[error("`{name}` is {found:?}, expected {expected:?}")]
    Extent {
        /// The offending image or slice.
        name: &'static str,
        /// Its extent (for a slice: its length as `[len, 1]`).
        found: [u32; 2],
        /// The extent it must have.
        expected: [u32; 2],
    },
    /// An image has the wrong format.
    #[error("`{name}` is {found:?}, expected R16G16B16A16_SFLOAT")]
    Format {
        /// The offending image.
        name: &'static str,
        /// Its format.
        found: vk::Format,
    },
    /// A tuning parameter is out of its range.
    #[error("upsample parameter {0}")]
    Parameter(&'static str),
}

/// The receiver buffer: the G-buffer's four images at `extent` = ceil(W/s)×ceil(H/s).
#[derive(Debug, Clone, Copy)]
pub struct Receivers {
    /// `recv_position`, RGBA32F (as `gb_position`).
    pub position: Handle<Image>,
    /// `recv_normal`, RGBA16F (as `gb_normal`).
    pub normal: Handle<Image>,
    /// `recv_albedo`, RGBA8_UNORM (as `gb_albedo`).
    pub albedo: Handle<Image>,
    /// `recv_material`, RGBA8_UNORM (as `gb_material`).
    pub material: Handle<Image>,
    /// Width and height of the receiver images.
    pub extent: [u32; 2],
    /// The block size s: each receiver stands for s×s full-resolution pixels.
    pub scale: u32,
}

impl Receivers {
    /// A new transient RGBA16F image `name` at receiver resolution: the format every
    /// receiver-resolution light (HVL, the sky, the proxies, the cubes) is written in.
    pub fn light_image(&self, rg: &mut RenderGraph, name: &str) -> Handle<Image> {
        let [w, h] = self.extent;
        rg.create_image(
            name,
            ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
        )
    }
}

/// Whether a receiver's position texel (xyz world, w view depth) is on a surface: view depth
/// above 0 (background holds 0; NaN is not), as the receivers' passes test it.
pub fn on_surface(position: [f32; 4]) -> bool {
    position[3] > 0.0
}

/// Push constants of `shaders/receivers.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ReceiversPush {
    /// Full-resolution extent.
    pub extent: [u32; 2],
    /// Receiver extent.
    pub recv_extent: [u32; 2],
    /// Block size s.
    pub scale: u32,
}

/// The receiver extent ceil(W/s)×ceil(H/s) of a full-resolution `extent`, after checking
/// that s is one of [`SCALES`] and the extent is not empty.
pub fn receiver_extent(extent: [u32; 2], scale: u32) -> Result<[u32; 2], ReceiverError> {
    if !SCALES.contains(&scale) {
        return Err(ReceiverError::Scale(scale));
    }
    if extent[0] == 0 || extent[1] == 0 {
        return Err(ReceiverError::EmptyExtent(extent));
    }
    Ok([extent[0].div_ceil(scale), extent[1].div_ceil(scale)])
}

/// Adds the `receivers` pass: downsamples `gbuffer` by `scale` into four new transient images.
pub fn receivers(
    rg: &mut RenderGraph,
    gbuffer: &GBuffer,
    scale: u32,
) -> Result<Receivers, ReceiverError> {
    let recv_extent = receiver_extent(gbuffer.extent, scale)?;
    let [w, h] = recv_extent;
    let mut out = Receivers {
        position: rg.create_image(
            "recv_position",
            ImageDesc::new_2d(vk::Format::R32G32B32A32_SFLOAT, w, h),
        ),
        normal: rg.create_image(
            "recv_normal",
            ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
        ),
        albedo: rg.create_image(
            "recv_albedo",
            ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, w, h),
        ),
        material: rg.create_image(
            "recv_material",
            ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, w, h),
        ),
        extent: recv_extent,
        scale,
    };
    let push = ReceiversPush {
        extent: gbuffer.extent,
        recv_extent,
        scale,
    };
    rg.compute("receivers", &shaders::RECEIVERS_COMP)
        .read("gb_position", &gbuffer.position)
        .read("gb_normal", &gbuffer.normal)
        .read("gb_albedo", &gbuffer.albedo)
        .read("gb_material", &gbuffer.material)
        .write("recv_position", &mut out.position)
        .write("recv_normal", &mut out.normal)
        .write("recv_albedo", &mut out.albedo)
        .write("recv_material", &mut out.material)
        .push(&push)
        .dispatch([w, h, 1]);
    Ok(out)
}

/// CPU reference of the sample choice: for each receiver pixel (row-major), the index
/// `y * W + x` of the full-resolution sample it copies. `position` is `gb_position` as
/// RGBA floats (4 per pixel, row-major).
pub fn receiver_samples(
    position: &[f32],
    extent: [u32; 2],
    scale: u32,
) -> Result<Vec<usize>, ReceiverError> {
    let [rw, rh] = receiver_extent(extent, scale)?;
    let [w, h] = extent.map(|v| v as usize);
    if position.len() != w * h * 4 {
        return Err(ReceiverError::Extent {
            name: "gb_position",
            found: [(position.len() / 4) as u32, 1],
            expected: extent,
        });
    }
    let s = scale as usize;
    let mut samples = Vec::with_capacity(rw as usize * rh as usize);
    for ry in 0..rh as usize {
        for rx in 0..rw as usize {
            let first = ry * s * w + rx * s;
            let mut chosen: Option<(usize, f32)> = None;
            for y in ry * s..((ry + 1) * s).min(h) {
                for x in rx * s..((rx + 1) * s).min(w) {
                    let i = y * w + x;
                    let depth = position[i * 4 + 3];
                    if depth > 0.0 && chosen.is_none_or(|(_, d)| depth < d) {
                        chosen = Some((i, depth));
                    }
                }
            }
            samples.push(chosen.map_or(first, |(i, _)| i));
        }
    }
    Ok(samples)
}

/// Copies the texels `samples` picks out of `texels` (`per_texel` values each): the CPU
/// reference of one receiver image from its G-buffer image.
pub fn gather_texels<T: Copy>(texels: &[T], per_texel: usize, samples: &[usize]) -> Vec<T> {
    samples
        .iter()
        .flat_map(|&i| texels[i * per_texel..(i + 1) * per_texel].iter().copied())
        .collect()
}
