//! Axis-aligned filtering of path-traced indirect light (paper 004): the `aaf_sample_first`,
//! `aaf_beta`, `aaf_sample_second`, `aaf_filter_x` and `aaf_filter_y` passes.
//!
//! 1. **First pass** (`shaders/aaf_sample.comp`, variant `first`): at every G-buffer pixel,
//!    [`AafParams::first_samples`] stratified, cosine-weighted rays about the shading normal
//!    through the BVH; each hit's outgoing radiance `L` is next-event estimation to the
//!    punctual lights (one bounce; [`AafParams::bounces`] > 1 continues the path by BRDF
//!    sampling, as the path tracer). A sample adds `π f_d(l, v) L / kd` to the pixel's diffuse
//!    sum and `π f_s(l, v) L / ks` to its specular sum (`f_d + f_s` the receiver's BRDF, `kd`,
//!    `ks` its demodulation weights), so that for a Lambertian receiver the diffuse mean is the
//!    irradiance over π, the quantity the paper filters. The directions are a digitally
//!    shifted (0, 2)-sequence per pixel (`sobol_02`, shaders/include/random.glsl): the first 16
//!    form a 4×4 stratification and every sample count stays stratified. The nearest and
//!    farthest hit distances are `z_min`, `z_max`.
//! 2. **Filter width and sampling rate** (`aaf_beta.comp`, GLSL twin of [`shine_sh::aaf`] in
//!    `shaders/include/aaf.glsl`): `Ω_x^r = μ min(Ω_h/z_min, α/d)` (eq. 15), `β = 2/Ω_x^r`
//!    (eq. 16), `n = γ (μ Ω_h d/z_min + α)² Ω_h² (1 + μ z_max/z_min)²` (eq. 21) clamped to
//!    `[spp_min, spp_max·μ]`, with `d` the pixel's world-space footprint and `z_min` clamped
//!    from below to [`AafParams::z_min_fraction`] of the scene's largest side ([`scene_size`]);
//!    a pixel whose first rays all escaped takes `z_min = z_max =` that size. Ω_h is the receiver's
//!    ([`shine_sh::aaf::receiver_bandlimit`]): [`AafParams::omega_h`] for dielectrics, blended
//!    by `metallic` towards the appendix's Blinn-Phong bandlimit `3.6 + 0.084 m` (eq. 24) with
//!    `m = 2/α² − 2` from the GGX roughness (Walter et al. 2007), `m ≤ 50` (the fit's range).
//! 3. **Second pass** (variant `second`): each pixel's remaining `n − first_samples` samples,
//!    the sequence's next points, added to the first pass's sums.
//! 4. **Filter** (`aaf_filter.comp`, variants `x` then `y`): per pass, a weighted least-squares
//!    fit of a polynomial of degree [`AafParams::filter_degree`] along the axis to the diffuse
//!    and, apart, the specular means ([`shine_sh::aaf::LocalFit`]), with the paper's gaussian
//!    weights of standard deviation `β` of the centre pixel over world-space distances (above
//!    degree 0, the columns' pass also weights each row by its row fit's precision),
//!    neighbours only within the normal threshold (paper: 10°) and near the centre's geometric
//!    tangent plane, the specular means only of neighbours within [`ROUGHNESS_TOLERANCE`] of the
//!    centre's roughness; then the receiver's weights `kd` and `ks (1 − trace_weight)` (the
//!    albedo modulation after filtering). Degree 0 is the paper's normalised gaussian (eq. 16).
//!
//! # Decisions and deviations from paper 004
//!
//! * Direct light stays the raster's; AAF computes the indirect term only. The receiver's whole
//!   metallic-roughness BRDF weights the samples (with cosine-weighted directions), demodulated
//!   by `kd` and `ks` (`brdf_indirect_weights`, as HVL and IGI) so the filter smooths what is
//!   smooth: without the specular part the cornell box lost 16% of its indirect energy against
//!   the path tracer (rough dielectrics, F0 = 0.04). Sharp metallic lobes are sampled with
//!   cosine-weighted directions (noisy) and filtered with their glossy β.
//! * The filter's world-distance test (not in the paper, which tests normals only): a neighbour
//!   farther than [`PLANE_TOLERANCE`] pixel footprints from the centre's tangent plane is left
//!   out, so light does not leak between parallel surfaces at different depths. The plane is
//!   the geometric one: a normal map's tilted shading normal put coplanar neighbours a few
//!   pixels away off its plane and cut the room's tiled floor into tile-sized filters.
//! * The gaussian is cut at 2β or [`MAX_RADIUS`] pixels, whichever is smaller.
//! * **The filter fits a quadratic by default** (`filter_degree = 2`; 0 is the paper's
//!   gaussian). The paper's gaussian passes frequencies at half its bandwidth `Ω_x^r` at 61%
//!   and flattens every peak of the light by `O(β²)`; where the normal and plane tests or the
//!   image's border leave neighbours on one side only, it also tilts the light by `O(β)`. The
//!   Cornell box's ceiling, lit from the floor's spot, lost its peak to that bias: at 128² the
//!   gaussian's error floor (filtered uniform Monte Carlo at 256 spp) was 0.27 of the mean,
//!   the quadratic fit's is 0.09, and the samples saved at equal error rose from 1.3× to 6.1×
//!   (5.3× from 3.3× on the animated scene). Where the tests cut the filters into small pieces
//!   a quadratic over few neighbours removes less noise than the gaussian: the room's
//!   normal-mapped floor did so until the irradiance vector (below). The weights, β and the
//!   sampling rates are the paper's. The light evaluated from the fits is clamped at zero.
//! * **Diffuse and specular apart** (as the paper's §6 computes rates and filters "separately
//!   for the diffuse and glossy components"): the diffuse mean is the same light whatever the
//!   material, so a glossy tile and its rough grout share it; their specular means differ (a
//!   lobe's mean depends on its width) and are filtered only among similar roughnesses. The
//!   specular part is weighted by `ks (1 − trace_weight)`, the share the frame's traced specular
//!   pass leaves ([`AafParams::specular_limit`]). One mean demodulated by `kd + ks (1 −
//!   trace_weight)`, as before, mixed the grout's and the tiles' different weightings of the
//!   light: with the stratified samples, the room's filtered error floor went from 0.143 to
//!   0.086 (docs/quality.md).
//! * **The diffuse part as an irradiance vector** ([`AafParams::irradiance_vector`], on by
//!   default): each pixel's `V = M₀ n + (8/3) M₁ₜ` ([`shine_sh::aaf::TANGENT_SCALE`]) is
//!   filtered (nine channels), the neighbours' geometric normals tested against the threshold,
//!   and `V · n` evaluated at each pixel's shading normal. With the paper's scalar mean, the
//!   room's bevelled tiles (normal map, 31° slopes) fail the 10° shading-normal test against
//!   their flat neighbours, so every bevel and every tile was filtered alone at eq. 21's 16
//!   samples; testing geometric normals with the scalar mean instead blurs away the normal
//!   map's real detail in the indirect light. The vector keeps both: the room's samples saved at
//!   equal error rose from 2.6× to 5.7× (docs/quality.md). Where a pixel's neighbours share its
//!   shading normal (no normal map, flat faces), `V · n` is the scalar filter's result; on
//!   smooth-shaded curved surfaces the geometric normals now decide which neighbours count. The
//!   vector is first order in the tilt: at the room's 31° bevels it misses up to 14% of the
//!   light's constant part (the energy reads 1.015 there).
//! * **Rows weighted by their precision** (above degree 0): the rows' pass leaves some rows
//!   fitted from many neighbours and others from few (at the image's border, beside an edge, a
//!   quadratic extrapolated from one side), and the columns' pass weights each row by the
//!   inverse of its fit's noise variance ([`shine_sh::aaf::LocalFit::precision`]), the weighted
//!   least squares of values of unequal noise. Rows are independent of each other (the rows'
//!   pass reads each pixel once per row), so the weights are exact up to the pixels' own noise,
//!   which the rows' pass takes as equal: weighting pixels by their sample counts as well pulls
//!   each fit towards the pixels eq. 21 gave more samples, those with nearer reflectors and
//!   faster-changing light, and raised the Cornell box's error at μ = 0.9 from 0.0996 to 0.105.
//!   The rows' precisions cut it to 0.0955 (docs/quality.md).
//! * **Path regularisation at the hits** ([`AafParams::hit_roughness_min`]): a hit's BRDF is
//!   evaluated no sharper than roughness 0.5, so a point light's highlight on chrome does not
//!   turn into caustic fireflies that no sample count averages out.
//! * The emission of emissive surfaces and the environment light nothing (punctual lights only,
//!   the convention of every raster GI technique).

