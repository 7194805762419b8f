//! Shared set-up of the GPU tests: a validated device that fails loudly when absent, and the
//! small resources and dispatches several tests share. (Each test crate uses a subset.)
#![allow(dead_code)]

pub mod cli;
pub mod scenes;
pub mod spot_rsm;

use glam::Vec4;
use shine::gpu::{
    Buffer, BufferDesc, ComputePipeline, Descriptor, Device, DeviceDesc, MemoryLocation,
    ShaderDesc, Validation, vk,
};
use shine::graph::ExternalState;

/// Creates the test device with the validation layer (synchronization validation on).
///
/// Never skips: without a Vulkan device or, under `CI`, without the validation layer, the test
/// fails with the install command (docs/architecture.md, "Tests").
pub fn device() -> Device {
    let validation = if std::env::var_os("CI").is_some() {
        Validation::Required
    } else {
        Validation::IfAvailable
    };
    let desc = DeviceDesc {
        validation,
        ..DeviceDesc::from_env()
    };
    match Device::new(&desc) {
        Ok(device) => device,
        Err(e) => panic!(
            "GPU tests need a Vulkan 1.3 device and the validation layer: {e}\n\
             (Debian: apt-get install libvulkan1 mesa-vulkan-drivers vulkan-validationlayers)"
        ),
    }
}

/// Asserts that the validation layer and driver reported no error and no warning.
pub fn assert_clean(device: &Device) {
    if let Err(e) = device.wait_idle() {
        panic!("waiting for the device failed: {e}");
    }
    let counts = device.message_counts();
    assert_eq!(
        counts.problems(),
        0,
        "validation reported {} error(s) and {} warning(s):\n{}",
        counts.errors,
        counts.warnings,
        device.messages().join("\n")
    );
}

/// A device-local buffer of `size` bytes.
pub fn buffer(device: &Device, name: &str, size: u64, usage: vk::BufferUsageFlags) -> Buffer {
    Buffer::new(
        device,
        &BufferDesc {
            name,
            size,
            usage,
            location: MemoryLocation::GpuOnly,
        },
    )
    .expect("buffer")
}

/// A device-local storage buffer holding `data`.
pub fn storage_with(device: &Device, name: &str, data: &[u8]) -> Buffer {
    Buffer::storage_with_data(device, name, data).expect("storage buffer")
}

/// Runs a `sh_eval.comp` variant of `coeffs` coefficients over `dirs`; returns the basis values.
pub fn sh_eval(
    device: &Device,
    shader: &'static ShaderDesc,
    dirs: &[[f32; 4]],
    coeffs: usize,
) -> Vec<f32> {
    let pipeline = ComputePipeline::new(device, shader).expect("pipeline");
    let input = storage_with(device, "directions", bytemuck::cast_slice(dirs));
    let output = buffer(
        device,
        "coefficients",
        (dirs.len() * coeffs * 4) as u64,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
    );
    let count = dirs.len() as u32;
    device
        .run_once(|cmd| {
            cmd.begin_scope("sh_eval")?;
            cmd.bind_compute(
                &pipeline,
                &[
                    ("directions", Descriptor::from(&input)),
                    ("coefficients", Descriptor::from(&output)),
                ],
            )?;
            cmd.push_constants(pipeline.layout(), bytemuck::bytes_of(&count))?;
            cmd.dispatch_threads(&pipeline, [count, 1, 1]);
            cmd.end_scope()
        })
        .expect("dispatch");
    let bytes = device.read_buffer(&output).expect("readback");
    bytemuck::cast_slice(&bytes).to_vec()
}

