//! Harmonics Virtual Lights (paper 003): the `hvl_cache` and `hvl_gather` passes.
//!
//! * [`hvl_cache`] turns the reflective shadow map of one primary light into `M = K²` HVLs
//!   (spherical secondary lights, §5.2) stored as [`Hvl`] records, with radius heuristic r1
//!   (eq. 23) or r2 (eq. 24–26) times a user scale, and the sender's SH emission (eq. 20).
//! * [`hvl_gather`] sums, at every receiver, the outgoing radiance towards the camera due to
//!   every HVL (eq. 1, 3, 19–22): the full O(n²) SH path with the receiver's BRDF SH tables
//!   (Lambert + a glossy table, [`GatherBrdf`]) or the O(n) zonal path (Lambert only, §6.3).
//!
//! The CPU twin of both passes is [`crate::hvl_reference`]; docs/frame.md, section "Indirect
//! light", fixes the formats and units.
//!
//! # Decisions and deviations from paper 003
//!
//! * **Construction.** The paper renders HVL data into the RSM (its "HVL cache", e.g. 1024²
//!   texels for 400 HVLs) and takes M HVLs from it; we sample the RSM on a regular K×K grid (K = √M): each cell gives one HVL at its valid texel nearest the cell
//!   centre, carrying the summed flux of all the cell's valid texels (so the reflected power
//!   is the same for every M; the paper's Φ_j is "the light's power divided by the number of
//!   HVLs"). r1's "8-connected neighbours in the cache" are the neighbours in this grid.
//! * **Emission.** RSM senders are Lambertian with the albedo already in the flux, so the
//!   sender's `F'` (eq. 20) is `1/π` over the hemisphere: a ZH vector about `n_j`, identical to
//!   the Lambert (albedo 1) row of [`shine_sh::brdf_table::BrdfTable::f_prime`] for every θ_l.
//!   Each record stores it (5 bands), the gather reconstructs `F'·Y(-ω_j)` to the emission band
//!   count of its variant and clamps it at 0 (band-limited ringing).
//! * **Visibility** is not computed: HVLs are unshadowed, as in the paper's results (§6).
//! * **Ringing.** Each HVL's contribution is clamped at 0 per channel so band-limited ringing
//!   never makes `indirect` negative; the paper's sinc window (§4.2) is not applied.
//! * **Receiver BRDF.** `kd = albedo (1 - metallic)` times Lambert, `ks = mix(1, albedo,
//!   metallic)` times ONE glossy table (GGX of a fixed α and η, built by [`GatherBrdf::build`]);
//!   the receiver's roughness does not select a table yet (the paper indexes one table per
//!   material). The zonal path has the Lambert term only.
//! * `emission_bands ≤ conv_bands`, and only the band pairs compiled as variants of
//!   `shaders/hvl_gather.comp` exist ([`gather_variants`]).
//!
//! # Accuracy
//!
//! One HVL against a quadrature of eq. 3 with eq. 19–21 (`tests/hvl.rs`, worst relative error
//! over 8 receivers, GGX α = 0.5 glossy): the SH truncation of the convolution alone is 4.9% at
//! 3 bands, 2.9% at 5, 0.8% at 9 (zonal: 5.8% at 3, 0.8% at 9); with the exact Lambert emission
//! as reference the total is 31–33% with 3 emission bands (the band-limited `F'·Y` overshoots
//! near the sender's normal, the paper's choice) and 19–21% with 5.

use glam::Vec3;
use shine_sh::brdf_table::{BrdfModel, BrdfTable, HemisphereSampling};