use crate::gpu_scene::SceneHandles;
use crate::gpu_scene::bvh::TraceImages;
use crate::graph::{Buffer, BufferDesc, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::amortise;
use crate::passes::gbuffer::{GBuffer, View};
use crate::shaders;

mod params;

pub use params::*;

/// The world-space size `d` of a pixel at linear view depth `z` is `z · scale + bias`:
/// `2 tan(fov/2) / H` and 0 for a perspective camera, 0 and `width / H` for an orthographic one.
pub fn footprint(camera: &View, height: u32) -> [f32; 2] {
    let h = height.max(1) as f32;
    if camera.orthographic {
        [0.0, camera.extent / h]
    } else {
        [2.0 * (0.5 * camera.extent).tan() / h, 0.0]
    }
}

/// The scene's size S for AAF: its bounds' largest side (paper 004 §5: z_min is clamped to
/// "about 2% of maximum scene dimension").
pub fn scene_size(bounds: (glam::Vec3, glam::Vec3)) -> f32 {
    (bounds.1 - bounds.0).max_element()
}

/// Push constants of `shaders/aaf_sample.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SamplePush {
    /// Width, height, light count, seed.
    pub frame: [u32; 4],
    /// Bounces, samples of the first pass, the pixels sampled ([`AafSlice::slice`]), the bits
    /// of [`AafParams::hit_roughness_min`].
    pub config: [u32; 4],
    /// xyz camera position, w padding.
    pub camera: [f32; 4],
}

