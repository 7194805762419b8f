//! AAF (paper 004, `src/passes/aaf/`) on the GPU against its CPU twin
//! (`shine::reference::aaf`) and the path-traced reference, with the validation layer reporting
//! nothing. Never skips (docs/architecture.md, "Tests").

mod common;

use common::{
    assert_clean, bytes_f16, bytes_unorm8, device, f16_to_f32, q16, read_by_copy,
    storage_image_with, transfer_storage, uploaded_state,
};
use glam::{Mat4, Vec3, Vec4};
use shine::frame::renderer::Renderer;
use shine::gpu::{Device, vk};
use shine::graph::{Executor, ExternalState, Handle, Image, RenderGraph};
use shine::passes::aaf::{self, AafParams};
use shine::passes::composite::Component;
use shine::passes::gbuffer::{GBuffer, View};
use shine::reference::aaf::{FilterTexel, Filtered, Means, beta_cpu, filter_cpu, weights};
use shine::reference::{ReferenceParams, render_reference};
use shine::settings::{GiTechniques, Settings};
use shine_scene::Scene;

const EXTENT: [u32; 2] = [24, 16];
const EYE: Vec3 = Vec3::new(0.0, 1.0, 3.0);
/// The scene's size S (the z_min clamp is a fraction of it).
const SCENE_SIZE: f32 = 6.0;

/// The perspective camera the synthetic G-buffer is seen from (only its footprint and
/// position matter to the passes under test).
fn camera() -> View {
    View {
        view: Mat4::look_at_rh(EYE, Vec3::new(0.0, 0.0, -1.0), Vec3::Y),
        proj: Mat4::perspective_rh(1.0, 1.5, 0.1, 100.0),
        eye: EYE,
        orthographic: false,
        extent: 1.0,
    }
}

/// A value as an RGBA8 UNORM texel stores it.
fn q8(v: Vec4) -> Vec4 {
    Vec4::from_array(v.to_array().map(|c| (c * 255.0).round() / 255.0))
}

/// Pixel `p`'s means as the filter reads them from the synthetic sums.
fn means(s: &Synthetic, p: usize) -> Means {
    let record = &s.sums[aaf::SUMS_STRIDE as usize * p..][..aaf::SUMS_STRIDE as usize];
    let count = record[0].w;
    Means {
        diffuse: (record[0].truncate() - record[1].truncate()) / count,
        tangent: std::array::from_fn(|k| record[2 + k].truncate() / count),
        specular: record[1].truncate() / count,
        lit: record[1].w > 0.0,
    }
}

/// Whether the filter moved a pixel's diffuse mean (at its shading normal `n`) or its specular
/// mean by more than 0.1%.
fn moved(filtered: &Filtered, raw: &Means, n: Vec3) -> bool {
    (filtered.diffuse_at(n) - raw.diffuse).length() > 1e-3 * raw.diffuse.length()
        || (filtered.specular - raw.specular).length() > 1e-3 * raw.specular.length()
}

/// The synthetic frame: per pixel, the G-buffer texels, the first pass's (z_min, z_max) and the
/// sampling sums ([`aaf::SUMS_STRIDE`] vec4: diffuse sum and count, specular sum and the
/// diffuse part's flag, the diffuse samples' tangent sums along x, y and z).
struct Synthetic {
    position: Vec<Vec4>,
    normal: Vec<Vec4>,
    geometric_normal: Vec<Vec4>,
    albedo: Vec<Vec4>,
    material: Vec<Vec4>,
    depths: Vec<[f32; 2]>,
    sums: Vec<Vec4>,
}