use crate::gpu::ShaderDesc;
use crate::graph::{Buffer, BufferDesc, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::shaders;

pub use super::receivers::Receivers;

/// Most emission bands an [`Hvl`] stores (paper 003 §3 uses 0–5 bands for the emission).
pub const EMISSION_MAX_BANDS: usize = 5;

/// One HVL of the cache, the GPU record (std430, 80 bytes; `struct Hvl` of
/// `shaders/include/hvl.glsl`, size checked against the compiled shader by a test).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Hvl {
    /// xyz: world position `y_j` of the HVL centre; w: radius `r_j` (scaled), 0 for an empty
    /// cell.
    pub position_radius: [f32; 4],
    /// xyz: unit normal `n_j`; w: distance `d_j` to the primary light.
    pub normal_distance: [f32; 4],
    /// rgb: flux `Φ_j` (W); a: 1 for a valid HVL, 0 for an empty cell.
    pub flux: [f32; 4],
    /// ZH coefficients (about `n_j`) of the sender's `F'` (eq. 20); [`EMISSION_MAX_BANDS`]
    /// used, the rest zero padding.
    pub emission: [f32; 8],
}

impl Hvl {
    /// Whether the record holds a light (an empty RSM cell gives an invalid one).
    pub fn is_valid(&self) -> bool {
        self.flux[3] != 0.0
    }
}

/// Push constants of `shaders/hvl_cache.comp` (both stages), 32 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CachePush {
    /// xyz: primary light position; w: RSM field of view λ (radians).
    pub light_position_fov: [f32; 4],
    /// RSM side S.
    pub rsm_size: u32,
    /// HVL grid side K (M = K²).
    pub grid: u32,
    /// 1: the build stage sets r2; 0: the r1 stage sets the radius.
    pub use_r2: u32,
    /// User radius scale k.
    pub radius_scale: f32,
}

/// Push constants of `shaders/hvl_gather.comp`, 32 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GatherPush {
    /// xyz: camera position; w unused.
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// HVLs in the cache.
    pub hvl_count: u32,
    /// Padding.
    pub pad: u32,
}

/// The reflective shadow map of one primary light (docs/frame.md, "Reflective shadow map").
#[derive(Debug, Clone, Copy)]
pub struct Rsm {
    /// `rsm_position`, RGBA32F: xyz world position, w = 1 (0 where empty).
    pub position: Handle<Image>,
    /// `rsm_normal`, RGBA16F: xyz unit world normal.
    pub normal: Handle<Image>,
    /// `rsm_flux`, RGBA32F: rgb reflected flux Φ of the texel (W).
    pub flux: Handle<Image>,
    /// Position of the primary light (point or spot: r2 needs a perspective RSM).
    pub light_position: Vec3,
    /// Full field of view λ of the square RSM, radians (eq. 24).
    pub fov: f32,
    /// Side S of the RSM in texels.
    pub size: u32,
}

/// HVL radius heuristic (paper 003 §5.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RadiusHeuristic {
    /// Eq. 23: weighted mean distance to the 8-connected neighbours (a second dispatch).
    R1,
    /// Eq. 24–26: from the RSM field of view, the HVL count and the distance to the light.
    R2,
}

/// How the gather convolves the incoming light with the receiver's BRDF.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Path {
    /// Full SH dot product with the BRDF SH tables rotated to the receiver frame, O(n²).
    Full,
    /// Zonal harmonics only, O(n): circularly symmetric lobes (Lambert).
    Zonal,
}

/// Parameters of the HVL passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HvlParams {
    /// Number of HVLs M. The cache needs a square K² with 64 ≤ M ≤ 10 000 and K ≤ the RSM
    /// side; the gather takes any 1 ≤ M ≤ 10 000 records.
    pub count: u32,
    /// Radius heuristic.
    pub radius: RadiusHeuristic,
    /// User scale of the radii, 1–2 in the paper (accepted: 0.1–4).
    pub radius_scale: f32,
    /// SH bands of the convolution at the receiver (1–10 in the paper).
    pub conv_bands: u32,
    /// SH bands of the HVL emission (1–5 in the paper), at most `conv_bands`.
    pub emission_bands: u32,
    /// Full or zonal convolution.
    pub path: Path,
}

