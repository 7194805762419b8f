//! `receivers` and `upsample` on the Vulkan device (lavapipe in CI) against their CPU
//! references, with the validation layer reporting zero messages.
//!
//! - receivers: GPU == CPU byte for byte, s = 1, 2, 4, on a size not divisible by 4.
//! - upsample: GPU within f16 rounding of the CPU on two planes at depths 2 and 4 with a
//!   background band; the bilateral result stays on its side of the depth edge where a plain
//!   bilinear upsample bleeds; s = 1 is an exact copy; all background gives 0; the fallback
//!   picks the best-matching receiver when every weight (nearly) vanishes.

mod common;

use common::{
    assert_clean, device, f16_to_f32 as f16_value, f32_to_f16 as f16_bits, storage_image_with,
};
use shine::gpu::{Device, MemoryLocation};
use shine::graph::vk::{self, AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
use shine::graph::{Executor, ExternalState, Handle, Image, RenderGraph};
use shine::passes::gbuffer::GBuffer;
use shine::passes::receivers::{
    Receivers, ReceiversPush, gather_texels, receiver_extent, receiver_samples, receivers,
};
use shine::passes::upsample::{
    Coarse, CoarseGrid, UpsampleInputs, UpsampleParams, UpsamplePush, upsample, upsample_cpu,
    upsample_grid,
};
use shine::shaders;

/// Rounds through f16 (what an RGBA16F image holds).
fn f16_round(v: &[f32]) -> Vec<f32> {
    v.iter().map(|&x| f16_value(f16_bits(x))).collect()
}

fn f16_bytes(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|&x| f16_bits(x).to_le_bytes()).collect()
}

fn f16_floats(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(2)
        .map(|c| f16_value(u16::from_le_bytes([c[0], c[1]])))
        .collect()
}

/// A full-resolution (or receiver) G-buffer on the CPU: RGBA floats / bytes per pixel.
struct CpuGBuffer {
    extent: [u32; 2],
    position: Vec<f32>,
    normal: Vec<f32>,
    albedo: Vec<u8>,
    material: Vec<u8>,
}

impl CpuGBuffer {
    /// Fills every pixel from `f(x, y) -> (position, normal)`; albedo and material from x, y.
    fn new(extent: [u32; 2], f: impl Fn(u32, u32) -> ([f32; 4], [f32; 3])) -> Self {
        let mut g = Self {
            extent,
            position: Vec::new(),
            normal: Vec::new(),
            albedo: Vec::new(),
            material: Vec::new(),
        };
        for y in 0..extent[1] {
            for x in 0..extent[0] {
                let (p, n) = f(x, y);
                g.position.extend(p);
                g.normal.extend(f16_round(&[n[0], n[1], n[2], 0.0]));
                g.albedo
                    .extend([(x * 7) as u8, (y * 5) as u8, (x ^ y) as u8, 255]);
                g.material.extend([(x * 3 + y) as u8, (y * 9) as u8, 0, 0]);
            }
        }
        g
    }
}

/// The state `Device::upload_image` leaves an image in (GENERAL, the copy finished).
fn uploaded_state() -> ExternalState {
    ExternalState::new(S::ALL_COMMANDS, A::MEMORY_WRITE, L::GENERAL)
}

/// The four G-buffer images on the device.
struct GpuGBuffer {
    extent: [u32; 2],
    images: [shine::gpu::Image; 4],
}

impl GpuGBuffer {
    fn new(device: &Device, g: &CpuGBuffer) -> Self {
        let e = g.extent;
        Self {
            extent: e,
            images: [
                storage_image_with(
                    device,
                    "gb_position",
                    vk::Format::R32G32B32A32_SFLOAT,
                    e,
                    bytemuck::cast_slice(&g.position),
                ),
                storage_image_with(
                    device,
                    "gb_normal",
                    vk::Format::R16G16B16A16_SFLOAT,
                    e,
                    &f16_bytes(&g.normal),
                ),
                storage_image_with(
                    device,
                    "gb_albedo",
                    vk::Format::R8G8B8A8_UNORM,
                    e,
                    &g.albedo,
                ),
                storage_image_with(
                    device,
                    "gb_material",
                    vk::Format::R8G8B8A8_UNORM,
                    e,
                    &g.material,
                ),
            ],
        }
    }