/// 24×16 pixels: a floor (left two thirds, y = 0, up) meeting a wall (right third, x = 1,
/// facing −x), two background columns, a few pixels whose rays hit nothing. The floor's
/// radiance is dim and the wall's bright, so light leaking across the corner shows.
fn synthetic() -> Synthetic {
    let [w, h] = EXTENT;
    let mut s = Synthetic {
        position: Vec::new(),
        normal: Vec::new(),
        geometric_normal: Vec::new(),
        albedo: Vec::new(),
        material: Vec::new(),
        depths: Vec::new(),
        sums: Vec::new(),
    };
    for j in 0..h {
        for i in 0..w {
            let p = j * w + i;
            let u = i as f32 / w as f32;
            let v = j as f32 / h as f32;
            let (position, normal, radiance) = if i == 3 || i == 4 {
                (Vec4::ZERO, Vec4::ZERO, Vec3::ZERO)
            } else if i < 16 {
                let x = Vec3::new(-1.0 + 2.0 * u, 0.0, -2.0 + 2.0 * v);
                (
                    x.extend((EYE - x).length()),
                    Vec4::new(0.0, 1.0, 0.0, 0.0),
                    Vec3::splat(0.2),
                )
            } else {
                let x = Vec3::new(1.0, 1.5 * v, -2.0 + 2.0 * (u - 0.66));
                (
                    x.extend((EYE - x).length()),
                    Vec4::new(-1.0, 0.0, 0.0, 0.0),
                    Vec3::splat(5.0),
                )
            };
            let count = 16.0 + (common::hash01(p) * 40.0).floor();
            let noise = Vec3::new(
                common::hash01(3 * p + 1),
                common::hash01(3 * p + 2),
                common::hash01(3 * p + 3),
            ) * 2.0;
            let metallic = match i % 7 {
                2 => 1.0,
                5 => 0.5,
                _ => 0.0,
            };
            // A normal map: every third pixel's shading normal tilted by about 6°, every
            // eleventh by about 22° (past the 10° threshold: the diffuse part, testing geometric
            // normals, still takes it; the specular part does not); the tangent-plane test takes
            // the geometric normal.
            let tilt = match (p % 3, p % 11) {
                (_, 4) => 0.4,
                (1, _) => 0.1,
                _ => 0.0,
            };
            let shading = (normal + Vec4::new(normal.y, normal.x, 0.0, 0.0) * tilt)
                .truncate()
                .normalize_or_zero();
            let diffuse = radiance * noise;
            let specular = radiance * (0.5 + common::hash01(p + 3000));
            // Word 0..2: the diffuse plus the specular sum.
            s.sums.push(((diffuse + specular) * count).extend(count));
            // Metals carry no diffuse light: their diffuse sums are left out of the filter.
            let lit = if metallic < 1.0 { 1.0 } else { 0.0 };
            s.sums.push((specular * count).extend(lit));
            // Tangent sums: the diffuse colour times a direction tangent to the shading normal,
            // up to a third of the diffuse sum.
            let t = Vec3::new(
                common::hash01(p + 4000),
                common::hash01(p + 5000),
                common::hash01(p + 6000),
            ) - 0.5;
            let t = (t - shading * shading.dot(t)) * 0.6;
            for axis in 0..3 {
                s.sums.push((diffuse * t[axis] * count).extend(0.0));
            }
            let hit = position.w > 0.0 && p % 17 != 5;
            let z_min = 0.05 + common::hash01(p + 1000);
            s.depths.push(if hit {
                [z_min, z_min + 2.0 * common::hash01(p + 2000)]
            } else {
                [0.0, 0.0]
            });
            s.position.push(position);
            s.geometric_normal.push(q16(normal));
            s.normal.push(q16(shading.extend(0.0)));
            s.albedo
                .push(q8(Vec4::new(0.2 + 0.6 * u, 0.5, 0.8 - 0.5 * v, 1.0)));
            // Roughness steps along y and, by 0.15 (past the specular part's tolerance), along x.
            let roughness = 0.2 + 0.6 * v + 0.15 * ((i / 2) % 2) as f32;
            s.material
                .push(q8(Vec4::new(roughness.min(1.0), metallic, 0.0, 0.0)));
        }
    }
    s
}

/// What the GPU wrote: β and spp per pixel, and the indirect light.
struct GpuResult {
    widths: Vec<[f32; 2]>,
    indirect: Vec<Vec3>,
}