/// Push constants of `shaders/aaf_beta.comp` (64 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BetaPush {
    /// Image size.
    pub extent: [u32; 2],
    /// [`footprint`].
    pub footprint: [f32; 2],
    /// Ω_h, α, μ, γ.
    pub paper: [f32; 4],
    /// Lower clamp of z_min (world units), spp_min, spp_upper, the scene's size.
    pub clamps: [f32; 4],
    /// The pixels computed ([`AafSlice::slice`]).
    pub slice: u32,
    /// Padding.
    pub pad: [u32; 3],
}

/// Push constants of `shaders/aaf_filter.comp` (64 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FilterPush {
    /// xyz camera position, w cos of the normal threshold.
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// [`footprint`].
    pub footprint: [f32; 2],
    /// [`PLANE_TOLERANCE`].
    pub plane_tolerance: f32,
    /// [`MAX_RADIUS`].
    pub max_radius: u32,
    /// 1: filter; 0: pass the mean through.
    pub enabled: u32,
    /// The specular pass's roughness limit ([`AafParams::specular_limit`]).
    pub specular_limit: f32,
    /// [`AafParams::filter_degree`].
    pub degree: u32,
    /// [`ROUGHNESS_TOLERANCE`].
    pub roughness_tolerance: f32,
    /// [`AafParams::irradiance_vector`].
    pub irradiance_vector: u32,
    /// Padding.
    pub pad: u32,
}

/// The scene as the AAF rays see it.
#[derive(Debug, Clone, Copy)]
pub struct AafScene<'a> {
    /// The scene's buffers and textures.
    pub handles: &'a SceneHandles,
    /// Its BVH.
    pub bvh: &'a TraceImages,
    /// Lights in the light buffer.
    pub light_count: u32,
    /// [`scene_size`] of the scene's bounds (the z_min clamp, and the reflector distance of a
    /// pixel whose first rays all escaped).
    pub size: f32,
    /// The sampler of the scene's textures.
    pub texture_sampler: vk::Sampler,
}