    fn import(&self, rg: &mut RenderGraph) -> GBuffer {
        let [position, normal, albedo, material] = self
            .images
            .each_ref()
            .map(|i| rg.import_gpu_image(i, uploaded_state(), ExternalState::UNDEFINED));
        // Emission and hardware depth are not read by these passes: placeholders.
        let [w, h] = self.extent;
        let unused = |rg: &mut RenderGraph, name, format| {
            rg.create_image(name, shine::graph::ImageDesc::new_2d(format, w, h))
        };
        GBuffer {
            position,
            normal,
            albedo,
            material,
            emissive: unused(rg, "unused emissive", vk::Format::R16G16B16A16_SFLOAT),
            geometric_normal: unused(
                rg,
                "unused geometric normal",
                vk::Format::R16G16B16A16_SFLOAT,
            ),
            motion: unused(rg, "unused motion", shine::passes::gbuffer::MOTION_FORMAT),
            depth: unused(rg, "unused depth", vk::Format::D32_SFLOAT),
            extent: self.extent,
        }
    }
}

/// Readback buffers of graph images (copied at the end of the graph).
struct Readback {
    buffers: Vec<shine::gpu::Buffer>,
}

impl Readback {
    fn new() -> Self {
        Self {
            buffers: Vec::new(),
        }
    }

    /// Copies `image` (`bytes` long) into a new readback buffer; returns its index.
    fn copy(
        &mut self,
        device: &Device,
        rg: &mut RenderGraph,
        image: &Handle<Image>,
        bytes: u64,
    ) -> usize {
        let desc = shine::gpu::BufferDesc {
            name: "readback",
            size: bytes,
            usage: vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuOnly,
        };
        let buffer = shine::gpu::Buffer::new(device, &desc).unwrap();
        let state = ExternalState::new(S::COPY, A::TRANSFER_READ, L::UNDEFINED);
        let mut out = rg.import_gpu_buffer(&buffer, ExternalState::UNDEFINED, state);
        let name = format!("readback{}", self.buffers.len());
        rg.copy_image_to_buffer(&name, image, &mut out);
        self.buffers.push(buffer);
        self.buffers.len() - 1
    }

    fn bytes(&self, device: &Device, index: usize) -> Vec<u8> {
        device.read_buffer(&self.buffers[index]).unwrap()
    }
}

fn run(device: &Device, executor: &mut Executor, rg: RenderGraph) {
    let mut commands = device.begin_commands().unwrap();
    executor.execute(commands.raw(), rg).unwrap();
    device.submit(commands).unwrap().wait().unwrap();
}

/// What the receivers pass should produce, from the CPU reference.
fn cpu_receivers(g: &CpuGBuffer, scale: u32) -> CpuGBuffer {
    let samples = receiver_samples(&g.position, g.extent, scale).unwrap();
    CpuGBuffer {
        extent: receiver_extent(g.extent, scale).unwrap(),
        position: gather_texels(&g.position, 4, &samples),
        normal: gather_texels(&g.normal, 4, &samples),
        albedo: gather_texels(&g.albedo, 4, &samples),
        material: gather_texels(&g.material, 4, &samples),
    }
}

#[test]
fn push_constants_match_the_reflected_sizes() {
    assert_eq!(
        std::mem::size_of::<ReceiversPush>() as u32,
        shaders::RECEIVERS_COMP.push_constant_size
    );
    assert_eq!(
        std::mem::size_of::<UpsamplePush>() as u32,
        shaders::UPSAMPLE_COMP.push_constant_size
    );
}