/// Runs `aaf_beta` and `aaf_filter` on the synthetic inputs.
fn run_gpu(device: &Device, s: &Synthetic, params: &AafParams) -> GpuResult {
    let e = EXTENT;
    let pixels = u64::from(e[0] * e[1]);
    let position = storage_image_with(
        device,
        "gb_position",
        vk::Format::R32G32B32A32_SFLOAT,
        e,
        bytemuck::cast_slice(&s.position),
    );
    let normal = storage_image_with(
        device,
        "gb_normal",
        vk::Format::R16G16B16A16_SFLOAT,
        e,
        &bytes_f16(&s.normal),
    );
    let geometric_normal = storage_image_with(
        device,
        "gb_geometric_normal",
        vk::Format::R16G16B16A16_SFLOAT,
        e,
        &bytes_f16(&s.geometric_normal),
    );
    let albedo = storage_image_with(
        device,
        "gb_albedo",
        vk::Format::R8G8B8A8_UNORM,
        e,
        &bytes_unorm8(&s.albedo),
    );
    let material = storage_image_with(
        device,
        "gb_material",
        vk::Format::R8G8B8A8_UNORM,
        e,
        &bytes_unorm8(&s.material),
    );
    let depths = transfer_storage(
        device,
        "depths",
        pixels * 8,
        Some(bytemuck::cast_slice(&s.depths)),
    );
    let sums = transfer_storage(
        device,
        "sums",
        pixels * aaf::SUMS_BYTES,
        Some(bytemuck::cast_slice(&s.sums)),
    );
    let widths_readback = transfer_storage(device, "widths readback", pixels * 8, None);
    let indirect_readback = transfer_storage(device, "indirect readback", pixels * 8, None);
    let mut executor = Executor::new(device, 1).expect("executor");
    let mut rg = executor.begin_frame();
    let import = |rg: &mut RenderGraph, image: &shine::gpu::Image| -> Handle<Image> {
        rg.import_gpu_image(image, uploaded_state(), ExternalState::UNDEFINED)
    };
    let unused = |rg: &mut RenderGraph, name: &str, format| {
        rg.create_image(name, shine::graph::ImageDesc::new_2d(format, e[0], e[1]))
    };
    let g = GBuffer {
        position: import(&mut rg, &position),
        normal: import(&mut rg, &normal),
        albedo: import(&mut rg, &albedo),
        material: import(&mut rg, &material),
        emissive: unused(&mut rg, "unused emissive", vk::Format::R16G16B16A16_SFLOAT),
        geometric_normal: import(&mut rg, &geometric_normal),
        motion: unused(
            &mut rg,
            "unused motion",
            shine::passes::gbuffer::MOTION_FORMAT,
        ),
        depth: unused(&mut rg, "unused depth", vk::Format::D32_SFLOAT),
        extent: e,
    };
    let depths = rg.import_gpu_buffer(&depths, uploaded_state(), ExternalState::UNDEFINED);
    let sums = rg.import_gpu_buffer(&sums, uploaded_state(), ExternalState::UNDEFINED);
    let widths =
        aaf::aaf_beta(&mut rg, &g, &depths, &camera(), SCENE_SIZE, params).expect("aaf_beta");
    let indirect =
        aaf::aaf_filter(&mut rg, &g, &sums, &widths, &camera(), params).expect("aaf_filter");
    let mut out = rg.import_gpu_buffer(&widths_readback, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_buffer("read widths", &widths, &mut out);
    let mut out =
        rg.import_gpu_buffer(&indirect_readback, ExternalState::UNDEFINED, read_by_copy());
    rg.copy_image_to_buffer("read indirect", &indirect, &mut out);
    let mut commands = device.begin_commands().expect("commands");
    executor.execute(commands.raw(), rg).expect("execute");
    device
        .submit(commands)
        .expect("submit")
        .wait()
        .expect("wait");
    let widths: Vec<[f32; 2]> =
        bytemuck::cast_slice(&device.read_buffer(&widths_readback).expect("read")).to_vec();
    let halves: Vec<u16> =
        bytemuck::cast_slice(&device.read_buffer(&indirect_readback).expect("read")).to_vec();
    let indirect = halves
        .chunks_exact(4)
        .map(|t| Vec3::new(f16_to_f32(t[0]), f16_to_f32(t[1]), f16_to_f32(t[2])))
        .collect();
    GpuResult { widths, indirect }
}

/// β and the sample count of every pixel equal shine-sh's eq. 15, 16 and 21 (through the CPU
/// twin), and the filtered, albedo-modulated light equals the CPU twin of the filter: the
/// quadratic fit and the paper's gaussian, each with the irradiance vector and with the paper's
/// scalar mean, two of them with a traced specular pass's limit.
#[test]
fn beta_spp_and_filter_match_the_cpu_twin() {
    let device = device();
    let s = synthetic();
    for (filter_degree, irradiance_vector, specular_limit) in [
        (2, true, 0.0),
        (0, false, 0.5),
        (0, true, 0.5),
        (2, false, 0.0),
    ] {
        let params = AafParams {
            filter_degree,
            irradiance_vector,
            specular_limit,
            ..AafParams::default()
        };
        matches_the_cpu_twin(&device, &s, &params);
    }
}

/// Runs `aaf_beta` and the filter on the GPU with `params` and checks them against the CPU
/// twin, pixel by pixel.
fn matches_the_cpu_twin(device: &Device, s: &Synthetic, params: &AafParams) {
    let params = *params;
    let gpu = run_gpu(device, s, &params);
    assert_clean(device);
    let footprint = aaf::footprint(&camera(), EXTENT[1]);
    let (mut filtered_pixels, mut clamped_spp) = (0, 0);
    for (p, got) in gpu.widths.iter().enumerate() {
        let material = [s.material[p].x, s.material[p].y];
        let want = beta_cpu(
            s.position[p].w,
            s.depths[p],
            material,
            footprint,
            SCENE_SIZE,
            &params,
        )
        .expect("beta");
        let beta_error = (got[0] - want[0]).abs() / want[0].max(1e-6);
        assert!(beta_error < 1e-4, "pixel {p}: β {} vs {}", got[0], want[0]);
        // ceil() of eq. 21 in f32 against f64 may differ by one sample at an integer.
        assert!(
            (got[1] - want[1]).abs() <= 1.0,
            "pixel {p}: spp {} vs {}",
            got[1],
            want[1]
        );
        filtered_pixels += usize::from(want[0] > 0.0);
        clamped_spp += usize::from(want[1] == params.spp_upper());
    }
    assert!(filtered_pixels > 250, "{filtered_pixels} pixels filtered");
    assert!(clamped_spp > 0, "no pixel reached the upper spp clamp");
    let texels: Vec<FilterTexel> = (0..s.position.len())
        .map(|p| FilterTexel {
            position: s.position[p],
            normal: s.normal[p].truncate(),
            geometric_normal: s.geometric_normal[p].truncate(),
            roughness: s.material[p].x,
            beta: gpu.widths[p][0],
            means: means(s, p),
        })
        .collect();
    let filtered = filter_cpu(&texels, EXTENT[0] as usize, footprint, &params);
    let (mut worst, mut changed) = (0.0f32, 0);
    for (p, got) in gpu.indirect.iter().enumerate() {
        let t = &texels[p];
        let want = if t.position.w == 0.0 {
            Vec3::ZERO
        } else {
            let n = t.normal.normalize();
            let v = (EYE - t.position.truncate()).normalize();
            let [roughness, metallic] = [s.material[p].x, s.material[p].y];
            let [kd, ks] = weights(
                s.albedo[p].truncate(),
                roughness,
                metallic,
                n.dot(v),
                params.specular_limit,
            );
            kd * filtered[p].diffuse_at(n) + ks * filtered[p].specular.max(Vec3::ZERO)
        };
        let error = (*got - want).abs().max_element() / want.max_element().max(1e-3);
        worst = worst.max(error);
        changed += usize::from(moved(&filtered[p], &t.means, t.normal.normalize()));
    }
    let degree = params.filter_degree;
    assert!(
        worst < 2e-3,
        "degree {degree}: worst relative error {worst}"
    );
    assert!(
        changed > 200,
        "degree {degree}: changed only {changed} pixels"
    );
}

/// The corner between the dim floor and the bright wall: the normal threshold and the
/// tangent-plane test keep the wall's light off the floor, whatever the fit's degree, with the
/// irradiance vector (geometric normals tested) or the paper's scalar mean (shading normals).
#[test]
fn the_filter_does_not_leak_across_surfaces() {
    for filter_degree in shine_sh::aaf::FILTER_DEGREES {
        for irradiance_vector in [true, false] {
            does_not_leak(&AafParams {
                filter_degree,
                irradiance_vector,
                ..AafParams::default()
            });
        }
    }
}

/// Filters the synthetic corner with a filter wide enough to cross the image and checks that
/// the floor's result does not depend on the wall.
fn does_not_leak(params: &AafParams) {
    let s = synthetic();
    let footprint = aaf::footprint(&camera(), EXTENT[1]);
    let texels: Vec<FilterTexel> = (0..s.position.len())
        .map(|p| FilterTexel {
            position: s.position[p],
            normal: s.normal[p].truncate(),
            geometric_normal: s.geometric_normal[p].truncate(),
            roughness: s.material[p].x,
            // Wide enough to reach across the whole image.
            beta: 10.0,
            means: means(&s, p),
        })
        .collect();
    let filtered = filter_cpu(&texels, EXTENT[0] as usize, footprint, params);
    // The same image without the wall (its pixels made background): the floor must not change.
    let floor = |t: &FilterTexel| t.position.w > 0.0 && t.normal.y > 0.5;
    let alone: Vec<FilterTexel> = texels
        .iter()
        .map(|t| {
            if floor(t) {
                *t
            } else {
                FilterTexel {
                    position: Vec4::ZERO,
                    ..*t
                }
            }
        })
        .collect();
    let filtered_alone = filter_cpu(&alone, EXTENT[0] as usize, footprint, params);
    let degree = params.filter_degree;
    let mut changed = 0;
    for (p, t) in texels.iter().enumerate().filter(|(_, t)| floor(t)) {
        assert_eq!(
            filtered[p], filtered_alone[p],
            "degree {degree}, floor pixel {p}: the wall's light leaked in"
        );
        changed += usize::from(moved(&filtered[p], &t.means, t.normal.normalize()));
    }
    assert!(
        changed > 100,
        "degree {degree}: the floor was barely filtered"
    );
}

/// A frame renderer of `scene` at 48² with `edit` applied to the settings; returns the
/// indirect radiance.
fn render_indirect(scene: &Scene, edit: impl Fn(&mut Settings)) -> Vec<Vec3> {
    let device = device();
    let mut renderer = Renderer::new(&device).expect("renderer");
    renderer.set_scene(scene, 0.0).expect("scene");
    let mut settings = Settings {
        width: 48,
        height: 48,
        gi: "aaf".parse::<GiTechniques>().expect("gi"),
        ..Settings::default()
    };
    settings.output.component = Component::Indirect;
    edit(&mut settings);
    let frame = renderer.render(&settings).expect("render");
    assert_clean(&device);
    frame
        .hdr
        .texels
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect()
}

/// Relative RMSE (RMSE / mean of the reference) and the energy ratio of `image`.
fn relative_error(image: &[Vec3], reference: &[Vec3]) -> (f32, f32) {
    let n = reference.len() as f32;
    let mean = reference.iter().map(|r| r.element_sum() / 3.0).sum::<f32>() / n;
    let mse = image
        .iter()
        .zip(reference)
        .map(|(a, b)| (*a - *b).length_squared() / 3.0)
        .sum::<f32>()
        / n;
    let energy = image.iter().map(|a| a.element_sum()).sum::<f32>()
        / reference.iter().map(|r| r.element_sum()).sum::<f32>();
    (mse.sqrt() / mean, energy)
}

/// The cornell box's AAF indirect light against the path tracer's one-bounce indirect light
/// from the punctual lights, and AAF against the unfiltered Monte-Carlo mean at the same
/// first-pass samples: the filter must reduce the error.
#[test]
fn cornell_box_against_the_path_tracer() {
    let scene = Scene::builtin("cornell-box").expect("scene");
    let device = device();
    let reference = render_reference(
        &device,
        &scene,
        0.0,
        &ReferenceParams {
            width: 48,
            height: 48,
            bounces: 1,
            jitter: false,
            emissive_lighting: false,
            ..ReferenceParams::default()
        },
        512,
    )
    .expect("reference");
    let truth: Vec<Vec3> = reference
        .indirect
        .texels
        .iter()
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    let filtered = render_indirect(&scene, |_| {});
    let unfiltered = render_indirect(&scene, |s| {
        s.aaf.adaptive = false;
        s.aaf.filter = false;
    });
    let (aaf_error, aaf_energy) = relative_error(&filtered, &truth);
    let (mc_error, mc_energy) = relative_error(&unfiltered, &truth);
    println!(
        "AAF: relative RMSE {aaf_error:.3}, energy {aaf_energy:.3}; \
         16 spp unfiltered: {mc_error:.3}, {mc_energy:.3}"
    );
    assert!(
        (0.93..=1.07).contains(&aaf_energy),
        "AAF energy {aaf_energy}"
    );
    assert!(
        (0.93..=1.07).contains(&mc_energy),
        "Monte-Carlo energy {mc_energy}"
    );
    assert!(
        aaf_error < 0.7 * mc_error,
        "AAF {aaf_error} vs unfiltered {mc_error}"
    );
}
