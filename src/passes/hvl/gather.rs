//! `hvl_gather` (and `hvl_regather`, amortised frames): every receiver shaded by the HVLs of
//! the cache (paper 003 §4.3, §6), after checking the inputs against the parameters.

use glam::Vec3;

use super::{
    Falloff, GatherHvl, GatherPath, GatherPush, HvlError, HvlParams, PrepPush, Window, cache_bytes,
    check_extent, shadows,
};
use crate::gpu::vk;
use crate::gpu_scene::bvh::TraceImages;
use crate::graph::{Buffer, Handle, Image, ImageDesc, PassCost, RenderGraph};
use crate::passes::amortise;
use crate::passes::brdf_tables::{
    GLOSSY_ROUGHNESS_MIN, GLOSSY_TABLES, GatherBrdf, glossy_roughness_step,
};
use crate::passes::receivers::Receivers;
use shadows::Shadowing;

/// Adds the `hvl_gather` pass: the `indirect` image (RGBA16F, receiver resolution, outgoing
/// radiance towards `camera` from all `params.count` HVLs, 0 on background), returned.
/// `records` holds the HVLs as [`hvl_gather_prep`] prepared them (once a frame, for the gather
/// and the regather).
/// `brdf` holds [`GatherBrdf::gpu_data`] at `params.conv_bands` bands (unused by the zonal
/// path); `bvh` is needed when `params.visibility` is set. `slice` 0 shades every receiver,
/// 1 + k one per 2×2 cell (the others are left undefined: `hvl_resolve` fills them). Sampled
/// shadow rays ([`shadows`]) add `hvl_shadow_filter`, whose output is returned.
#[allow(clippy::too_many_arguments)]
pub fn hvl_gather(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    records: &Handle<Image>,
    brdf: &Handle<Buffer>,
    bvh: Option<&TraceImages>,
    camera: Vec3,
    params: &HvlParams,
    slice: u32,
) -> Result<Handle<Image>, HvlError> {
    let (shader, inputs) = GatherInputs::checked(receivers, records, brdf, bvh, camera, params)?;
    let mut indirect = receivers.light_image(rg, "indirect");
    Ok(
        match record_gather(rg, shader, &inputs, params, &mut indirect, slice) {
            Some(unshadowed) => shadows::shadow_filter(
                rg,
                receivers,
                &indirect,
                &unshadowed,
                &params.shadows(),
                slice,
            ),
            None => indirect,
        },
    )
}

/// Adds `hvl_regather`: the gather at the receivers `hvl_regather_mask` marked in `target`
/// (alpha -1), written there (amortised frames, [`amortise`]), from the same `records` as the
/// frame's `hvl_gather`; sampled shadows take each receiver's own ratio there, unfiltered.
#[allow(clippy::too_many_arguments)]
pub fn hvl_regather(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    records: &Handle<Image>,
    brdf: &Handle<Buffer>,
    bvh: Option<&TraceImages>,
    camera: Vec3,
    params: &HvlParams,
    target: &mut Handle<Image>,
) -> Result<(), HvlError> {
    let (shader, inputs) = GatherInputs::checked(receivers, records, brdf, bvh, camera, params)?;
    record_gather(
        rg,
        shader,
        &inputs,
        params,
        target,
        amortise::REGATHER_SLICE,
    );
    Ok(())
}

/// What a gather pass reads.
struct GatherInputs<'a> {
    receivers: &'a Receivers,
    records: &'a Handle<Image>,
    brdf: &'a Handle<Buffer>,
    bvh: Option<&'a TraceImages>,
    camera: Vec3,
}

impl<'a> GatherInputs<'a> {
    /// The gather's shader and inputs after checking them against `params`: image extents,
    /// buffer sizes, a BVH when `params.visibility` is set.
    fn checked(
        receivers: &'a Receivers,
        records: &'a Handle<Image>,
        brdf: &'a Handle<Buffer>,
        bvh: Option<&'a TraceImages>,
        camera: Vec3,
        params: &HvlParams,
    ) -> Result<(&'static crate::gpu::ShaderDesc, Self), HvlError> {
        let shader = params.validate_gather()?;
        let bvh = match (params.visibility, bvh) {
            (true, None) => return Err(HvlError::NoBvh),
            (true, Some(b)) => Some(b),
            (false, _) => None,
        };
        for (name, image) in [
            ("recv_position", &receivers.position),
            ("recv_normal", &receivers.normal),
            ("recv_albedo", &receivers.albedo),
            ("recv_material", &receivers.material),
        ] {
            check_extent(name, image, receivers.extent)?;
        }
        let [need_w, need_h] = records_extent(params.count);
        let extent = records.desc().extent;
        if extent.width < need_w || extent.height < need_h {
            return Err(HvlError::Size {
                name: "hvl_records",
                actual: format!("{}×{} texels", extent.width, extent.height),
                expected: format!(
                    "at least {need_w}×{need_h} texels for {} HVLs",
                    params.count
                ),
            });
        }
        let table = GatherBrdf::gpu_bytes(params.conv_bands);
        if params.path == GatherPath::Full && brdf.desc().size != table {
            return Err(HvlError::Size {
                name: "brdf",
                actual: format!("{} bytes", brdf.desc().size),
                expected: format!(
                    "{table} bytes (GatherBrdf::gpu_data at {} bands)",
                    params.conv_bands
                ),
            });
        }
        let inputs = Self {
            receivers,
            records,
            brdf,
            bvh,
            camera,
        };
        Ok((shader, inputs))
    }
}

