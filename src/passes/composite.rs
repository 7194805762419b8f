//! `composite`: direct + indirect radiance × exposure → the HDR frame (RGBA32F, linear) and
//! the LDR frame (RGBA8, tonemapped and sRGB-encoded) — docs/frame.md, "Direct light and
//! composition".
//!
//! The HDR frame is what EXR output writes (never tonemapped, negative values kept as they
//! are); the LDR frame is what PNG output writes. Alpha is 1 in both.

use glam::Vec3;

use crate::capture::tonemap::{self, Tonemap};
use crate::graph::{Buffer, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::exposure::ExposureParams;
use crate::shaders;

/// Format of the `hdr` output: linear radiance, exposure applied.
pub const HDR_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;
/// Format of the `ldr` output: tonemapped, sRGB-encoded values stored as plain UNORM.
pub const LDR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// Format of the `direct` and `indirect_full` inputs.
pub const INPUT_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// What the composite does with the summed radiance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompositeParams {
    /// Linear factor applied to radiance before it is written and tonemapped.
    pub exposure: f32,
    /// Operator of the LDR frame.
    pub tonemap: Tonemap,
    /// Supersampling N: the inputs are N times the output's size, and each output pixel is the
    /// box average of N×N of them ([`SSAA`] range).
    pub ssaa: u32,
    /// Automatic exposure ([`crate::passes::exposure`]): the LDR frame's radiance is also
    /// multiplied by the frame's exposure (`exposure` then a compensation on top); the HDR
    /// frame stays scene-referred (`exposure` only), so EXR captures compare with each other
    /// and with the path tracer whatever the scene's brightness.
    pub auto_exposure: Option<ExposureParams>,
}

/// Supersampling factors: input pixels per output pixel along each axis.
pub const SSAA: std::ops::RangeInclusive<u32> = 1..=4;
/// The largest supersampling [`auto_ssaa`] chooses.
pub const AUTO_SSAA_MAX: u32 = 2;
/// The most pixels [`auto_ssaa`] lets a frame render: 1024² (a 512² capture at 2×2, the
/// Cornell box of `make render` in about 3 s on the CI machine's lavapipe).
pub const AUTO_SSAA_PIXELS: u64 = 1 << 20;

/// Supersampling for a capture of `extent` that fits the time: the largest factor up to
/// [`AUTO_SSAA_MAX`] whose rendered frame has at most [`AUTO_SSAA_PIXELS`] pixels, else 1.
pub fn auto_ssaa(extent: [u32; 2]) -> u32 {
    let pixels = u64::from(extent[0]) * u64::from(extent[1]);
    (1..=AUTO_SSAA_MAX)
        .rev()
        .find(|&n| u64::from(n * n) * pixels <= AUTO_SSAA_PIXELS)
        .unwrap_or(1)
}

impl Default for CompositeParams {
    /// Exposure 1, the default tonemap ([`tonemap::DEFAULT_TONEMAP`], PBR Neutral), no
    /// supersampling.
    fn default() -> Self {
        Self {
            exposure: 1.0,
            tonemap: tonemap::DEFAULT_TONEMAP,
            ssaa: 1,
            auto_exposure: None,
        }
    }
}

crate::choice::named_choice! {
    /// Which part of the radiance the frame shows (image tests compare each against the
    /// path-traced reference, `crate::reference`): what the composite sums.
    pub enum Component ("output component") {
        /// Direct + indirect light.
        Full = "full",
        /// The direct pass only (emission and punctual lights).
        Direct = "direct",
        /// The GI technique's indirect light only (needs a GI technique).
        Indirect = "indirect",
        /// The G-buffer's world shading normal, unlit (for `shine compare --surfaces`).
        Normal = "normal",
        /// The G-buffer's geometric (face) normal, unlit: what `shine compare --surfaces` should
        /// read on normal-mapped surfaces, whose shading normals part one plane into many.
        GeometricNormal = "geometric-normal",
        /// The G-buffer's world position (xyz, at half precision), unlit (for `shine compare
        /// --positions`: parallel planes apart).
        Position = "position",
    }
}

/// The push constants of `composite.comp` (its `Push` block, 32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CompositePush {
    /// Output size in pixels; invocations outside it do nothing.
    pub extent: [u32; 2],
    /// [`CompositeParams::exposure`].
    pub exposure: f32,
    /// [`Tonemap::shader_id`] of the operator.
    pub op: u32,
    /// [`CompositeParams::ssaa`].
    pub ssaa: u32,
    /// 1 / ssaa², the box filter's weight.
    pub inv_samples: f32,
    /// Padding.
    pub pad: [u32; 2],
}

/// The images the composite writes.
#[derive(Debug)]
pub struct CompositeOutputs {
    /// Linear HDR frame, [`HDR_FORMAT`].
    pub hdr: Handle<Image>,
    /// Tonemapped LDR frame, [`LDR_FORMAT`].
    pub ldr: Handle<Image>,
}