/// The AAF passes' outputs.
#[derive(Debug, Clone, Copy)]
pub struct AafOutputs {
    /// Indirect light (RGBA16F, full resolution): `kd` × the filtered diffuse part at the
    /// shading normal plus `ks (1 − trace_weight)` × the filtered specular mean.
    pub indirect: Handle<Image>,
    /// Per pixel: the samples' sums ([`SUMS_STRIDE`] vec4).
    pub sums: Handle<Buffer>,
    /// Per pixel: z_min, z_max of the first pass (vec2).
    pub depths: Handle<Buffer>,
    /// Per pixel: β (world units), samples per pixel (vec2).
    pub widths: Handle<Buffer>,
}

/// Adds the AAF passes over the G-buffer `g` seen from `camera`; returns the indirect light and
/// the intermediate buffers (for tests and the study).
pub fn aaf(
    rg: &mut RenderGraph,
    g: &GBuffer,
    scene: &AafScene<'_>,
    camera: &View,
    params: &AafParams,
) -> Result<AafOutputs, AafError> {
    let samples = aaf_sample(rg, g, scene, camera, params, AafSlice::default())?;
    let indirect = aaf_filter(rg, g, &samples.sums, &samples.widths, camera, params)?;
    Ok(AafOutputs {
        indirect,
        sums: samples.sums,
        depths: samples.depths,
        widths: samples.widths,
    })
}

/// Which pixels one run of AAF's sampling passes samples, and into which buffers: paper 001's
/// amortised frames (`aaf.slices`, [`crate::passes::amortise`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct AafSlice {
    /// 0: every pixel; 1 + k: the pixel at (k & 1, k >> 1) of every 2×2 cell;
    /// [`amortise::REGATHER_SLICE`]: the pixels `marks` marks with alpha −1.
    pub slice: u32,
    /// The marks of `aaf_reproject`; required by the regather slice.
    pub marks: Option<Handle<Image>>,
    /// The sums and widths buffers to write (the amortised frame's records; `None`: new ones).
    pub into: Option<AafRecords>,
}

/// AAF's per-pixel records: what the filter reads.
#[derive(Debug, Clone, Copy)]
pub struct AafRecords {
    /// [`SUMS_STRIDE`] vec4 per pixel: the samples' sums and their count.
    pub sums: Handle<Buffer>,
    /// vec2 per pixel: β, samples per pixel ([`aaf_beta`]).
    pub widths: Handle<Buffer>,
}

/// vec4 per pixel of [`AafRecords::sums`] (`AAF_SUMS_STRIDE` of aaf.glsl): the diffuse plus the
/// specular sum (rgb: the amortised change test's signal, [`amortise::RecordSignal::MeanRgb`])
/// and the samples taken, then the specular sum (rgb) and 1 where the receiver's `kd`
/// carries light ([`crate::reference::aaf::WEIGHT_MIN`]), then the sums of the diffuse samples
/// times the x, y and z of their direction's part tangent to the shading normal (rgb each).
pub const SUMS_STRIDE: u64 = 5;
/// vec4 per pixel of the filter's rows (`AAF_ROWS_STRIDE`): the irradiance vector's x, y, z
/// columns (the w of the first two: the diffuse and the specular row fit's precision, which
/// the columns' pass weights each row by), then the specular mean and the diffuse part's flag.
pub const ROWS_STRIDE: u64 = 4;
/// Bytes per pixel of [`AafRecords::sums`].
pub const SUMS_BYTES: u64 = 16 * SUMS_STRIDE;
/// Bytes per pixel of [`AafRecords::widths`] (and of the depths).
pub const WIDTHS_BYTES: u64 = 8;

/// What [`aaf_sample`] returns.
#[derive(Debug, Clone, Copy)]
pub struct AafSamples {
    /// The sums the filter reads.
    pub sums: Handle<Buffer>,
    /// The first pass's z_min, z_max.
    pub depths: Handle<Buffer>,
    /// β and the sample counts.
    pub widths: Handle<Buffer>,
}

