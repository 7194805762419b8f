//! The proxy passes of paper 002 (`src/passes/proxy/`) on the Vulkan device against their
//! CPU twin built from shine-sh, on a synthetic receiver buffer: a 24×24 patch of ground
//! (y = 0, normal +y) with a background column, a few proxies above it (one poking through the
//! ground, one far away), the spheres scene's sky. Validation must report nothing.
//!
//! * the splatted accumulation (per-tile neighbour lists + influence test) equals the
//!   brute-force one at every receiver, with a few proxies and with 100 scattered ones, and
//!   receivers outside every sphere of influence get exactly 0;
//! * the accumulation and the shading (SH exponential HYB / PS / OL, eq. 10, eq. 12) match the
//!   CPU twin at every receiver, i.e. the GLSL twins (`sh_proxy_self_shadow`, table lookups,
//!   `sh_exp_*`, `sh_product`) match shine-sh;
//! * the brute-force product mode matches its CPU twin.

mod common;

use common::{
    assert_clean, device, f16_to_f32, f32_to_f16, read_by_copy, storage_image_with, uploaded_state,
};
use glam::{Vec3, Vec4};
use shine::gpu::{Device, vk};
use shine::gpu_scene::environment_sh::EnvironmentSh;
use shine::graph::{Executor, ExternalState, RenderGraph};
use shine::passes::brdf_tables::GatherBrdf;
use shine::passes::proxy::{
    self, Accumulation, ExpMethod, GpuProxy, ProxyInputs, ProxyParams, ProxyTables,
};
use shine::passes::receivers::Receivers;
use shine::reference::proxy::{GlossyView, ReceiverSample, accumulate_cpu, shade_cpu};
use shine_sh::brdf_table::HemisphereSampling;
use shine_sh::exp_log::ShExp;

const SIDE: u32 = 24;

/// The synthetic receiver buffer: ground samples 0.25 m apart around the origin; the last
/// column is background.
fn receivers() -> Vec<ReceiverSample> {
    (0..SIDE * SIDE)
        .map(|i| {
            let (x, y) = (i % SIDE, i / SIDE);
            let position = Vec3::new((x as f32 - 11.5) * 0.25, 0.0, (y as f32 - 11.5) * 0.25);
            ReceiverSample {
                position,
                valid: x != SIDE - 1,
                normal: Vec3::Y,
                albedo: Vec3::new(0.8, 0.6, 0.4),
                // every third column metal; roughness exact in the receivers' unorm8, across
                // the whole range (the specular pass's fade included)
                metallic: if x % 3 == 0 { 1.0 } else { 0.0 },
                roughness: ((y * 11) % 256) as f32 / 255.0,
            }
        })
        .collect()
}

/// Where the receivers are seen from (their glossy lobes).
const CAMERA: Vec3 = Vec3::new(0.4, 1.5, 2.5);

/// The BRDF SH tables of the glossy receivers (coarse sampling: GPU and CPU read the same).
fn glossy(bands: u32) -> GatherBrdf {
    let sampling = HemisphereSampling {
        n_theta: 12,
        n_phi: 24,
    };
    GatherBrdf::build(bands, sampling).unwrap()
}

fn proxies() -> Vec<GpuProxy> {
    vec![
        GpuProxy::new(Vec3::new(0.3, 0.12, 0.2), 0.08, Vec3::new(0.9, 0.2, 0.2)),
        GpuProxy::new(Vec3::new(0.45, 0.1, 0.3), 0.07, Vec3::new(0.2, 0.9, 0.2)),
        // pokes through the ground: self-shadowing rule 3
        GpuProxy::new(Vec3::new(-0.5, -0.02, 0.4), 0.06, Vec3::splat(0.7)),
        // far away and small: its sphere of influence (≈ 17 r) reaches few receivers
        GpuProxy::new(Vec3::new(-2.6, 0.05, -2.6), 0.02, Vec3::splat(0.5)),
    ]
}

fn environment(bands: u32) -> EnvironmentSh {
    let scene = shine_scene::Scene::builtin("spheres").expect("spheres scene");
    let sky = scene.environment.expect("the spheres scene has a sky");
    EnvironmentSh::project(&sky, bands as usize).expect("projection")
}

/// GPU images of the receiver buffer, in the receivers' upload formats.
struct ReceiverImages([shine::gpu::Image; 4]);