/// Errors of the HVL passes: parameters out of range or inconsistent inputs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HvlError {
    /// The HVL count is not a square K² in 64..=10 000, or K exceeds the RSM side.
    #[error(
        "HVL count {count} is not usable with a {rsm_size}×{rsm_size} RSM: it must be a square K² with 64 ≤ K² ≤ 10000 and K ≤ {rsm_size}"
    )]
    Count {
        /// The count asked for.
        count: u32,
        /// The RSM side.
        rsm_size: u32,
    },
    /// No compiled `hvl_gather.comp` variant has these bands and path.
    #[error(
        "no hvl_gather variant for {path:?} with {conv_bands} convolution and {emission_bands} emission bands; available: {available}"
    )]
    Variant {
        /// Convolution bands asked for.
        conv_bands: u32,
        /// Emission bands asked for.
        emission_bands: u32,
        /// Path asked for.
        path: Path,
        /// The compiled variants, as `path cC eE`.
        available: String,
    },
    /// A scalar parameter out of its range.
    #[error("HVL parameter `{name}` = {value} is out of range: {expected}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// Expected range in words.
        expected: &'static str,
    },
    /// An input image or buffer does not have the size its description says.
    #[error("HVL input `{name}` is {actual}, expected {expected}")]
    Size {
        /// Which input.
        name: &'static str,
        /// What it is.
        actual: String,
        /// What it should be.
        expected: String,
    },
    /// Building the BRDF SH tables failed.
    #[error("BRDF SH table: {0}")]
    Sh(#[from] shine_sh::ShError),
}

/// The `hvl_gather.comp` variants compiled: `(path, conv_bands, emission_bands, shader)`.
pub fn gather_variants() -> [(Path, u32, u32, &'static ShaderDesc); 8] {
    [
        (Path::Full, 3, 3, &shaders::HVL_GATHER_COMP_FULL_C3_E3),
        (Path::Full, 5, 3, &shaders::HVL_GATHER_COMP_FULL_C5_E3),
        (Path::Full, 5, 5, &shaders::HVL_GATHER_COMP_FULL_C5_E5),
        (Path::Full, 9, 3, &shaders::HVL_GATHER_COMP_FULL_C9_E3),
        (Path::Full, 10, 5, &shaders::HVL_GATHER_COMP_FULL_C10_E5),
        (Path::Zonal, 3, 3, &shaders::HVL_GATHER_COMP_ZONAL_C3_E3),
        (Path::Zonal, 5, 3, &shaders::HVL_GATHER_COMP_ZONAL_C5_E3),
        (Path::Zonal, 9, 3, &shaders::HVL_GATHER_COMP_ZONAL_C9_E3),
    ]
}

/// The gather shader for `params` (its path and band counts), or [`HvlError::Variant`].
pub fn gather_shader(params: &HvlParams) -> Result<&'static ShaderDesc, HvlError> {
    let variants = gather_variants();
    variants
        .iter()
        .find(|v| v.0 == params.path && v.1 == params.conv_bands && v.2 == params.emission_bands)
        .map(|v| v.3)
        .ok_or_else(|| HvlError::Variant {
            conv_bands: params.conv_bands,
            emission_bands: params.emission_bands,
            path: params.path,
            available: variants
                .iter()
                .map(|v| format!("{:?} c{} e{}", v.0, v.1, v.2))
                .collect::<Vec<_>>()
                .join(", "),
        })
}

impl HvlParams {
    /// Checks the parameters for the cache built from an RSM of side `rsm_size`; returns the
    /// grid side K (`count = K²`).
    pub fn validate_cache(&self, rsm_size: u32) -> Result<u32, HvlError> {
        let k = (f64::from(self.count).sqrt().round()) as u32;
        if k * k != self.count || !(64..=10_000).contains(&self.count) || k > rsm_size {
            return Err(HvlError::Count {
                count: self.count,
                rsm_size,
            });
        }
        if !(0.1..=4.0).contains(&self.radius_scale) {
            return Err(HvlError::OutOfRange {
                name: "radius_scale",
                value: f64::from(self.radius_scale),
                expected: "0.1..=4 (the paper uses 1–2)",
            });
        }
        Ok(k)
    }