/// Adds the sampling half of AAF at the pixels of `slice`: `aaf_sample_first`, `aaf_beta` and
/// (adaptive) `aaf_sample_second`, named `aaf_resample_*` and `aaf_rebeta` for the regather
/// slice. The sums and widths are valid at those pixels.
pub fn aaf_sample(
    rg: &mut RenderGraph,
    g: &GBuffer,
    scene: &AafScene<'_>,
    camera: &View,
    params: &AafParams,
    slice: AafSlice,
) -> Result<AafSamples, AafError> {
    params.validate()?;
    params.check_extent(g.extent)?;
    amortise::check_slice(slice.slice, slice.marks.is_some())?;
    let regather = slice.slice == amortise::REGATHER_SLICE;
    let [w, h] = g.extent;
    let pixels = u64::from(w) * u64::from(h);
    let sample_push = SamplePush {
        frame: [w, h, scene.light_count, params.seed],
        config: [
            params.bounces,
            params.first_samples,
            slice.slice,
            params.hit_roughness_min.to_bits(),
        ],
        camera: camera.eye.extend(0.0).to_array(),
    };
    let into = match slice.into {
        Some(r) => r,
        None => AafRecords {
            sums: rg.create_buffer("aaf_sums", BufferDesc::new(pixels * SUMS_BYTES)),
            widths: rg.create_buffer("aaf_widths", BufferDesc::new(pixels * WIDTHS_BYTES)),
        },
    };
    // Read only by the regather slice; the G-buffer's normals (any full-resolution RGBA16F
    // image the frame writes) fill the binding of the others.
    let marks = slice.marks.unwrap_or(g.normal);
    let threads = amortise::slice_threads(g.extent, slice.slice);
    let name = |first: &'static str, again: &'static str| if regather { again } else { first };
    let mut first = if params.adaptive {
        rg.create_buffer("aaf_sums_first", BufferDesc::new(pixels * SUMS_BYTES))
    } else {
        into.sums
    };
    let mut depths = rg.create_buffer("aaf_depths", BufferDesc::new(pixels * WIDTHS_BYTES));
    sample_pass(
        rg,
        name("aaf_sample_first", "aaf_resample_first"),
        &shaders::AAF_SAMPLE_COMP_FIRST,
        g,
        scene,
    )
    .read("marks", &marks)
    .write("sums", &mut first)
    .write("depths", &mut depths)
    .push(&sample_push)
    .dispatch(threads);
    let mut widths = into.widths;
    rg.compute(name("aaf_beta", "aaf_rebeta"), &shaders::AAF_BETA_COMP)
        .read("gb_position", &g.position)
        .read("gb_material", &g.material)
        .read("depths", &depths)
        .read("marks", &marks)
        .write("filter_widths", &mut widths)
        .push(&beta_push(g, camera, scene.size, params, slice.slice))
        .dispatch(threads);
    let sums = if params.adaptive {
        let mut second = into.sums;
        sample_pass(
            rg,
            name("aaf_sample_second", "aaf_resample_second"),
            &shaders::AAF_SAMPLE_COMP_SECOND,
            g,
            scene,
        )
        .read("first_sums", &first)
        .read("filter_widths", &widths)
        .read("marks", &marks)
        .write("sums", &mut second)
        .push(&sample_push)
        .dispatch(threads);
        second
    } else {
        first
    };
    Ok(AafSamples {
        sums,
        depths,
        widths,
    })
}

/// Adds `aaf_beta`: per pixel of `g`, β (world units) and the sample count (eq. 15, 16, 21)
/// from the first pass's `depths` (vec2 z_min, z_max per pixel); z_min is clamped to
/// `z_min_fraction × scene_size`. Returns the widths buffer (vec2 per pixel).
pub fn aaf_beta(
    rg: &mut RenderGraph,
    g: &GBuffer,
    depths: &Handle<Buffer>,
    camera: &View,
    scene_size: f32,
    params: &AafParams,
) -> Result<Handle<Buffer>, AafError> {
    params.validate()?;
    let [w, h] = g.extent;
    let mut widths = rg.create_buffer(
        "aaf_widths",
        BufferDesc::new(u64::from(w) * u64::from(h) * WIDTHS_BYTES),
    );
    rg.compute("aaf_beta", &shaders::AAF_BETA_COMP)
        .read("gb_position", &g.position)
        .read("gb_material", &g.material)
        .read("depths", depths)
        .read("marks", &g.normal)
        .write("filter_widths", &mut widths)
        .push(&beta_push(g, camera, scene_size, params, 0))
        .dispatch([w, h, 1]);
    Ok(widths)
}