#[test]
fn bad_scales_extents_and_parameters_are_errors() {
    let mut rg = RenderGraph::new(0);
    let desc = shine::graph::ImageDesc::new_2d(vk::Format::R32G32B32A32_SFLOAT, 8, 8);
    let h = rg.create_image("x", desc);
    let g = GBuffer {
        position: h,
        normal: h,
        albedo: h,
        material: h,
        emissive: h,
        geometric_normal: h,
        motion: h,
        depth: h,
        extent: [8, 8],
    };
    for scale in [0, 3, 8] {
        assert!(receivers(&mut rg, &g, scale).is_err(), "scale {scale}");
    }
    assert!(receiver_extent([0, 8], 2).is_err());
    assert_eq!(receiver_extent([30, 22], 4), Ok([8, 6]));
    let r = receivers(&mut rg, &g, 2).unwrap();
    let bad = UpsampleParams {
        depth_sigma: 0.0,
        ..UpsampleParams::default()
    };
    assert!(upsample(&mut rg, &r.position, &r, &g, &bad).is_err());
    // The radiance must be RGBA16F at the receiver extent.
    let params = UpsampleParams::default();
    assert!(upsample(&mut rg, &h, &r, &g, &params).is_err());
    let wrong_size = rg.create_image(
        "wrong_size",
        shine::graph::ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, 8, 8),
    );
    assert!(upsample(&mut rg, &wrong_size, &r, &g, &params).is_err());
    let right = rg.create_image(
        "right",
        shine::graph::ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, 4, 4),
    );
    assert!(upsample(&mut rg, &right, &r, &g, &params).is_ok());
}

#[test]
fn receivers_match_the_cpu_exactly() {
    let device = device();
    // 30×22: not divisible by 4, so the right and bottom blocks are clipped.
    let extent = [30, 22];
    let g = CpuGBuffer::new(extent, |x, y| {
        let hash = (x * 73 + y * 151) % 17;
        let depth = if (x + 2 * y) % 7 == 0 || y < 2 {
            0.0
        } else {
            1.0 + hash as f32 * 0.25
        };
        (
            [x as f32, y as f32, -depth, depth],
            [0.0, (hash as f32 / 17.0), 1.0],
        )
    });
    let gpu = GpuGBuffer::new(&device, &g);
    for scale in [1, 2, 4] {
        let mut executor = Executor::new(&device, 1).unwrap();
        let mut rg = executor.begin_frame();
        let gb = gpu.import(&mut rg);
        let r = receivers(&mut rg, &gb, scale).unwrap();
        let texels = u64::from(r.extent[0] * r.extent[1]);
        let mut readback = Readback::new();
        for (image, bytes) in [
            (r.position, 16),
            (r.normal, 8),
            (r.albedo, 4),
            (r.material, 4),
        ] {
            readback.copy(&device, &mut rg, &image, texels * bytes);
        }
        run(&device, &mut executor, rg);
        let expected = cpu_receivers(&g, scale);
        let position: Vec<f32> = bytemuck::pod_collect_to_vec(&readback.bytes(&device, 0));
        assert_eq!(position, expected.position, "recv_position, s = {scale}");
        assert_eq!(
            readback.bytes(&device, 1),
            f16_bytes(&expected.normal),
            "recv_normal, s = {scale}"
        );
        assert_eq!(
            readback.bytes(&device, 2),
            expected.albedo,
            "recv_albedo, s = {scale}"
        );
        assert_eq!(
            readback.bytes(&device, 3),
            expected.material,
            "recv_material, s = {scale}"
        );
    }
    assert_clean(&device);
}