    /// Checks the band counts and the HVL count of the gather (`1..=10 000` records, bands as
    /// documented on the fields) and returns the matching shader variant.
    pub fn validate_gather(&self) -> Result<&'static ShaderDesc, HvlError> {
        if !(1..=10_000).contains(&self.count) {
            return Err(HvlError::OutOfRange {
                name: "count",
                value: f64::from(self.count),
                expected: "1..=10000 HVLs",
            });
        }
        if !(1..=10).contains(&self.conv_bands) {
            return Err(HvlError::OutOfRange {
                name: "conv_bands",
                value: f64::from(self.conv_bands),
                expected: "1..=10",
            });
        }
        if !(1..=EMISSION_MAX_BANDS as u32).contains(&self.emission_bands)
            || self.emission_bands > self.conv_bands
        {
            return Err(HvlError::OutOfRange {
                name: "emission_bands",
                value: f64::from(self.emission_bands),
                expected: "1..=5 and at most conv_bands",
            });
        }
        gather_shader(self)
    }
}

/// The receiver BRDF SH tables of the full gather path (paper 003 §4.2, eq. 18): `F` of
/// Lambert (albedo 1, scaled by `kd` per receiver) and `F` of one glossy BRDF (scaled by `ks`).
#[derive(Debug, Clone, PartialEq)]
pub struct GatherBrdf {
    /// `F` of Lambert with albedo 1.
    pub lambert: BrdfTable,
    /// `F` of the glossy lobe (GGX in the frame; any isotropic model works).
    pub glossy: BrdfTable,
}

impl GatherBrdf {
    /// Tabulates both BRDFs to `conv_bands` bands with the hemisphere quadrature `sampling`.
    pub fn build(
        conv_bands: u32,
        glossy: BrdfModel,
        sampling: HemisphereSampling,
    ) -> Result<Self, HvlError> {
        let bands = conv_bands as usize;
        Ok(Self {
            lambert: BrdfTable::build_with(BrdfModel::Lambert { albedo: 1.0 }, bands, sampling)?,
            glossy: BrdfTable::build_with(glossy, bands, sampling)?,
        })
    }

    /// The GPU buffer `brdf` of the gather: Lambert `F` rows then glossy `F` rows
    /// (`2 × 90 × bands²` floats, the shine-sh table layout).
    pub fn gpu_data(&self) -> Vec<f32> {
        [self.lambert.f(), self.glossy.f()].concat()
    }
}

fn check_extent(
    name: &'static str,
    image: &Handle<Image>,
    expected: [u32; 2],
) -> Result<(), HvlError> {
    let e = image.desc().extent;
    if [e.width, e.height] == expected {
        Ok(())
    } else {
        Err(HvlError::Size {
            name,
            actual: format!("{}×{}", e.width, e.height),
            expected: format!("{}×{}", expected[0], expected[1]),
        })
    }
}

/// Bytes of a cache of `count` HVLs.
pub fn cache_bytes(count: u32) -> u64 {
    u64::from(count) * std::mem::size_of::<Hvl>() as u64
}