/// Adds the composite pass: reads `direct` and, when given, `indirect` (both [`INPUT_FORMAT`],
/// `extent` × [`CompositeParams::ssaa`]), writes new transient `hdr` and `ldr` images of
/// `extent`. With `exposure` (the buffer of [`crate::passes::exposure::exposure`]) the LDR
/// frame's radiance is also multiplied by its first float.
///
/// Without `indirect` the frame is direct light only (`--gi none`).
pub fn composite(
    rg: &mut RenderGraph,
    direct: &Handle<Image>,
    indirect: Option<&Handle<Image>>,
    exposure: Option<&Handle<Buffer>>,
    extent: [u32; 2],
    params: &CompositeParams,
) -> CompositeOutputs {
    let [width, height] = extent;
    let mut hdr = rg.create_image("hdr", ImageDesc::new_2d(HDR_FORMAT, width, height));
    let mut ldr = rg.create_image("ldr", ImageDesc::new_2d(LDR_FORMAT, width, height));
    let ssaa = params.ssaa.max(1);
    let push = CompositePush {
        extent,
        exposure: params.exposure,
        op: params.tonemap.shader_id(),
        ssaa,
        inv_samples: 1.0 / (ssaa * ssaa) as f32,
        pad: [0; 2],
    };
    let shader = match (indirect, exposure) {
        (Some(_), None) => &shaders::COMPOSITE_COMP_WITH_INDIRECT,
        (None, None) => &shaders::COMPOSITE_COMP_DIRECT_ONLY,
        (Some(_), Some(_)) => &shaders::COMPOSITE_COMP_WITH_INDIRECT_AUTO,
        (None, Some(_)) => &shaders::COMPOSITE_COMP_DIRECT_ONLY_AUTO,
    };
    let mut pass = rg.compute("composite", shader);
    pass.read("direct", direct);
    if let Some(indirect) = indirect {
        pass.read("indirect_full", indirect);
    }
    if let Some(exposure) = exposure {
        pass.read("exposure", exposure);
    }
    pass.write("hdr", &mut hdr)
        .write("ldr", &mut ldr)
        .push(&push)
        .dispatch([width, height, 1]);
    CompositeOutputs { hdr, ldr }
}

/// The CPU reference of one composite texel: the HDR value and the LDR texel.
///
/// `direct` and `indirect` are the values the GPU reads (already rounded to half floats).
pub fn composite_texel(
    direct: [f32; 4],
    indirect: Option<[f32; 4]>,
    params: &CompositeParams,
) -> ([f32; 4], [u8; 4]) {
    composite_block(
        &[direct],
        indirect.as_ref().map(std::slice::from_ref),
        params,
    )
}

/// The CPU reference of one supersampled composite texel: its `ssaa`² input texels (row by row,
/// as the shader visits them) summed, weighted by 1/ssaa², exposed and tonemapped.
pub fn composite_block(
    direct: &[[f32; 4]],
    indirect: Option<&[[f32; 4]]>,
    params: &CompositeParams,
) -> ([f32; 4], [u8; 4]) {
    let mut radiance = Vec3::ZERO;
    for (k, d) in direct.iter().enumerate() {
        let mut sample = Vec3::from_slice(&d[..3]);
        if let Some(indirect) = indirect {
            sample += Vec3::from_slice(&indirect[k][..3]);
        }
        radiance += sample;
    }
    let ssaa = params.ssaa.max(1);
    let exposed = radiance * (1.0 / (ssaa * ssaa) as f32) * params.exposure;
    (
        exposed.extend(1.0).to_array(),
        tonemap::encode_ldr(params.tonemap, exposed),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn push_constants_match_the_shader() {
        for shader in [
            &shaders::COMPOSITE_COMP_WITH_INDIRECT,
            &shaders::COMPOSITE_COMP_DIRECT_ONLY,
        ] {
            assert_eq!(
                shader.push_constant_size as usize,
                std::mem::size_of::<CompositePush>(),
                "{}",
                shader.name
            );
        }
        assert!(
            shaders::COMPOSITE_COMP_WITH_INDIRECT
                .binding("indirect_full")
                .is_some()
        );
        assert!(
            shaders::COMPOSITE_COMP_DIRECT_ONLY
                .binding("indirect_full")
                .is_none()
        );
    }

    #[test]
    fn auto_ssaa_fits_the_pixel_budget() {
        assert_eq!(auto_ssaa([512, 512]), 2);
        assert_eq!(auto_ssaa([128, 128]), 2);
        assert_eq!(auto_ssaa([513, 512]), 1);
        assert_eq!(auto_ssaa([1280, 720]), 1);
        assert_eq!(auto_ssaa([0, 0]), AUTO_SSAA_MAX);
    }

    #[test]
    fn reference_adds_then_exposes() {
        let params = CompositeParams {
            exposure: 0.5,
            tonemap: Tonemap::None,
            ssaa: 1,
            auto_exposure: None,
        };
        let (hdr, ldr) =
            composite_texel([1.0, 0.25, 0.0, 0.0], Some([1.0, 0.0, 0.5, 0.0]), &params);
        assert_eq!(hdr, [1.0, 0.125, 0.25, 1.0]);
        assert_eq!(ldr[0], 255);
        let (direct_only, _) = composite_texel([1.0, 0.25, 0.0, 0.0], None, &params);
        assert_eq!(direct_only, [0.5, 0.125, 0.0, 1.0]);
    }
}