/// Runs receivers (when `recv` is None) or takes the given receiver images, then upsample
/// `radiance` (receiver resolution, RGBA); returns the GPU result and the CPU reference.
fn upsample_both(
    device: &Device,
    g: &CpuGBuffer,
    scale: u32,
    recv: Option<&CpuGBuffer>,
    radiance: &[f32],
    params: &UpsampleParams,
) -> (Vec<f32>, Vec<f32>) {
    let gpu = GpuGBuffer::new(device, g);
    let computed = cpu_receivers(g, scale);
    let recv_cpu = recv.unwrap_or(&computed);
    let recv_gpu = recv.map(|r| GpuGBuffer::new(device, r));
    let radiance = f16_round(radiance);
    let radiance_image = storage_image_with(
        device,
        "radiance",
        vk::Format::R16G16B16A16_SFLOAT,
        recv_cpu.extent,
        &f16_bytes(&radiance),
    );
    let mut executor = Executor::new(device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let gb = gpu.import(&mut rg);
    let r = match &recv_gpu {
        Some(images) => {
            let i = images.import(&mut rg);
            Receivers {
                position: i.position,
                normal: i.normal,
                albedo: i.albedo,
                material: i.material,
                extent: i.extent,
                scale,
            }
        }
        None => receivers(&mut rg, &gb, scale).unwrap(),
    };
    let l = rg.import_gpu_image(&radiance_image, uploaded_state(), ExternalState::UNDEFINED);
    let out = upsample(&mut rg, &l, &r, &gb, params).unwrap();
    let mut readback = Readback::new();
    readback.copy(
        device,
        &mut rg,
        &out,
        u64::from(g.extent[0] * g.extent[1]) * 8,
    );
    run(device, &mut executor, rg);
    let got = f16_floats(&readback.bytes(device, 0));
    let inputs = UpsampleInputs {
        radiance: &radiance,
        recv_position: &recv_cpu.position,
        recv_normal: &recv_cpu.normal,
        position: &g.position,
        normal: &g.normal,
        extent: g.extent,
        grid: CoarseGrid::blocks(g.extent, scale).unwrap(),
    };
    let expected = upsample_cpu(&inputs, params).unwrap();
    (got, expected)
}

/// Largest |gpu − cpu| / (1 + |cpu|).
fn max_error(got: &[f32], expected: &[f32]) -> f32 {
    got.iter()
        .zip(expected)
        .map(|(g, e)| (g - e).abs() / (1.0 + e.abs()))
        .fold(0.0, f32::max)
}

/// f16 rounding (2⁻¹¹ relative) plus pow/division differences between GPU and CPU.
const F16_TOLERANCE: f32 = 2e-3;

const NEAR: f32 = 2.0;
const FAR: f32 = 4.0;
const NEAR_RADIANCE: [f32; 4] = [1.0, 0.5, 0.25, 1.0];
const FAR_RADIANCE: [f32; 4] = [0.0, 0.125, 2.0, 0.0];

/// 64×64: a near rectangle (depth 2) over a far plane (depth 4), edges off the 2- and 4-pixel
/// grids, both facing the camera; the top 3 rows are background.
fn two_planes() -> CpuGBuffer {
    CpuGBuffer::new([64, 64], |x, y| {
        let near = (13..45).contains(&x) && (9..39).contains(&y);
        let depth = match (y < 3, near) {
            (true, _) => 0.0,
            (false, true) => NEAR,
            (false, false) => FAR,
        };
        (
            [
                x as f32 * 0.01 * depth,
                y as f32 * 0.01 * depth,
                -depth,
                depth,
            ],
            [0.0, 0.0, 1.0],
        )
    })
}

/// Radiance of each receiver by the plane it lies on.
fn plane_radiance(recv: &CpuGBuffer) -> Vec<f32> {
    recv.position
        .chunks_exact(4)
        .flat_map(|p| match p[3] {
            d if d == NEAR => NEAR_RADIANCE,
            d if d == FAR => FAR_RADIANCE,
            _ => [0.0; 4],
        })
        .collect()
}

/// Largest distance, relative to the step between the planes, from each valid pixel's result to
/// its own plane's radiance; panics if a background pixel is not 0.
fn max_bleed(g: &CpuGBuffer, result: &[f32]) -> f32 {
    let step: Vec<f32> = NEAR_RADIANCE
        .iter()
        .zip(FAR_RADIANCE)
        .map(|(a, b)| (a - b).abs())
        .collect();
    let mut worst = 0.0f32;
    for (p, out) in g.position.chunks_exact(4).zip(result.chunks_exact(4)) {
        let own = match p[3] {
            d if d == NEAR => NEAR_RADIANCE,
            d if d == FAR => FAR_RADIANCE,
            _ => {
                assert_eq!(out, [0.0; 4], "background must stay 0");
                continue;
            }
        };
        for c in 0..4 {
            if step[c] > 0.0 {
                worst = worst.max((out[c] - own[c]).abs() / step[c]);
            }
        }
    }
    worst
}

/// Bleed the bilateral upsample may leave at a depth ratio of 2, relative to the step: f16
/// rounding only (measured 0 at s = 2 and 4; plain bilinear: 0.75 and 1).
const BLEED_TOLERANCE: f32 = 1e-3;

#[test]
fn upsample_does_not_bleed_across_a_depth_edge() {
    let device = device();
    let g = two_planes();
    let params = UpsampleParams::default();
    // Plain bilinear: every depth and normal weight 1 (σ_z huge, n = 0), on the CPU.
    let bilinear = UpsampleParams {
        depth_sigma: 1e30,
        normal_power: 0.0,
        min_match: 0.0,
    };
    for scale in [2, 4] {
        let recv = cpu_receivers(&g, scale);
        let radiance = plane_radiance(&recv);
        let (got, expected) = upsample_both(&device, &g, scale, None, &radiance, &params);
        let error = max_error(&got, &expected);
        let bleed = max_bleed(&g, &got);
        let inputs = UpsampleInputs {
            radiance: &radiance,
            recv_position: &recv.position,
            recv_normal: &recv.normal,
            position: &g.position,
            normal: &g.normal,
            extent: g.extent,
            grid: CoarseGrid::blocks(g.extent, scale).unwrap(),
        };
        let naive = max_bleed(&g, &upsample_cpu(&inputs, &bilinear).unwrap());
        println!("s = {scale}: GPU vs CPU {error:.2e}, bleed {bleed:.4} (bilinear {naive:.4})");
        assert!(error <= F16_TOLERANCE, "s = {scale}: GPU vs CPU {error}");
        assert!(
            bleed <= BLEED_TOLERANCE,
            "s = {scale}: bilateral bleeds {bleed}"
        );
        assert!(naive >= 0.25, "s = {scale}: bilinear should bleed, {naive}");
    }
    assert_clean(&device);
}

/// 64×64 curved, sloped surface (a bump on a tilted floor) with a step, varying normals and
/// radiance, so the blend uses every weight: GPU against CPU at s = 2 and 4.
#[test]
fn upsample_matches_the_cpu_on_a_curved_surface() {
    let device = device();
    let g = CpuGBuffer::new([64, 64], |x, y| {
        let (fx, fy) = (x as f32 / 64.0 - 0.5, y as f32 / 64.0 - 0.5);
        let bump = 0.3 * (-(fx * fx + fy * fy) * 20.0).exp();
        let depth = 3.0 + 2.0 * fy - bump + if x > 40 { 0.4 } else { 0.0 };
        let n = [fx * 2.0 * bump, 0.5 + fy * 2.0 * bump, 1.0];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        ([fx * depth, fy * depth, -depth, depth], n.map(|v| v / len))
    });
    for scale in [2, 4] {
        let [rw, rh] = receiver_extent(g.extent, scale).unwrap();
        let radiance: Vec<f32> = (0..rw * rh)
            .flat_map(|i| {
                let v = ((i * 37) % 29) as f32 * 0.11;
                [v, 1.0 + v * 0.5, 2.0 - v * 0.25, 1.0]
            })
            .collect();
        let (got, expected) = upsample_both(
            &device,
            &g,
            scale,
            None,
            &radiance,
            &UpsampleParams::default(),
        );
        let error = max_error(&got, &expected);
        println!("s = {scale}: GPU vs CPU {error:.2e}");
        assert!(error <= F16_TOLERANCE, "s = {scale}: GPU vs CPU {error}");
    }
    assert_clean(&device);
}

/// The coarse G-buffer of an internal grid: each sample the full-resolution pixel under its
/// centre (`CoarseGrid::source_texel`, what the host G-buffer conversion fetches).
fn cpu_decimate(g: &CpuGBuffer, grid: &CoarseGrid) -> CpuGBuffer {
    let [w, h] = grid.extent;
    let samples: Vec<usize> = (0..h)
        .flat_map(|y| (0..w).map(move |x| [x, y]))
        .map(|i| {
            let [x, y] = grid.source_texel(i, g.extent);
            (y * g.extent[0] + x) as usize
        })
        .collect();
    CpuGBuffer {
        extent: grid.extent,
        position: gather_texels(&g.position, 4, &samples),
        normal: gather_texels(&g.normal, 4, &samples),
        albedo: gather_texels(&g.albedo, 4, &samples),
        material: gather_texels(&g.material, 4, &samples),
    }
}

/// A GI context's internal grids (75 % and 50 % of 64, and an odd 23 of 64: steps of 4/3, 2
/// and 2.78 pixels): the upsample from the decimated G-buffer matches its CPU twin and does
/// not bleed across the depth edge, as with the receivers' integer blocks.
#[test]
fn internal_grids_match_the_cpu_and_do_not_bleed() {
    let device = device();
    let g = two_planes();
    let gpu = GpuGBuffer::new(&device, &g);
    let params = UpsampleParams::default();
    for side in [48, 32, 23] {
        let grid = CoarseGrid::internal(g.extent, [side, side]).unwrap();
        let coarse = cpu_decimate(&g, &grid);
        let radiance = f16_round(&plane_radiance(&coarse));
        let radiance_image = storage_image_with(
            &device,
            "radiance",
            vk::Format::R16G16B16A16_SFLOAT,
            grid.extent,
            &f16_bytes(&radiance),
        );
        let coarse_gpu = GpuGBuffer::new(&device, &coarse);
        let mut executor = Executor::new(&device, 1).unwrap();
        let mut rg = executor.begin_frame();
        let gb = gpu.import(&mut rg);
        let c = coarse_gpu.import(&mut rg);
        let l = rg.import_gpu_image(&radiance_image, uploaded_state(), ExternalState::UNDEFINED);
        let source = Coarse {
            position: c.position,
            normal: c.normal,
            grid,
        };
        let out = upsample_grid(&mut rg, "upsample", &l, &source, &gb, &params);
        let mut readback = Readback::new();
        readback.copy(
            &device,
            &mut rg,
            &out,
            u64::from(g.extent[0] * g.extent[1]) * 8,
        );
        run(&device, &mut executor, rg);
        let got = f16_floats(&readback.bytes(&device, 0));
        let inputs = UpsampleInputs {
            radiance: &radiance,
            recv_position: &coarse.position,
            recv_normal: &coarse.normal,
            position: &g.position,
            normal: &g.normal,
            extent: g.extent,
            grid,
        };
        let expected = upsample_cpu(&inputs, &params).unwrap();
        let (error, bleed) = (max_error(&got, &expected), max_bleed(&g, &got));
        println!("{side}²: GPU vs CPU {error:.2e}, bleed {bleed:.4}");
        assert!(error <= F16_TOLERANCE, "{side}²: GPU vs CPU {error}");
        assert!(bleed <= BLEED_TOLERANCE, "{side}²: bleeds {bleed}");
    }
    assert_clean(&device);
}

#[test]
fn scale_one_is_an_exact_copy() {
    let device = device();
    let g = CpuGBuffer::new([32, 32], |x, y| {
        let depth = if (x * y) % 11 == 3 {
            0.0
        } else {
            1.0 + ((x * 31 + y * 17) % 13) as f32
        };
        let n = [x as f32 / 32.0 - 0.5, 0.6, y as f32 / 32.0 - 0.5];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        ([x as f32, y as f32, -depth, depth], n.map(|v| v / len))
    });
    let radiance: Vec<f32> = g
        .position
        .chunks_exact(4)
        .enumerate()
        .flat_map(|(i, p)| {
            let v = (i % 97) as f32 * 0.37 + 0.01;
            if p[3] > 0.0 {
                [v, v * 2.0, v * 0.5, 1.0]
            } else {
                [0.0; 4]
            }
        })
        .collect();
    let (got, expected) =
        upsample_both(&device, &g, 1, None, &radiance, &UpsampleParams::default());
    let copy = f16_round(&radiance);
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&expected), bits(&copy), "CPU");
    assert_eq!(bits(&got), bits(&copy), "GPU");
    assert_clean(&device);
}