impl ReceiverImages {
    fn new(device: &Device, samples: &[ReceiverSample]) -> Self {
        let e = [SIDE, SIDE];
        let position: Vec<f32> = samples
            .iter()
            .flat_map(|s| {
                let w = if s.valid { 5.0 } else { 0.0 };
                s.position.extend(w).to_array()
            })
            .collect();
        let normal: Vec<u8> = samples
            .iter()
            .flat_map(|s| {
                let n = if s.valid { s.normal } else { Vec3::ZERO };
                n.extend(0.0).to_array().map(f32_to_f16)
            })
            .flat_map(u16::to_le_bytes)
            .collect();
        let unorm = |v: Vec4| v.to_array().map(|c| (c * 255.0).round() as u8);
        let albedo: Vec<u8> = samples
            .iter()
            .flat_map(|s| unorm(s.albedo.extend(1.0)))
            .collect();
        let material: Vec<u8> = samples
            .iter()
            .flat_map(|s| unorm(Vec4::new(s.roughness, s.metallic, 0.0, 0.0)))
            .collect();
        Self([
            storage_image_with(
                device,
                "recv_position",
                vk::Format::R32G32B32A32_SFLOAT,
                e,
                bytemuck::cast_slice(&position),
            ),
            storage_image_with(
                device,
                "recv_normal",
                vk::Format::R16G16B16A16_SFLOAT,
                e,
                &normal,
            ),
            storage_image_with(
                device,
                "recv_albedo",
                vk::Format::R8G8B8A8_UNORM,
                e,
                &albedo,
            ),
            storage_image_with(
                device,
                "recv_material",
                vk::Format::R8G8B8A8_UNORM,
                e,
                &material,
            ),
        ])
    }

    fn import(&self, rg: &mut RenderGraph) -> Receivers {
        let [p, n, a, m] = self
            .0
            .each_ref()
            .map(|i| rg.import_gpu_image(i, uploaded_state(), ExternalState::UNDEFINED));
        Receivers {
            position: p,
            normal: n,
            albedo: a,
            material: m,
            extent: [SIDE, SIDE],
            scale: 1,
        }
    }
}

/// What one GPU run returns.
struct GpuRun {
    sums: Vec<f32>,
    occlusion: Vec<f32>,
    radiance: Vec<Vec3>,
}