/// Records one gather pass of `slice` into `indirect`; with sampled shadows, returns the
/// unshadowed sum the `_shadows` variants also write.
fn record_gather(
    rg: &mut RenderGraph,
    shader: &'static crate::gpu::ShaderDesc,
    inputs: &GatherInputs<'_>,
    params: &HvlParams,
    indirect: &mut Handle<Image>,
    slice: u32,
) -> Option<Handle<Image>> {
    let (receivers, camera) = (inputs.receivers, inputs.camera);
    let [w, h] = receivers.extent;
    let push = GatherPush {
        camera: camera.extend(params.specular_limit).to_array(),
        extent: receivers.extent,
        hvl_count: params.count,
        emission_bands: params.emission_bands,
        roughness_nodes: [GLOSSY_ROUGHNESS_MIN, glossy_roughness_step()],
        glossy_tables: GLOSSY_TABLES,
        slice,
        window_width: match params.window {
            Window::None => 0.0,
            Window::Sinc => params.conv_bands as f32,
        },
        disc_falloff: u32::from(params.falloff == Falloff::Disc),
        shadow_rays: params.shadow_rays,
        seed: params.shadow_seed,
        near_range: params.near_radius,
        pad: [0; 3],
    };
    let name = if slice == amortise::REGATHER_SLICE {
        "hvl_regather"
    } else {
        "hvl_gather"
    };
    let threads = amortise::slice_threads([w, h], slice);
    let sampled = Shadowing::of(params.visibility, &params.shadows()) == Shadowing::Sampled;
    let mut unshadowed = sampled.then(|| receivers.light_image(rg, "hvl_unshadowed"));
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("hvl_records", inputs.records);
    if params.path == GatherPath::Full {
        pass.read("brdf", inputs.brdf);
    }
    if let Some(b) = inputs.bvh {
        b.bind(&mut pass);
    }
    if let Some(u) = unshadowed.as_mut() {
        pass.write("unshadowed", u);
    }
    if slice != amortise::REGATHER_SLICE {
        let [x, y, _] = threads;
        pass.cost(gather_cost(params, u64::from(x) * u64::from(y)));
    }
    pass.write("indirect", indirect)
        .push(&push)
        .dispatch(threads);
    unshadowed
}

/// Adds `hvl_gather_prep`: the first `params.count` HVLs of `hvls` as [`GatherHvl`] records in
/// a new RGBA32F image ([`RECORDS_PER_ROW`]), returned (per-HVL terms of the gather computed once a frame, read by
/// [`hvl_gather`] and [`hvl_regather`]; CPU twin [`crate::reference::hvl::gather_records`]).
pub fn hvl_gather_prep(
    rg: &mut RenderGraph,
    hvls: &Handle<Buffer>,
    params: &HvlParams,
) -> Result<Handle<Image>, HvlError> {
    params.validate_gather()?;
    let need = cache_bytes(params.count);
    if hvls.desc().size < need {
        return Err(HvlError::Size {
            name: "hvls",
            actual: format!("{} bytes", hvls.desc().size),
            expected: format!("at least {need} bytes for {} HVLs", params.count),
        });
    }
    let bytes = records_bytes(params);
    let [w, h] = records_extent(params.count);
    let mut records = rg.create_image(
        "hvl_records",
        ImageDesc::new_2d(vk::Format::R32G32B32A32_SFLOAT, w, h),
    );
    let push = PrepPush {
        count: params.count,
        emission_bands: params.emission_bands,
    };
    rg.compute("hvl_gather_prep", &crate::shaders::HVL_GATHER_PREP_COMP)
        .read("hvls", hvls)
        .write("hvl_records", &mut records)
        .push(&push)
        .cost(PassCost {
            // Per HVL: the emission polynomial (5 bands of 5 coefficients, 4 flops each, and
            // the band weights), the normal's normalisation and 1 / (π r²): about 130.
            flops: 130 * u64::from(params.count),
            bytes: cache_bytes(params.count) + bytes,
        })
        .dispatch([params.count, 1, 1]);
    Ok(records)
}