/// Adds the `hvl_cache` pass(es): the RSM → `params.count` [`Hvl`] records (row-major over the
/// K×K grid) in a new transient buffer, returned. With [`RadiusHeuristic::R1`] a second
/// dispatch computes the radii from the first one's records.
pub fn hvl_cache(
    rg: &mut RenderGraph,
    rsm: &Rsm,
    params: &HvlParams,
) -> Result<Handle<Buffer>, HvlError> {
    let k = params.validate_cache(rsm.size)?;
    for (name, image) in [
        ("rsm_position", &rsm.position),
        ("rsm_normal", &rsm.normal),
        ("rsm_flux", &rsm.flux),
    ] {
        check_extent(name, image, [rsm.size, rsm.size])?;
    }
    if !(rsm.fov > 0.0 && rsm.fov < std::f32::consts::PI) {
        return Err(HvlError::OutOfRange {
            name: "RSM fov",
            value: f64::from(rsm.fov),
            expected: "0 < λ < π radians",
        });
    }
    let push = CachePush {
        light_position_fov: rsm.light_position.extend(rsm.fov).to_array(),
        rsm_size: rsm.size,
        grid: k,
        use_r2: u32::from(params.radius == RadiusHeuristic::R2),
        radius_scale: params.radius_scale,
    };
    let desc = BufferDesc::new(cache_bytes(params.count));
    let mut built = rg.create_buffer("hvl_cache", desc);
    rg.compute("hvl_cache", &shaders::HVL_CACHE_COMP_BUILD)
        .read("rsm_position", &rsm.position)
        .read("rsm_normal", &rsm.normal)
        .read("rsm_flux", &rsm.flux)
        .write("hvls", &mut built)
        .push(&push)
        .dispatch([k, k, 1]);
    if params.radius == RadiusHeuristic::R2 {
        return Ok(built);
    }
    let mut sized = rg.create_buffer("hvl_cache_r1", desc);
    rg.compute("hvl_radius_r1", &shaders::HVL_CACHE_COMP_R1)
        .read("source", &built)
        .write("hvls", &mut sized)
        .push(&push)
        .dispatch([k, k, 1]);
    Ok(sized)
}

/// Adds the `hvl_gather` pass: the `indirect` image (RGBA16F, receiver resolution, outgoing
/// radiance towards `camera` from all `params.count` HVLs of `hvls`, 0 on background), returned.
/// `brdf` holds [`GatherBrdf::gpu_data`] at `params.conv_bands` bands (unused by the zonal
/// path).
pub fn hvl_gather(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    hvls: &Handle<Buffer>,
    brdf: &Handle<Buffer>,
    camera: Vec3,
    params: &HvlParams,
) -> Result<Handle<Image>, HvlError> {
    let shader = params.validate_gather()?;
    for (name, image) in [
        ("recv_position", &receivers.position),
        ("recv_normal", &receivers.normal),
        ("recv_albedo", &receivers.albedo),
        ("recv_material", &receivers.material),
    ] {
        check_extent(name, image, receivers.extent)?;
    }
    let need = cache_bytes(params.count);
    if hvls.desc().size < need {
        return Err(HvlError::Size {
            name: "hvls",
            actual: format!("{} bytes", hvls.desc().size),
            expected: format!("at least {need} bytes for {} HVLs", params.count),
        });
    }
    let table = 2
        * shine_sh::brdf_table::THETA_SAMPLES as u64
        * u64::from(params.conv_bands * params.conv_bands)
        * 4;
    if params.path == Path::Full && brdf.desc().size != table {
        return Err(HvlError::Size {
            name: "brdf",
            actual: format!("{} bytes", brdf.desc().size),
            expected: format!(
                "{table} bytes (GatherBrdf::gpu_data at {} bands)",
                params.conv_bands
            ),
        });
    }
    let [w, h] = receivers.extent;
    let mut indirect = rg.create_image(
        "indirect",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let push = GatherPush {
        camera: camera.extend(0.0).to_array(),
        extent: receivers.extent,
        hvl_count: params.count,
        pad: 0,
    };
    let mut pass = rg.compute("hvl_gather", shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("hvls", hvls);
    if params.path == Path::Full {
        pass.read("brdf", brdf);
    }
    pass.write("indirect", &mut indirect)
        .push(&push)
        .dispatch([w, h, 1]);
    Ok(indirect)
}