#[test]
fn all_background_gives_zero() {
    let device = device();
    let g = CpuGBuffer::new([32, 32], |x, y| {
        ([x as f32, y as f32, 0.0, 0.0], [0.0, 0.0, 1.0])
    });
    let radiance = vec![7.0; 16 * 16 * 4];
    let (got, expected) =
        upsample_both(&device, &g, 2, None, &radiance, &UpsampleParams::default());
    assert!(expected.iter().all(|&v| v == 0.0));
    assert!(got.iter().all(|&v| v.to_bits() == 0), "GPU output not 0");
    assert_clean(&device);
}

#[test]
fn fallback_takes_the_best_match_or_the_nearest() {
    let device = device();
    // 8×8 at depth 2 facing +x; receivers 4×4 at the same depth facing +z (match 0), except
    // (1, 1) at 37° from +x (match 0.8³² ≈ 8·10⁻⁴) and (2, 1) at 46° (0.7³² ≈ 10⁻⁵): every
    // pixel's 2×2 is below μ, so each takes the best match of the 3×3 around its own receiver.
    let g = CpuGBuffer::new([8, 8], |x, y| {
        ([x as f32, y as f32, -2.0, 2.0], [1.0, 0.0, 0.0])
    });
    let recv = CpuGBuffer::new([4, 4], |x, y| {
        let n = match (x, y) {
            (1, 1) => [0.8, 0.0, 0.6],
            (2, 1) => [0.7, 0.0, 0.714_142_8],
            _ => [0.0, 0.0, 1.0],
        };
        ([x as f32, y as f32, -2.0, 2.0], n)
    });
    let radiance: Vec<f32> = (0..16u32)
        .flat_map(|i| [i as f32 + 1.0, 100.0 * (i % 3) as f32, 0.5, 1.0])
        .collect();
    let (got, expected) = upsample_both(
        &device,
        &g,
        2,
        Some(&recv),
        &radiance,
        &UpsampleParams::default(),
    );
    for y in 0..8u32 {
        for x in 0..8u32 {
            let (cx, cy) = (x / 2, y / 2);
            let near = |rx: u32, ry: u32| cx.abs_diff(rx) <= 1 && cy.abs_diff(ry) <= 1;
            let chosen = if near(1, 1) {
                4 + 1
            } else if near(2, 1) {
                4 + 2
            } else {
                (cy * 4 + cx) as usize
            };
            let want = &radiance[chosen * 4..chosen * 4 + 4];
            let p = ((y * 8 + x) * 4) as usize;
            assert_eq!(&expected[p..p + 4], want, "CPU at ({x}, {y})");
            assert_eq!(&got[p..p + 4], want, "GPU at ({x}, {y})");
        }
    }
    assert_clean(&device);
}
