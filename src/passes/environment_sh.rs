//! `environment sh rows`, `environment sh`: an equirectangular environment image on the
//! device projected to SH (`L` and `L̃`, the layout of [`EnvironmentSh::gpu_data`]), the GPU
//! twin of [`EnvironmentSh::project`]: a GI context's host environment map
//! (`GiDispatch::environment`) lights the proxy technique through it.
//!
//! [`EnvironmentSh::project`]: crate::gpu_scene::environment_sh::EnvironmentSh::project
//! [`EnvironmentSh::gpu_data`]: crate::gpu_scene::environment_sh::EnvironmentSh::gpu_data

use crate::gpu_scene::environment_sh::ORDERS;
use crate::graph::{Buffer, BufferDesc, Handle, Image, RenderGraph, vk};
use crate::shaders;
use shine_sh::kernels::{clamped_cosine_zh, convolve};

/// Push constants of the `rows` variants (16 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct RowsPush {
    /// Map width and height.
    pub extent: [u32; 2],
    /// Multiplier on the map's radiance.
    pub intensity: f32,
    /// Unused (16-byte size).
    pub pad: f32,
}

/// Push constants of the `total` variants (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TotalPush {
    /// Per band l, the clamped-cosine convolution factor √(4π/(2l+1)) · ĉ_l (8 slots).
    pub kernel: [f32; 8],
    /// Rows of the map.
    pub rows: u32,
    /// Unused (16-byte multiple).
    pub pad: [u32; 3],
}

/// Why an environment image cannot be projected.
#[derive(Debug, thiserror::Error)]
pub enum EnvironmentShError {
    /// The band count is outside [`ORDERS`].
    #[error("environment SH: {0} bands (supported: {ORDERS:?})")]
    Bands(u32),
    /// The image has no texel.
    #[error("environment SH: the map is empty")]
    Empty,
    /// shine-sh refused the kernel.
    #[error("environment SH: {0}")]
    Sh(#[from] shine_sh::ShError),
}

/// The clamped-cosine convolution factor of each band (`convolve` of an all-ones vector reads
/// them off).
fn kernel(bands: u32) -> Result<[f32; 8], EnvironmentShError> {
    let n = (bands * bands) as usize;
    let convolved = convolve(&vec![1.0; n], &clamped_cosine_zh(bands as usize)?)?;
    let mut k = [0.0; 8];
    for (l, slot) in k.iter_mut().enumerate().take(bands as usize) {
        *slot = convolved[l * l + l];
    }
    Ok(k)
}

/// Projects `map` (`extent` texels, sampled through `sampler`, a nearest one) times
/// `intensity` to `bands` bands; returns the SH buffer (`6 · bands²` floats).
pub fn environment_sh(
    rg: &mut RenderGraph,
    map: &Handle<Image>,
    extent: [u32; 2],
    intensity: f32,
    bands: u32,
    sampler: vk::Sampler,
) -> Result<Handle<Buffer>, EnvironmentShError> {
    if !ORDERS.contains(&bands) {
        return Err(EnvironmentShError::Bands(bands));
    }
    if extent[0] == 0 || extent[1] == 0 {
        return Err(EnvironmentShError::Empty);
    }
    let values = 3 * u64::from(bands * bands);
    let mut rows = rg.create_buffer(
        "environment sh rows",
        BufferDesc::new(values * u64::from(extent[1]) * 4),
    );
    let mut sh = rg.create_buffer("environment sh", BufferDesc::new(2 * values * 4));
    let variant = |kind: &str| {
        shaders::get(&format!("environment_sh.comp:{kind}_b{bands}"))
            .ok_or(EnvironmentShError::Bands(bands))
    };
    rg.compute("environment sh rows", variant("rows")?)
        .read("environment", map)
        .sampler("environment_sampler", sampler)
        .write("rows", &mut rows)
        .push(&RowsPush {
            extent,
            intensity,
            pad: 0.0,
        })
        // One workgroup (64 threads) per row.
        .dispatch([extent[1] * 64, 1, 1]);
    rg.compute("environment sh", variant("total")?)
        .read("rows", &rows)
        .write("sh", &mut sh)
        .push(&TotalPush {
            kernel: kernel(bands)?,
            rows: extent[1],
            pad: [0; 3],
        })
        .dispatch([64, 1, 1]);
    Ok(sh)
}
