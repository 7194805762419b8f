//! The composite pass on a real device (lavapipe in CI) against its CPU reference
//! (`shine::passes::composite::composite_texel`, built on `shine::capture::tonemap`), for every tonemap
//! operator, with and without indirect light. This also ties `shaders/include/tonemap.glsl` to
//! `src/capture/tonemap.rs`.
//!
//! Input: a 32×32 RGBA16F ramp from 0 through mid greys to 65504, including values at and
//! around the PBR Neutral knee (0.8 = K_s + F90) and its black offset (2·F90 = 0.08).
//! Tolerances: HDR within one f32 ulp (relative 2⁻²³), LDR within one 8-bit level.
//! Zero validation messages. Never skips (docs/architecture.md, "Tests").

mod common;

use common::{assert_clean, buffer_with as buffer, device};
use shine::capture::tonemap::Tonemap;
use shine::gpu::Device;
use shine::graph::vk::{self, AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
use shine::graph::*;
use shine::passes::composite::{
    CompositeParams, HDR_FORMAT, INPUT_FORMAT, LDR_FORMAT, composite, composite_block,
    composite_texel,
};

const W: u32 = 32;
const H: u32 = 32;
const TEXELS: usize = (W * H) as usize;

/// Half-float bits of `v` (truncating the mantissa; normal range and zero only).
fn half_bits(v: f32) -> u16 {
    if v == 0.0 {
        return 0;
    }
    let bits = v.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    assert!(
        (1..31).contains(&exponent),
        "{v} is outside the half normal range"
    );
    (((bits >> 16) & 0x8000) | ((exponent as u32) << 10) | ((bits >> 13) & 0x3ff)) as u16
}

/// The f32 value of half-float bits (normal range and zero).
fn half_value(bits: u16) -> f32 {
    if bits & 0x7fff == 0 {
        return 0.0;
    }
    let sign = u32::from(bits & 0x8000) << 16;
    let exponent = u32::from((bits >> 10) & 0x1f) + 127 - 15;
    let mantissa = u32::from(bits & 0x3ff) << 13;
    f32::from_bits(sign | (exponent << 23) | mantissa)
}

/// Grey values that must be hit exactly: zero, the black offset, mid grey, the knee, bright.
const SPECIAL: [f32; 20] = [
    0.0, 0.002, 0.04, 0.079, 0.08, 0.081, 0.18, 0.5, 0.75, 0.76, 0.77, 0.799, 0.8, 0.801, 0.84,
    1.0, 2.0, 16.0, 1000.0, 65504.0,
];

/// A log ramp of half floats from 2⁻¹⁰ to 65504 over the texel index.
fn ramp(i: usize) -> u16 {
    let (low, high) = (0x1400u32, 0x7bffu32);
    (low + (high - low) * i as u32 / (TEXELS as u32 - 1)) as u16
}

/// The `direct` input as half-float bits: special greys first, then coloured ramp texels.
fn direct_bits() -> Vec<[u16; 4]> {
    (0..TEXELS)
        .map(|i| match SPECIAL.get(i) {
            Some(&v) => {
                let h = half_bits(v);
                [h, h, h, 0x3c00]
            }
            None => [
                ramp(i),
                ramp(i).saturating_sub(0x0400),
                ramp(i * 37 % TEXELS),
                0x3c00,
            ],
        })
        .collect()
}

/// The `indirect_full` input: zero on the special greys (so they reach the tonemap
/// unchanged), small coloured values elsewhere.
fn indirect_bits() -> Vec<[u16; 4]> {
    (0..TEXELS)
        .map(|i| {
            if i < SPECIAL.len() {
                [0; 4]
            } else {
                let x = (i % 32) as f32;
                [half_bits(0.01 * x), half_bits(0.02 * x), half_bits(0.5), 0]
            }
        })
        .collect()
}

fn values(bits: &[[u16; 4]]) -> Vec<[f32; 4]> {
    bits.iter().map(|t| t.map(half_value)).collect()
}

/// Runs the composite on the device and returns the HDR and LDR frames read back.
fn run_composite(
    device: &Device,
    direct: &[[u16; 4]],
    indirect: Option<&[[u16; 4]]>,
    params: &CompositeParams,
) -> (Vec<[f32; 4]>, Vec<[u8; 4]>) {
    let uploaded = ExternalState::new(S::COPY, A::TRANSFER_WRITE, L::UNDEFINED);
    let read_by_copy = ExternalState::new(S::COPY, A::TRANSFER_READ, L::UNDEFINED);
    let src_usage = vk::BufferUsageFlags::TRANSFER_SRC;
    let dst_usage = vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC;
    let direct_src = buffer(
        device,
        "direct_src",
        src_usage,
        bytemuck::cast_slice(direct),
    );
    let indirect_src = indirect.map(|bits| {
        buffer(
            device,
            "indirect_src",
            src_usage,
            bytemuck::cast_slice(bits),
        )
    });
    let hdr_dst = buffer(device, "hdr_dst", dst_usage, &vec![0; TEXELS * 16]);
    let ldr_dst = buffer(device, "ldr_dst", dst_usage, &vec![0; TEXELS * 4]);

    let mut executor = Executor::new(device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let n = params.ssaa;
    let input = ImageDesc::new_2d(INPUT_FORMAT, W * n, H * n);
    let src = rg.import_gpu_buffer(&direct_src, uploaded, ExternalState::UNDEFINED);
    let mut direct_image = rg.create_image("direct", input);
    rg.copy_buffer_to_image("upload_direct", &src, &mut direct_image);
    let indirect_image = indirect_src.as_ref().map(|buffer| {
        let src = rg.import_gpu_buffer(buffer, uploaded, ExternalState::UNDEFINED);
        let mut image = rg.create_image("indirect_full", input);
        rg.copy_buffer_to_image("upload_indirect", &src, &mut image);
        image
    });
    let out = composite(
        &mut rg,
        &direct_image,
        indirect_image.as_ref(),
        None,
        [W, H],
        params,
    );
    let mut hdr = rg.import_gpu_buffer(&hdr_dst, ExternalState::UNDEFINED, read_by_copy);
    let mut ldr = rg.import_gpu_buffer(&ldr_dst, ExternalState::UNDEFINED, read_by_copy);
    rg.copy_image_to_buffer("read_hdr", &out.hdr, &mut hdr);
    rg.copy_image_to_buffer("read_ldr", &out.ldr, &mut ldr);
    let mut commands = device.begin_commands().unwrap();
    let plan = executor.execute(commands.raw(), rg).unwrap();
    device.submit(commands).unwrap().wait().unwrap();
    assert!(plan.order().contains(&"composite"));

    let hdr_bytes = device.read_buffer(&hdr_dst).unwrap();
    let ldr_bytes = device.read_buffer(&ldr_dst).unwrap();
    (
        bytemuck::pod_collect_to_vec(&hdr_bytes),
        bytemuck::pod_collect_to_vec(&ldr_bytes),
    )
}

/// Compares the device's frames with the CPU reference texel by texel.
fn check(device: &Device, indirect: bool, params: CompositeParams) {
    let direct = direct_bits();
    let indirect_input = indirect.then(indirect_bits);
    let (hdr, ldr) = run_composite(device, &direct, indirect_input.as_deref(), &params);
    let direct_values = values(&direct);
    let indirect_values = indirect_input.as_deref().map(values);
    let mut worst_ldr = 0;
    for i in 0..TEXELS {
        let (want_hdr, want_ldr) = composite_texel(
            direct_values[i],
            indirect_values.as_ref().map(|v| v[i]),
            &params,
        );
        for c in 0..4 {
            let (got, want) = (hdr[i][c], want_hdr[c]);
            assert!(
                (got - want).abs() <= want.abs() * f32::EPSILON,
                "{params:?} texel {i} channel {c}: hdr {got} vs {want}"
            );
            let diff = ldr[i][c].abs_diff(want_ldr[c]);
            assert!(
                diff <= 1,
                "{params:?} texel {i} ({:?}) channel {c}: ldr {} vs {}",
                want_hdr,
                ldr[i][c],
                want_ldr[c]
            );
            worst_ldr = worst_ldr.max(diff);
        }
    }
    // The ramp really spans black to white.
    assert_eq!(ldr[0], [0, 0, 0, 255]);
    assert!(ldr[SPECIAL.len() - 1][..3].iter().all(|&c| c >= 254));
    println!("{params:?}, indirect {indirect}: worst LDR difference {worst_ldr} level(s)");
}

#[test]
fn every_operator_matches_the_cpu_with_indirect_light() {
    let device = device();
    for &tonemap in Tonemap::ALL {
        check(
            &device,
            true,
            CompositeParams {
                exposure: 1.0,
                tonemap,
                ssaa: 1,
                auto_exposure: None,
            },
        );
    }
    assert_clean(&device);
}

#[test]
fn direct_only_with_exposure_matches_the_cpu() {
    let device = device();
    for &tonemap in Tonemap::ALL {
        check(
            &device,
            false,
            CompositeParams {
                exposure: 0.37,
                tonemap,
                ssaa: 1,
                auto_exposure: None,
            },
        );
    }
    assert_clean(&device);
}

/// Supersampled 2×: 64×64 inputs (the ramp's texels shuffled, direct and indirect) into the
/// 32×32 frame, each pixel the box average of its 2×2 inputs before exposure and tonemap,
/// against `composite_block` (HDR within one f32 ulp of each sum, LDR within one level).
#[test]
fn supersampled_composite_matches_the_cpu() {
    let device = device();
    let params = CompositeParams {
        exposure: 0.5,
        tonemap: Tonemap::PbrNeutral,
        ssaa: 2,
        auto_exposure: None,
    };
    let (direct, indirect) = (direct_bits(), indirect_bits());
    let shuffle = |bits: &[[u16; 4]], k: usize| bits[(k * 13) % TEXELS];
    let direct: Vec<[u16; 4]> = (0..4 * TEXELS).map(|k| shuffle(&direct, k)).collect();
    let indirect: Vec<[u16; 4]> = (0..4 * TEXELS).map(|k| shuffle(&indirect, k + 5)).collect();
    let (hdr, ldr) = run_composite(&device, &direct, Some(&indirect), &params);
    let (dv, iv) = (values(&direct), values(&indirect));
    let wide = 2 * W as usize;
    for y in 0..H as usize {
        for x in 0..W as usize {
            let taps: Vec<usize> = [(0, 0), (1, 0), (0, 1), (1, 1)]
                .iter()
                .map(|(i, j)| (2 * y + j) * wide + 2 * x + i)
                .collect();
            let d: Vec<[f32; 4]> = taps.iter().map(|&t| dv[t]).collect();
            let i: Vec<[f32; 4]> = taps.iter().map(|&t| iv[t]).collect();
            let (want_hdr, want_ldr) = composite_block(&d, Some(&i), &params);
            let k = y * W as usize + x;
            for c in 0..3 {
                assert!(
                    (hdr[k][c] - want_hdr[c]).abs() <= want_hdr[c].abs() * 4.0 * f32::EPSILON,
                    "pixel {k} channel {c}: hdr {} vs {}",
                    hdr[k][c],
                    want_hdr[c]
                );
                assert!(
                    ldr[k][c].abs_diff(want_ldr[c]) <= 1,
                    "pixel {k} channel {c}"
                );
            }
        }
    }
    assert_clean(&device);
}

#[test]
fn half_float_helpers_round_trip() {
    for v in SPECIAL {
        let back = half_value(half_bits(v));
        assert!((back - v).abs() <= v * 1e-3, "{v} → {back}");
    }
    assert_eq!(half_value(0x3c00), 1.0);
    assert_eq!(half_value(0x7bff), 65504.0);
    assert_eq!(HDR_FORMAT, vk::Format::R32G32B32A32_SFLOAT);
    assert_eq!(LDR_FORMAT, vk::Format::R8G8B8A8_UNORM);
}