/// Floating-point operations of one receiver–HVL pair, counted from `hvl_gather.comp` (a fused
/// multiply-add is two, a square root, reciprocal or division one) for `b` convolution bands:
///
/// - common to both paths, 130: the vector to the HVL and its length (14), the two cosines
///   (11), the cap terms (59: `hvl_cap_terms` runs all of its branch-free form for every pair —
///   two 7-term `asin` polynomials with their square roots (36), the inside cosine's
///   polynomial (12), r/d, cos a, eq. 22's argument and smoothstep (11)), G (2), the near
///   field's weight (7), the emission polynomial (9), the light L_j (4), the clamped
///   contribution and its sum (24);
/// - the cap's ZH, `7 (b - 1) + 2`: the Legendre recurrence (5 per band) and the ZH (2 per band);
/// - full path: the direction in the receiver frame (10), the basis at m ≥ 0
///   (`7 (b - 1) + 3.5 b (b - 1) / 2 + b (b - 1)`: the (x + iy)^m recurrence, the normalised
///   Legendre recurrence, the √2 cos mφ factors) and the two products with the BRDF rows
///   (`b (b + 1) + 5 b`);
/// - zonal path: the Legendre recurrence at the receiver's cosine and the ZH product,
///   `5 (b - 1) + 3 b`;
/// - sampled shadows add the unshadowed sum and weights and the stratum's reservoir (the mean
///   weight, its sums, the random number's scale and the take test), 10 per pair.
///
/// Every pair is counted as lit: a SIMD group runs the whole path whenever one of its lanes
/// does. The shadow rays' traversal is not counted (it depends on the scene's BVH).
pub fn gather_pair_flops(path: GatherPath, b: u32, sampled_shadows: bool) -> u64 {
    let b = u64::from(b.max(1));
    let cap = 7 * (b - 1) + 2;
    let specific = match path {
        GatherPath::Full => {
            10 + 7 * (b - 1) + (7 * b * (b - 1)) / 4 + b * (b - 1) + b * (b + 1) + 5 * b
        }
        GatherPath::Zonal => 5 * (b - 1) + 3 * b,
    };
    130 + cap + specific + if sampled_shadows { 10 } else { 0 }
}

/// The gather's [`PassCost`] over `receivers` receivers: `receivers × count ×`
/// [`gather_pair_flops`]; bytes: per receiver its four G-buffer texels (16 + 8 + 4 + 4) and its
/// RGBA16F output (8, and 8 more for the unshadowed sum of sampled shadows), plus the HVL
/// records and the BRDF tables once (a few kilobytes every workgroup then reads from cache).
pub fn gather_cost(params: &HvlParams, receivers: u64) -> PassCost {
    let sampled = Shadowing::of(params.visibility, &params.shadows()) == Shadowing::Sampled;
    let pairs = receivers * u64::from(params.count);
    let per_receiver = 32 + if sampled { 16 } else { 8 };
    let tables = match params.path {
        GatherPath::Full => GatherBrdf::gpu_bytes(params.conv_bands),
        GatherPath::Zonal => 0,
    };
    PassCost {
        flops: pairs * gather_pair_flops(params.path, params.conv_bands, sampled),
        bytes: receivers * per_receiver + records_bytes(params) + tables,
    }
}

/// Texels of a [`GatherHvl`] record in the records image, one per field.
pub const RECORD_TEXELS: u32 = 5;

/// Records per row of the records image (`HVL_RECORDS_PER_ROW` of `shaders/include/hvl.glsl`):
/// record `j` is texels `RECORD_TEXELS · (j mod RECORDS_PER_ROW) + field` of row
/// `j / RECORDS_PER_ROW`. An image, not a storage buffer: llvmpipe loads an image texel about
/// 4× faster than a storage buffer's vec4, and the gather loads four per receiver–HVL pair
/// (docs/performance.md). 512 keeps a row of five-texel records within 4096 texels, the
/// least `maxImageDimension2D` Vulkan allows.
pub const RECORDS_PER_ROW: u32 = 512;

/// Width and height in texels of the records image of `count` HVLs.
pub fn records_extent(count: u32) -> [u32; 2] {
    let count = count.max(1);
    [
        RECORD_TEXELS * count.min(RECORDS_PER_ROW),
        count.div_ceil(RECORDS_PER_ROW),
    ]
}

/// Bytes of the [`GatherHvl`] records of `params.count` HVLs.
fn records_bytes(params: &HvlParams) -> u64 {
    u64::from(params.count.max(1)) * std::mem::size_of::<GatherHvl>() as u64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::passes::hvl::MAX_HVLS;

    /// Rows hold whole records, so texel `RECORD_TEXELS · j + field` read row by row is
    /// field `field` of record `j`; the largest cache fits the smallest allowed image.
    #[test]
    fn records_extent_rows_of_whole_records() {
        assert_eq!(records_extent(1), [5, 1]);
        assert_eq!(records_extent(400), [2000, 1]);
        assert_eq!(records_extent(RECORDS_PER_ROW), [2560, 1]);
        assert_eq!(records_extent(RECORDS_PER_ROW + 1), [2560, 2]);
        let [w, h] = records_extent(MAX_HVLS);
        assert!(w <= 4096 && h <= 4096, "{w}×{h}");
        assert!(u64::from(w) * u64::from(h) >= u64::from(RECORD_TEXELS * MAX_HVLS));
    }
}