/// f32 → IEEE half bits, round to nearest even (what an RGBA16F upload holds).
pub fn f32_to_f16(v: f32) -> u16 {
    let bits = v.to_bits();
    let sign = ((bits >> 16) & 0x8000) as u16;
    let exp = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    let mant = bits & 0x7f_ffff;
    if exp >= 31 {
        return sign | 0x7c00;
    }
    if exp <= 0 {
        if exp < -10 {
            return sign;
        }
        let m = (mant | 0x80_0000) >> (1 - exp);
        let half = m >> 13;
        let rest = m & 0x1fff;
        let round = u32::from(rest > 0x1000 || (rest == 0x1000 && half & 1 == 1));
        return sign | (half + round) as u16;
    }
    let half = ((exp as u32) << 10) | (mant >> 13);
    let rest = mant & 0x1fff;
    let round = u32::from(rest > 0x1000 || (rest == 0x1000 && half & 1 == 1));
    sign | (half + round) as u16
}

/// IEEE half bits → f32 (exact).
pub fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let mant = f32::from(h & 0x3ff);
    match exp {
        0 => sign * mant * 2f32.powi(-24),
        31 => sign * f32::INFINITY,
        _ => sign * (1.0 + mant / 1024.0) * 2f32.powi(exp - 15),
    }
}

/// A device-local buffer of exactly `data.len()` bytes holding `data`.
pub fn buffer_with(
    device: &Device,
    name: &str,
    usage: vk::BufferUsageFlags,
    data: &[u8],
) -> Buffer {
    let desc = BufferDesc {
        name,
        size: data.len() as u64,
        usage,
        location: MemoryLocation::GpuOnly,
    };
    Buffer::with_data(device, &desc, data).expect("buffer with data")
}

/// A storage image holding `data` (tightly packed texels), left in `GENERAL` layout.
pub fn storage_image_with(
    device: &Device,
    name: &str,
    format: vk::Format,
    extent: [u32; 2],
    data: &[u8],
) -> shine::gpu::Image {
    let usage = vk::ImageUsageFlags::STORAGE
        | vk::ImageUsageFlags::TRANSFER_DST
        | vk::ImageUsageFlags::TRANSFER_SRC;
    let desc = shine::gpu::ImageDesc::new_2d(name, extent, format, usage);
    let image = shine::gpu::Image::new(device, &desc).expect("image");
    device
        .upload_image(&image, data, vk::ImageLayout::GENERAL)
        .expect("image upload");
    image
}

/// The state an uploaded input is in when a graph imports it (a copy wrote it, `GENERAL`).
pub fn uploaded_state() -> ExternalState {
    ExternalState::new(
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_WRITE,
        vk::ImageLayout::GENERAL,
    )
}

/// The state a readback buffer is left in: a copy reads it next.
pub fn read_by_copy() -> ExternalState {
    ExternalState::new(
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::UNDEFINED,
    )
}

/// A device-local storage buffer that transfers can fill and read: holding `data`, or `size`
/// uninitialised bytes.
pub fn transfer_storage(device: &Device, name: &str, size: u64, data: Option<&[u8]>) -> Buffer {
    let desc = BufferDesc {
        name,
        size,
        usage: vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST,
        location: MemoryLocation::GpuOnly,
    };
    match data {
        Some(d) => Buffer::with_data(device, &desc, d).expect("buffer"),
        None => Buffer::new(device, &desc).expect("buffer"),
    }
}

/// A value as an RGBA16F texel stores it.
pub fn q16(v: Vec4) -> Vec4 {
    Vec4::from_array(v.to_array().map(|c| f16_to_f32(f32_to_f16(c))))
}

/// RGBA16F texel bytes of `texels`.
pub fn bytes_f16(texels: &[Vec4]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.to_array().map(f32_to_f16))
        .flat_map(u16::to_le_bytes)
        .collect()
}

/// RGBA8_UNORM texel bytes of `texels` (rounded).
pub fn bytes_unorm8(texels: &[Vec4]) -> Vec<u8> {
    texels
        .iter()
        .flat_map(|t| t.to_array().map(|c| (c * 255.0).round() as u8))
        .collect()
}