/// The push constants of `aaf_beta` at the pixels of `slice`.
fn beta_push(
    g: &GBuffer,
    camera: &View,
    scene_size: f32,
    params: &AafParams,
    slice: u32,
) -> BetaPush {
    BetaPush {
        extent: g.extent,
        footprint: footprint(camera, g.extent[1]),
        paper: [params.omega_h, params.alpha, params.mu, params.gamma],
        clamps: [
            params.z_min_fraction * scene_size,
            params.spp_min as f32,
            params.spp_upper(),
            scene_size,
        ],
        slice,
        pad: [0; 3],
    }
}

/// Adds `aaf_filter_x` and `aaf_filter_y`: the separable filter of the diffuse and specular
/// means of `sums` ([`SUMS_STRIDE`] vec4 per pixel) with the widths of [`aaf_beta`], then the
/// receivers' weights ([`crate::reference::aaf::weights`]).
/// Returns the indirect light (RGBA16F).
pub fn aaf_filter(
    rg: &mut RenderGraph,
    g: &GBuffer,
    sums: &Handle<Buffer>,
    widths: &Handle<Buffer>,
    camera: &View,
    params: &AafParams,
) -> Result<Handle<Image>, AafError> {
    params.validate()?;
    params.check_extent(g.extent)?;
    let [w, h] = g.extent;
    let push = FilterPush {
        camera: camera
            .eye
            .extend(params.normal_threshold_degrees.to_radians().cos())
            .to_array(),
        extent: g.extent,
        footprint: footprint(camera, h),
        plane_tolerance: PLANE_TOLERANCE,
        max_radius: MAX_RADIUS,
        enabled: u32::from(params.filter),
        specular_limit: params.specular_limit,
        degree: params.filter_degree,
        roughness_tolerance: ROUGHNESS_TOLERANCE,
        irradiance_vector: u32::from(params.irradiance_vector),
        pad: 0,
    };
    let mut rows = rg.create_buffer(
        "aaf_rows",
        BufferDesc::new(u64::from(w) * u64::from(h) * 16 * ROWS_STRIDE),
    );
    rg.compute("aaf_filter_x", &shaders::AAF_FILTER_COMP_X)
        .read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_geometric_normal", &g.geometric_normal)
        .read("filter_widths", widths)
        .read("sums", sums)
        .read("gb_material", &g.material)
        .write("filtered", &mut rows)
        .push(&push)
        .dispatch([w, h, 1]);
    let mut indirect = rg.create_image(
        "aaf_indirect",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    rg.compute("aaf_filter_y", &shaders::AAF_FILTER_COMP_Y)
        .read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_geometric_normal", &g.geometric_normal)
        .read("filter_widths", widths)
        .read("filtered", &rows)
        .read("gb_albedo", &g.albedo)
        .read("gb_material", &g.material)
        .write("indirect", &mut indirect)
        .push(&push)
        .dispatch([w, h, 1]);
    Ok(indirect)
}

/// A sampling pass with the scene, BVH and G-buffer bound.
fn sample_pass<'a>(
    rg: &'a mut RenderGraph,
    name: &str,
    shader: &'static crate::gpu::ShaderDesc,
    g: &GBuffer,
    scene: &AafScene<'_>,
) -> crate::graph::ComputePass<'a> {
    let mut pass = rg.compute(name, shader);
    crate::passes::traced_scene::bind_surfaces(
        &mut pass,
        scene.handles,
        scene.texture_sampler,
        scene.bvh,
    );
    pass.read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_geometric_normal", &g.geometric_normal)
        .read("gb_albedo", &g.albedo)
        .read("gb_material", &g.material);
    pass
}