/// Runs accumulate (+ shade when `shade`) on the GPU.
fn run_gpu(
    device: &Device,
    samples: &[ReceiverSample],
    list: &[GpuProxy],
    tables: &ProxyTables,
    env: &EnvironmentSh,
    params: &ProxyParams,
) -> GpuRun {
    let images = ReceiverImages::new(device, samples);
    let storage = |name, data: &[u8]| common::storage_with(device, name, data);
    let proxy_buffer = storage("proxies", bytemuck::cast_slice(list));
    let table_buffer = storage("tables", bytemuck::cast_slice(&tables.gpu_data()));
    let env_buffer = storage("environment", bytemuck::cast_slice(&env.gpu_data()));
    let brdf_buffer = storage(
        "brdf",
        bytemuck::cast_slice(&glossy(params.bands).gpu_data()),
    );
    let texels = u64::from(SIDE * SIDE);
    let coeffs = u64::from(params.bands * params.bands);
    let readback = |name, bytes| {
        common::buffer(
            device,
            name,
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
        )
    };
    let sums_out = readback("sums", texels * proxy::sums_stride(params.bands) as u64 * 4);
    let occ_out = readback("occlusion", texels * coeffs * 4);
    let rad_out = readback("radiance", texels * 8);
    let mut executor = Executor::new(device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let recv = images.import(&mut rg);
    let inputs = ProxyInputs {
        proxies: rg.import_gpu_buffer(&proxy_buffer, uploaded_state(), ExternalState::UNDEFINED),
        count: list.len() as u32,
        tables: rg.import_gpu_buffer(&table_buffer, uploaded_state(), ExternalState::UNDEFINED),
        environment: rg.import_gpu_buffer(&env_buffer, uploaded_state(), ExternalState::UNDEFINED),
        brdf: rg.import_gpu_buffer(&brdf_buffer, uploaded_state(), ExternalState::UNDEFINED),
    };
    let sums = proxy::proxy_accumulate(&mut rg, &recv, &inputs, tables, params).unwrap();
    let out = proxy::proxy_shade(&mut rg, &recv, &sums, &inputs, tables, params, CAMERA).unwrap();
    let mut s = rg.import_gpu_buffer(&sums_out, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_buffer("read sums", &sums, &mut s);
    let mut o = rg.import_gpu_buffer(&occ_out, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_buffer("read occlusion", &out.occlusion, &mut o);
    let mut r = rg.import_gpu_buffer(&rad_out, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_image_to_buffer("read radiance", &out.radiance, &mut r);
    let mut commands = device.begin_commands().unwrap();
    executor.execute(commands.raw(), rg).unwrap();
    device.submit(commands).unwrap().wait().unwrap();
    let floats = |b: &shine::gpu::Buffer| -> Vec<f32> {
        bytemuck::cast_slice(&device.read_buffer(b).unwrap()).to_vec()
    };
    let halves: Vec<f32> = device
        .read_buffer(&rad_out)
        .unwrap()
        .chunks_exact(2)
        .map(|c| f16_to_f32(u16::from_le_bytes([c[0], c[1]])))
        .collect();
    GpuRun {
        sums: floats(&sums_out),
        occlusion: floats(&occ_out),
        radiance: halves
            .chunks_exact(4)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect(),
    }
}

fn params(bands: u32, accumulation: Accumulation, exp: ExpMethod) -> ProxyParams {
    ProxyParams {
        bands,
        accumulation,
        exp,
        indirect: true,
        // the glossy share of the traced specular pass: ties the GLSL fade to the Rust one
        specular_limit: shine::passes::specular::LIMIT,
    }
}

fn close(a: f32, b: f32, rel: f32, abs: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + abs
}

/// Splatting equals brute force at every receiver; outside every sphere of influence the sums
/// are exactly 0; the GPU matches the CPU twin (accumulation and HYB shading).
#[test]
fn splat_equals_brute_force_and_cpu() {
    let device = device();
    let bands = 4;
    let samples = receivers();
    let list = proxies();
    let tables = ProxyTables::build(bands, 15.0, 10.0).unwrap();
    let env = environment(bands);
    let exp = ShExp::new(bands as usize).unwrap();
    let brdf = glossy(bands);
    let view = GlossyView {
        camera: CAMERA,
        brdf: &brdf,
    };
    let splat_params = params(bands, Accumulation::Splat, ExpMethod::Hyb);
    let splat = run_gpu(&device, &samples, &list, &tables, &env, &splat_params);
    let brute = run_gpu(
        &device,
        &samples,
        &list,
        &tables,
        &env,
        &params(bands, Accumulation::Brute, ExpMethod::Hyb),
    );
    assert_clean(&device);
    assert_eq!(splat.sums, brute.sums, "splat and brute force differ");
    let stride = proxy::sums_stride(bands);
    let support = tables.support_shadow.min(tables.support_indirect);
    let (mut inside, mut outside) = (0, 0);
    let mut worst = (0.0f32, 0.0f32);
    for (i, s) in samples.iter().enumerate() {
        let gpu = &splat.sums[i * stride..(i + 1) * stride];
        let influenced = s.valid
            && list.iter().any(|p| {
                let c = Vec3::from_slice(&p.sphere[..3]);
                p.sphere[3] > support * c.distance(s.position)
            });
        if influenced {
            inside += 1;
        } else {
            outside += 1;
            assert!(gpu.iter().all(|&x| x == 0.0), "receiver {i}: {gpu:?}");
        }
        let cpu = accumulate_cpu(s, &list, &tables, &env, &splat_params, &exp).unwrap();
        for (k, (g, c)) in gpu.iter().zip(&cpu).enumerate() {
            assert!(
                close(*g, *c, 2e-4, 2e-5),
                "receiver {i} sum {k}: {g} vs {c}"
            );
            worst.0 = worst.0.max((g - c).abs());
        }
        let (o, rad) = shade_cpu(s, &cpu, &env, &splat_params, &exp, &view).unwrap();
        let go = &splat.occlusion[i * 16..(i + 1) * 16];
        for (k, (g, c)) in go.iter().zip(&o).enumerate() {
            assert!(close(*g, *c, 1e-3, 1e-4), "receiver {i} O_{k}: {g} vs {c}");
        }
        let gr = splat.radiance[i];
        for c in 0..3 {
            // RGBA16F output: 2^-11 relative
            assert!(
                close(gr[c], rad[c], 2e-3, 1e-4),
                "receiver {i} radiance {c}: {} vs {}",
                gr[c],
                rad[c]
            );
            worst.1 = worst.1.max((gr[c] - rad[c]).abs() / rad[c].abs().max(1e-3));
        }
    }
    println!(
        "receivers inside an influence sphere: {inside}, outside: {outside}; worst sum diff \
         {:e}, worst radiance rel diff {:e}",
        worst.0, worst.1
    );
    assert!(
        inside > 50 && outside > 50,
        "{inside} inside, {outside} outside"
    );
}

/// Neighbour lists over many proxies (issue 18, item 4): 100 small proxies scattered over
/// the receivers, so each 8×8 tile's list holds a different subset, spread over four mask
/// words. The splatted sums equal brute force's bit for bit, and the lists do cull: no
/// receiver lies in every sphere of influence, many lie in several.
#[test]
fn neighbour_lists_of_many_proxies_equal_brute_force() {
    let device = device();
    let bands = 4;
    let samples = receivers();
    // a fixed linear congruential sequence in [0, 1)
    let mut state = 12345u32;
    let mut next = move || {
        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        (state >> 8) as f32 / (1u32 << 24) as f32
    };
    let list: Vec<GpuProxy> = (0..100)
        .map(|_| {
            let r = 0.01 + 0.02 * next();
            let (x, z) = (6.0 * next() - 3.0, 6.0 * next() - 3.0);
            GpuProxy::new(Vec3::new(x, r, z), r, Vec3::new(next(), next(), next()))
        })
        .collect();
    let tables = ProxyTables::build(bands, 15.0, 10.0).unwrap();
    let env = environment(bands);
    let run = |accumulation| {
        let p = params(bands, accumulation, ExpMethod::Hyb);
        run_gpu(&device, &samples, &list, &tables, &env, &p)
    };
    let (splat, brute) = (run(Accumulation::Splat), run(Accumulation::Brute));
    assert_clean(&device);
    assert_eq!(
        splat.sums, brute.sums,
        "neighbour lists and brute force differ"
    );
    let support = tables.support_shadow.min(tables.support_indirect);
    let neighbours: Vec<usize> = samples
        .iter()
        .filter(|s| s.valid)
        .map(|s| {
            list.iter()
                .filter(|p| {
                    p.sphere[3] > support * Vec3::from_slice(&p.sphere[..3]).distance(s.position)
                })
                .count()
        })
        .collect();
    let most = neighbours.iter().copied().max().unwrap();
    let several = neighbours.iter().filter(|&&n| n >= 2).count();
    println!(
        "proxies in reach of a receiver: at most {most} of 100; {several} receivers reach 2 or more"
    );
    assert!(
        most < 100 / 4,
        "the proxies are not scattered: {most} reach one receiver"
    );
    assert!(
        several > samples.len() / 4,
        "only {several} receivers reach 2 or more proxies"
    );
}

/// The other exponentials (PS, OL) and orders 3 and 6 shade as their CPU twin.
#[test]
fn exponentials_and_orders_match_cpu() {
    let device = device();
    let samples = receivers();
    let list = proxies();
    for (bands, method) in [
        (4, ExpMethod::Ps),
        (4, ExpMethod::Ol),
        (3, ExpMethod::Hyb),
        (6, ExpMethod::Hyb),
    ] {
        let tables = ProxyTables::build(bands, 15.0, 10.0).unwrap();
        let env = environment(bands);
        let exp = ShExp::new(bands as usize).unwrap();
        let brdf = glossy(bands);
        let view = GlossyView {
            camera: CAMERA,
            brdf: &brdf,
        };
        let p = params(bands, Accumulation::Splat, method);
        let gpu = run_gpu(&device, &samples, &list, &tables, &env, &p);
        let stride = proxy::sums_stride(bands);
        let n2 = (bands * bands) as usize;
        for (i, s) in samples.iter().enumerate().step_by(7) {
            let sums = &gpu.sums[i * stride..(i + 1) * stride];
            let (o, rad) = shade_cpu(s, sums, &env, &p, &exp, &view).unwrap();
            for (k, (g, c)) in gpu.occlusion[i * n2..(i + 1) * n2]
                .iter()
                .zip(&o)
                .enumerate()
            {
                assert!(
                    close(*g, *c, 1e-3, 1e-4),
                    "{method} b{bands} receiver {i} O_{k}: {g} vs {c}"
                );
            }
            for c in 0..3 {
                assert!(
                    close(gpu.radiance[i][c], rad[c], 2e-3, 1e-4),
                    "{method} b{bands} receiver {i}: {} vs {}",
                    gpu.radiance[i][c],
                    rad[c]
                );
            }
        }
    }
    assert_clean(&device);
}

/// Brute-force mode (unclamped tables, exact SH products) against its CPU twin.
#[test]
fn brute_force_product_matches_cpu() {
    let device = device();
    let bands = 4;
    let samples = receivers();
    let list = proxies();
    let tables = ProxyTables::build(bands, 15.0, 10.0).unwrap();
    let env = environment(bands);
    let exp = ShExp::new(bands as usize).unwrap();
    let brdf = glossy(bands);
    let view = GlossyView {
        camera: CAMERA,
        brdf: &brdf,
    };
    let p = params(bands, Accumulation::Product, ExpMethod::Hyb);
    let gpu = run_gpu(&device, &samples, &list, &tables, &env, &p);
    assert_clean(&device);
    let stride = proxy::sums_stride(bands);
    for (i, s) in samples.iter().enumerate().step_by(5) {
        let cpu = accumulate_cpu(s, &list, &tables, &env, &p, &exp).unwrap();
        for (k, (g, c)) in gpu.sums[i * stride..(i + 1) * stride]
            .iter()
            .zip(&cpu)
            .enumerate()
        {
            assert!(
                close(*g, *c, 1e-3, 1e-4),
                "receiver {i} sum {k}: {g} vs {c}"
            );
        }
        let (_, rad) = shade_cpu(s, &cpu, &env, &p, &exp, &view).unwrap();
        for c in 0..3 {
            assert!(
                close(gpu.radiance[i][c], rad[c], 3e-3, 1e-4),
                "receiver {i}: {} vs {}",
                gpu.radiance[i][c],
                rad[c]
            );
        }
    }
}

/// Sanity of the model on the CPU twin: a unit-albedo ground point 0.1 m beside a ball of
/// radius 0.5 resting on the ground (α = 0.64) loses about 30% of its sky light to the ball's
/// shadow, half of which the grey ball's indirect light gives back; a far point is unchanged.
#[test]
fn a_proxy_shadows_the_ground_beside_it() {
    let bands = 4;
    let tables = ProxyTables::build(bands, 15.0, 10.0).unwrap();
    let env = environment(bands);
    let exp = ShExp::new(bands as usize).unwrap();
    let brdf = glossy(bands);
    let view = GlossyView {
        camera: CAMERA,
        brdf: &brdf,
    };
    let with_indirect = params(bands, Accumulation::Splat, ExpMethod::Hyb);
    let ball = [GpuProxy::new(
        Vec3::new(0.0, 0.5, 0.0),
        0.5,
        Vec3::splat(0.5),
    )];
    let shade_with = |x: f32, proxies: &[GpuProxy], p: &ProxyParams| {
        let r = ReceiverSample {
            position: Vec3::new(x, 0.0, 0.0),
            valid: true,
            normal: Vec3::Y,
            albedo: Vec3::ONE,
            metallic: 0.0,
            roughness: 1.0,
        };
        let sums = accumulate_cpu(&r, proxies, &tables, &env, p, &exp).unwrap();
        shade_cpu(&r, &sums, &env, p, &exp, &view).unwrap().1
    };
    let shade = |x: f32, proxies: &[GpuProxy]| shade_with(x, proxies, &with_indirect);
    let (near, open) = (shade(0.6, &ball), shade(0.6, &[]));
    let (far, far_open) = (shade(20.0, &ball), shade(20.0, &[]));
    println!("beside the ball {near} vs open sky {open}; far {far} vs {far_open}");
    assert!(
        near.y < 0.95 * open.y && near.y > 0.7 * open.y,
        "{near} vs {open}"
    );
    assert_eq!(far, far_open);
    let shadow_only = shade_with(
        0.6,
        &ball,
        &ProxyParams {
            indirect: false,
            ..with_indirect
        },
    );
    println!("shadow only {shadow_only}");
    assert!(
        shadow_only.y < 0.8 * open.y && shadow_only.y < near.y,
        "{shadow_only}"
    );
}