/// Records `rg` with `executor` into one command buffer, submits it and waits.
pub fn run_graph(
    device: &Device,
    executor: &mut shine::graph::Executor,
    rg: shine::graph::RenderGraph,
) {
    let mut commands = device.begin_commands().expect("commands");
    executor.execute(commands.raw(), rg).expect("execute");
    device
        .submit(commands)
        .expect("submit")
        .wait()
        .expect("wait");
}

/// RGBA16F texels from their bytes.
pub fn decode_rgba16f(bytes: &[u8]) -> Vec<Vec4> {
    let halves: Vec<f32> = bytes
        .chunks_exact(2)
        .map(|c| f16_to_f32(u16::from_le_bytes([c[0], c[1]])))
        .collect();
    halves.chunks_exact(4).map(Vec4::from_slice).collect()
}

/// RMS of `a - b` over the mean of `b` (rgb, every pixel): the image tests' relative RMSE.
pub fn relative_rmse(
    a: &shine::capture::image_io::HdrImage,
    b: &shine::capture::image_io::HdrImage,
) -> f64 {
    let rgb = |i: &shine::capture::image_io::HdrImage| -> Vec<[f32; 3]> {
        i.texels.iter().map(|t| [t[0], t[1], t[2]]).collect()
    };
    let mask = vec![true; b.texels.len()];
    shine::study::metrics::image_error(&rgb(a), &rgb(b), &mask)
        .expect("a lit reference")
        .relative_rmse
}

/// A deterministic pseudo-random number generator (xorshift32) for test inputs.
pub struct Rng(pub u32);

impl Rng {
    /// The next number in [0, 1).
    pub fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 17;
        self.0 ^= self.0 << 5;
        (self.0 >> 8) as f32 / (1u32 << 24) as f32
    }
}

/// A motion image (`gb_motion`, RG16F) holding `motion`, row-major at `extent`.
pub fn motion_image(device: &Device, extent: [u32; 2], motion: &[glam::Vec2]) -> shine::gpu::Image {
    let bytes: Vec<u8> = motion
        .iter()
        .flat_map(|m| [f32_to_f16(m.x), f32_to_f16(m.y)])
        .flat_map(u16::to_le_bytes)
        .collect();
    storage_image_with(
        device,
        "gb_motion",
        vk::Format::R16G16_SFLOAT,
        extent,
        &bytes,
    )
}

/// A number in [0, 1) from `i`, the same every run: reproducible pseudo-random test inputs.
pub fn hash01(i: u32) -> f32 {
    let mut x = i.wrapping_mul(0x9e37_79b9) ^ 0x85eb_ca6b;
    x ^= x >> 15;
    x = x.wrapping_mul(0x2c1b_3c6d);
    x ^= x >> 12;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

/// Runs a test shader of the "cases" shape once: binding `cases` (a storage buffer holding
/// `cases`), binding `results` (`result_bytes`, read back and returned), a push constant of
/// `count` and one invocation per case (the GLSL-against-Rust checks of `shaders/tests/`).
pub fn run_cases(
    device: &Device,
    shader: &'static ShaderDesc,
    cases: &[u8],
    result_bytes: u64,
    count: u32,
) -> Vec<u8> {
    let pipeline = ComputePipeline::new(device, shader).expect("pipeline");
    let input = storage_with(device, "cases", cases);
    let results = buffer(
        device,
        "results",
        result_bytes,
        vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
    );
    device
        .run_once(|cmd| {
            cmd.bind_compute(
                &pipeline,
                &[
                    ("cases", Descriptor::from(&input)),
                    ("results", Descriptor::from(&results)),
                ],
            )?;
            cmd.push_constants(pipeline.layout(), bytemuck::bytes_of(&count))?;
            cmd.dispatch_threads(&pipeline, [count, 1, 1]);
            Ok(())
        })
        .expect("dispatch");
    device.read_buffer(&results).expect("readback")
}
