//! Harmonics Virtual Lights (paper 003): the `hvl_cache` and `hvl_gather` passes.
//!
//! * [`hvl_cache`] turns the reflective shadow map of one primary light into M HVLs
//!   (spherical secondary lights, §5.2) stored as [`Hvl`] records, with radius heuristic r1
//!   (eq. 23) or r2 (eq. 24–26) times a user scale, and the sender's SH emission (eq. 20).
//! * [`hvl_gather`] sums, at every receiver, the outgoing radiance towards the camera due to
//!   every HVL (eq. 1, 3, 19–22): the full O(n²) SH path with the receiver's BRDF SH tables
//!   (Lambert + glossy tables over roughness, [`GatherBrdf`]) or the O(n) zonal path (Lambert
//!   only, §6.3).
//!
//! The CPU twin of both passes is [`crate::hvl_reference`]; docs/frame.md, section "Indirect
//! light", fixes the formats and units.
//!
//! # Decisions and deviations from paper 003
//!
//! * **Construction.** The paper renders HVL data into the RSM (its "HVL cache", e.g. 1024²
//!   texels for 400 HVLs) and takes M HVLs from it; we cut the RSM into exactly M cells
//!   ([`HvlGrid`]: R ≈ √M rows of ⌊M/R⌋ or ⌈M/R⌉ cells, a regular K×K grid when M = K²):
//!   each cell gives one HVL at its valid texel nearest the cell centre, carrying the summed
//!   flux of all the cell's valid texels (so the reflected power is the same for every M; the
//!   paper's Φ_j is "the light's power divided by the number of HVLs"). r1's "8-connected
//!   neighbours in the cache" are the cells beside it in its row and the three cells of each
//!   adjacent row nearest its centre (the 8-neighbourhood when M = K²).
//! * **Directional lights.** Eq. 24–26 assume a perspective RSM. An orthographic RSM (a
//!   directional primary light) covers the same width W at every distance, so `d·λ` of eq. 24–25
//!   becomes W: `r2 = √2 W / √M` ([`shine_sh::hvl::radius_r2_orthographic`]), and the distance
//!   `d_j` of eq. 23 is measured along the light's direction.
//! * **Emission.** RSM senders are Lambertian with the albedo already in the flux, so the
//!   sender's `F'` (eq. 20) is `1/π` over the hemisphere: a ZH vector about `n_j`, identical to
//!   the Lambert (albedo 1) row of [`shine_sh::brdf_table::BrdfTable::f_prime`] for every θ_l.
//!   Each record stores it (5 bands), the gather reconstructs `F'·Y(-ω_j)` to the emission band
//!   count of its variant and clamps it at 0 (band-limited ringing).
//! * **Visibility.** As published, HVLs are unshadowed (§6). [`HvlParams::visibility`] adds
//!   one BVH shadow ray per receiver and HVL, to the HVL's centre lifted off its surface
//!   (shine's extension; measured against the path tracer in the issue notes).
//! * **Ringing.** Each HVL's contribution is clamped at 0 per channel so band-limited ringing
//!   never makes `indirect` negative; the paper's sinc window (§4.2) is not applied.
//! * **Receiver BRDF.** `kd` times Lambert and `ks` times GGX (its tables hold the dielectric
//!   Fresnel of η = 1.5; [`table_fresnel_weight`] swaps it for the material's, approximately,
//!   at n·v) at the
//!   receiver's roughness, with the weights of [`indirect_weights`]: the paper
//!   tabulates one table per material; we tabulate [`GLOSSY_TABLES`] roughness nodes
//!   ([`glossy_roughness`]) and interpolate the two tables around the receiver's roughness
//!   linearly, which serves every material of every scene with one buffer. Rougher than the
//!   first node is clamped to it (lobes sharper than roughness 0.2 are beyond what ≤ 10 bands
//!   resolve). The zonal path has the Lambert term only.
//! * `emission_bands ≤ conv_bands`; the emission band count is a push constant and each
//!   convolution band count 1–10 of each path is a variant of `shaders/hvl_gather.comp`
//!   ([`gather_variants`]).
//!
//! # Accuracy
//!
//! One HVL against a quadrature of eq. 3 with eq. 19–21 (`tests/hvl.rs`, worst relative error
//! over 8 receivers, three of them half-metallic with a GGX lobe of roughness 0.6): the SH
//! truncation of the convolution alone is 27% at 3 bands, 11% at 5, 1.1% at 9 (the metallic
//! lobes; zonal, Lambert only: 5.8% at 3, 0.8% at 9); with the exact Lambert emission as
//! reference the total is 31–33% with 3 emission bands (the band-limited `F'·Y` overshoots
//! near the sender's normal, the paper's choice) and 27% with 5.

use glam::Vec3;
use shine_sh::brdf_table::{BrdfModel, BrdfTable, HemisphereSampling};

use crate::gpu::ShaderDesc;
use crate::gpu_bvh::TraceBuffers;
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

/// Push constants of `shaders/hvl_cache.comp` (both stages), 48 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CachePush {
    /// xyz: primary light position (perspective) or the RSM's eye (orthographic); w: the RSM's
    /// field of view λ in radians (perspective) or its width W in metres (orthographic).
    pub light_position_extent: [f32; 4],
    /// xyz: unit axis of the RSM's view; w: 1 for an orthographic RSM, 0 for perspective.
    pub light_direction_ortho: [f32; 4],
    /// RSM side S.
    pub rsm_size: u32,
    /// HVL count M.
    pub count: u32,
    /// Rows R of the [`HvlGrid`].
    pub rows: u32,
    /// 1: the build stage sets r2; 0: the r1 stage sets the radius.
    pub use_r2: u32,
    /// User radius scale k.
    pub radius_scale: f32,
    /// Padding.
    pub pad: [f32; 3],
}

/// Push constants of `shaders/hvl_gather.comp`, 48 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GatherPush {
    /// xyz: camera position; w unused.
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// HVLs in the cache.
    pub hvl_count: u32,
    /// Bands of the HVL emission reconstructed (1–5).
    pub emission_bands: u32,
    /// Roughness of the first glossy table and the step between tables ([`glossy_roughness`]).
    pub roughness_nodes: [f32; 2],
    /// Number of glossy tables ([`GLOSSY_TABLES`]).
    pub glossy_tables: u32,
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
    /// Position of the primary light (perspective) or the RSM's eye (orthographic).
    pub light_position: Vec3,
    /// Unit axis of the RSM's view (the light's direction for a directional light).
    pub light_direction: Vec3,
    /// How the RSM was projected.
    pub projection: RsmProjection,
    /// Side S of the RSM in texels.
    pub size: u32,
}

/// The projection of an RSM: it decides the r2 heuristic and the distance `d_j` to the light.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RsmProjection {
    /// A point or spot light's square frustum of full field of view λ (radians, eq. 24).
    Perspective {
        /// λ.
        fov: f32,
    },
    /// A directional light's box of width W (metres) across.
    Orthographic {
        /// W.
        width: f32,
    },
}

impl RsmProjection {
    /// `(λ or W, 1 for orthographic)`, the shader's encoding.
    fn encode(self) -> (f32, f32) {
        match self {
            Self::Perspective { fov } => (fov, 0.0),
            Self::Orthographic { width } => (width, 1.0),
        }
    }

    /// Checks λ in (0, π) or W > 0.
    fn validate(self) -> Result<(), HvlError> {
        match self {
            Self::Perspective { fov } if !(fov > 0.0 && fov < std::f32::consts::PI) => {
                Err(HvlError::OutOfRange {
                    name: "RSM fov",
                    value: f64::from(fov),
                    expected: "0 < λ < π radians",
                })
            }
            Self::Orthographic { width } if !(width > 0.0 && width.is_finite()) => {
                Err(HvlError::OutOfRange {
                    name: "RSM width",
                    value: f64::from(width),
                    expected: "a finite width > 0 metres",
                })
            }
            _ => Ok(()),
        }
    }
}

/// How the S×S RSM is cut into exactly M cells, one HVL each: R rows of equal height, row j
/// holding the cells `row_start(j)..row_start(j + 1)` (`row_start(j) = ⌊j M / R⌋`) of equal
/// width. The GLSL twin is in `shaders/hvl_cache.comp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct HvlGrid {
    /// Number of cells M.
    pub count: u32,
    /// Number of rows R.
    pub rows: u32,
    /// RSM side S.
    pub size: u32,
}

impl HvlGrid {
    /// The grid of `count` cells over an RSM of side `size`: R = round(√M), raised so that no
    /// row holds more than S cells and lowered to at most S rows; `None` when M > S².
    pub fn new(count: u32, size: u32) -> Option<Self> {
        if count == 0 || size == 0 || u64::from(count) > u64::from(size) * u64::from(size) {
            return None;
        }
        let rows = ((f64::from(count).sqrt().round()) as u32)
            .max(count.div_ceil(size))
            .min(size);
        Some(Self { count, rows, size })
    }

    /// First cell of row `j` (`j ≤ R`; `row_start(R) = M`).
    pub fn row_start(&self, j: u32) -> u32 {
        (u64::from(j) * u64::from(self.count) / u64::from(self.rows)) as u32
    }

    /// The row of cell `m`: `⌈(m + 1) R / M⌉ - 1`.
    pub fn row_of(&self, m: u32) -> u32 {
        ((u64::from(m + 1) * u64::from(self.rows)).div_ceil(u64::from(self.count)) - 1) as u32
    }

    /// Cells in row `j`.
    pub fn row_len(&self, j: u32) -> u32 {
        self.row_start(j + 1) - self.row_start(j)
    }

    /// The texel rectangle `[x0, y0]..[x1, y1]` (exclusive) of cell `m`.
    pub fn cell(&self, m: u32) -> ([u32; 2], [u32; 2]) {
        let j = self.row_of(m);
        let (i, n) = (m - self.row_start(j), self.row_len(j));
        let s = self.size;
        (
            [i * s / n, j * s / self.rows],
            [(i + 1) * s / n, (j + 1) * s / self.rows],
        )
    }

    /// The r1 neighbours of cell `m` (eq. 23's "8-connected neighbours"): the cells beside it in
    /// its row and, in each adjacent row, the cell under its centre and that cell's two
    /// neighbours.
    pub fn neighbours(&self, m: u32) -> Vec<u32> {
        let j = self.row_of(m);
        let ([x0, _], [x1, _]) = self.cell(m);
        let mut out = Vec::with_capacity(8);
        for dj in [-1i64, 0, 1] {
            let jj = i64::from(j) + dj;
            if jj < 0 || jj >= i64::from(self.rows) {
                continue;
            }
            let jj = jj as u32;
            let n = self.row_len(jj);
            // The cell of row jj under the centre (x0 + x1) / 2 of cell m.
            let c = if dj == 0 {
                m - self.row_start(j)
            } else {
                ((x0 + x1) * n / (2 * self.size)).min(n - 1)
            };
            for di in [-1i64, 0, 1] {
                let ii = i64::from(c) + di;
                if (dj == 0 && di == 0) || ii < 0 || ii >= i64::from(n) {
                    continue;
                }
                out.push(self.row_start(jj) + ii as u32);
            }
        }
        out
    }
}

pub use crate::settings::{GatherPath as Path, RadiusHeuristic};

/// Parameters of the HVL passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HvlParams {
    /// Number of HVLs M. The cache needs 64 ≤ M ≤ 10 000 and M ≤ S² (S the RSM side); the
    /// gather takes any 1 ≤ M ≤ 10 000 records.
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
    /// Shadow rays from each receiver to each HVL through the scene's BVH (not in paper 003,
    /// whose HVLs are unshadowed).
    pub visibility: bool,
}

/// Errors of the HVL passes: parameters out of range or inconsistent inputs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HvlError {
    /// The HVL count is outside 64..=10 000 or exceeds the RSM's texel count.
    #[error(
        "HVL count {count} is not usable with a {rsm_size}×{rsm_size} RSM: it must lie in 64..=10000 and not exceed the RSM's texel count (raise rsm.size)"
    )]
    Count {
        /// The count asked for.
        count: u32,
        /// The RSM side.
        rsm_size: u32,
    },
    /// No compiled `hvl_gather.comp` variant has these bands and path.
    #[error(
        "no hvl_gather variant for {path:?} with {conv_bands} convolution bands; available: {available}"
    )]
    Variant {
        /// Convolution bands asked for.
        conv_bands: u32,
        /// Path asked for.
        path: Path,
        /// The compiled variants, as `path cC`.
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
    /// HVL visibility was asked for without the scene's BVH.
    #[error("HVL visibility needs the scene's BVH buffers")]
    NoBvh,
    /// Building the BRDF SH tables failed.
    #[error("BRDF SH table: {0}")]
    Sh(#[from] shine_sh::ShError),
}

/// Convolution band counts of the gather (paper 003: 1–10).
pub const CONV_BANDS: std::ops::RangeInclusive<u32> = 1..=10;

/// The `hvl_gather.comp` variants: `(path, conv_bands, visibility, shader)` for every path,
/// every band count of [`CONV_BANDS`] and with or without shadow rays (variants `full_cN`,
/// `zonal_cN`, `full_cN_vis`, `zonal_cN_vis`).
pub fn gather_variants() -> Vec<(Path, u32, bool, &'static ShaderDesc)> {
    let mut variants = Vec::new();
    for (path, name) in [(Path::Full, "full"), (Path::Zonal, "zonal")] {
        for visibility in [false, true] {
            for bands in CONV_BANDS {
                let suffix = if visibility { "_vis" } else { "" };
                if let Some(shader) =
                    shaders::get(&format!("hvl_gather.comp:{name}_c{bands}{suffix}"))
                {
                    variants.push((path, bands, visibility, shader));
                }
            }
        }
    }
    variants
}

/// The gather shader for `params` (its path, convolution bands and visibility), or
/// [`HvlError::Variant`].
pub fn gather_shader(params: &HvlParams) -> Result<&'static ShaderDesc, HvlError> {
    let variants = gather_variants();
    variants
        .iter()
        .find(|v| v.0 == params.path && v.1 == params.conv_bands && v.2 == params.visibility)
        .map(|v| v.3)
        .ok_or_else(|| HvlError::Variant {
            conv_bands: params.conv_bands,
            path: params.path,
            available: variants
                .iter()
                .map(|v| format!("{:?} c{}{}", v.0, v.1, if v.2 { " vis" } else { "" }))
                .collect::<Vec<_>>()
                .join(", "),
        })
}

impl HvlParams {
    /// Checks the parameters for the cache built from an RSM of side `rsm_size`; returns the
    /// cells of the RSM, one per HVL.
    pub fn validate_cache(&self, rsm_size: u32) -> Result<HvlGrid, HvlError> {
        let grid = HvlGrid::new(self.count, rsm_size)
            .filter(|_| (64..=10_000).contains(&self.count))
            .ok_or(HvlError::Count {
                count: self.count,
                rsm_size,
            })?;
        if !(0.1..=4.0).contains(&self.radius_scale) {
            return Err(HvlError::OutOfRange {
                name: "radius_scale",
                value: f64::from(self.radius_scale),
                expected: "0.1..=4 (the paper uses 1–2)",
            });
        }
        Ok(grid)
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

/// Number of glossy BRDF tables of the gather, at the roughness nodes of [`glossy_roughness`].
pub const GLOSSY_TABLES: u32 = 5;

/// Perceptual roughness of the first glossy table; the nodes are spaced evenly up to 1.
pub const GLOSSY_ROUGHNESS_MIN: f32 = 0.2;

/// The Fresnel index of refraction of the glossy tables (dielectrics; metals take their colour
/// from `ks`).
pub const GLOSSY_IOR: f32 = 1.5;

/// Perceptual roughness of glossy table `k` (GGX α = roughness², as the direct light).
pub fn glossy_roughness(k: u32) -> f32 {
    GLOSSY_ROUGHNESS_MIN + k as f32 * glossy_roughness_step()
}

/// Roughness between two glossy tables.
pub fn glossy_roughness_step() -> f32 {
    (1.0 - GLOSSY_ROUGHNESS_MIN) / (GLOSSY_TABLES - 1) as f32
}

/// The two glossy tables around `roughness` and the weight of the second: `(k, k + 1, t)`,
/// clamped to the nodes (the GLSL twin is `glossy_rows` in `shaders/hvl_gather.comp`).
pub fn glossy_blend(roughness: f32) -> (u32, u32, f32) {
    let x = ((roughness - GLOSSY_ROUGHNESS_MIN) / glossy_roughness_step())
        .clamp(0.0, (GLOSSY_TABLES - 1) as f32);
    let k0 = (x.floor() as u32).min(GLOSSY_TABLES - 1);
    let k1 = (k0 + 1).min(GLOSSY_TABLES - 1);
    (k0, k1, x - k0 as f32)
}

/// Diffuse and specular weights `(kd, ks)` of the metallic-roughness material for indirect
/// light (HVL and IGI; GLSL `brdf_indirect_weights`): Schlick's Fresnel F at the mirror
/// direction (v·h = n·v), `kd = (1 - F)(1 - metallic) albedo` (the direct pass's diffuse),
/// `ks = F` with `F0 = mix(0.04, albedo, metallic)`.
pub fn indirect_weights(albedo: Vec3, metallic: f32, n_dot_v: f32) -> (Vec3, Vec3) {
    let f0 = Vec3::splat(0.04).lerp(albedo, metallic);
    let ks = f0 + (Vec3::ONE - f0) * (1.0 - n_dot_v.clamp(0.0, 1.0)).powi(5);
    let kd = (Vec3::ONE - ks) * (1.0 - metallic) * albedo;
    (kd, ks)
}

/// The weight of a GGX table's glossy row for a material whose Fresnel is `ks` (GLSL
/// `brdf_table_fresnel_weight`): the tables hold the exact dielectric Fresnel of
/// [`GLOSSY_IOR`] at each direction's v·h; dividing `ks` by Schlick's F with F0 = 0.04 at
/// `n_dot_v` swaps it for the material's approximately (an n·v stand-in for v·h): 1 for
/// dielectrics, about albedo / 0.04 for metals at normal view.
pub fn table_fresnel_weight(ks: Vec3, n_dot_v: f32) -> Vec3 {
    ks / (0.04 + 0.96 * (1.0 - n_dot_v.clamp(0.0, 1.0)).powi(5))
}

/// The receiver BRDF SH tables of the full gather path (paper 003 §4.2, eq. 18): `F` of
/// Lambert (albedo 1, scaled by `kd` per receiver) and `F` of GGX at each roughness node
/// (scaled by `ks`).
#[derive(Debug, Clone, PartialEq)]
pub struct GatherBrdf {
    /// `F` of Lambert with albedo 1.
    pub lambert: BrdfTable,
    /// `F` of GGX at [`glossy_roughness`]`(k)`, k = 0..[`GLOSSY_TABLES`].
    pub glossy: Vec<BrdfTable>,
}

impl GatherBrdf {
    /// Tabulates every BRDF to `conv_bands` bands with the hemisphere quadrature `sampling`.
    pub fn build(conv_bands: u32, sampling: HemisphereSampling) -> Result<Self, HvlError> {
        let bands = conv_bands as usize;
        let glossy = (0..GLOSSY_TABLES)
            .map(|k| {
                let r = glossy_roughness(k);
                let model = BrdfModel::Ggx {
                    alpha: r * r,
                    ior: GLOSSY_IOR,
                };
                BrdfTable::build_with(model, bands, sampling)
            })
            .collect::<Result<_, _>>()?;
        Ok(Self {
            lambert: BrdfTable::build_with(BrdfModel::Lambert { albedo: 1.0 }, bands, sampling)?,
            glossy,
        })
    }

    /// The glossy row `F(θ_o)` at `roughness`: the two nodes' rows blended linearly.
    pub fn glossy_f(&self, roughness: f32, theta_o: f32) -> Vec<f32> {
        let (k0, k1, t) = glossy_blend(roughness);
        let a = self.glossy[k0 as usize].lookup_f(theta_o);
        let b = self.glossy[k1 as usize].lookup_f(theta_o);
        a.iter()
            .zip(&b)
            .map(|(a, b)| a * (1.0 - t) + b * t)
            .collect()
    }

    /// The GPU buffer `brdf` of the gather: Lambert `F` rows then each glossy table's `F` rows
    /// (`(1 + GLOSSY_TABLES) × 90 × bands²` floats, the shine-sh table layout).
    pub fn gpu_data(&self) -> Vec<f32> {
        std::iter::once(&self.lambert)
            .chain(&self.glossy)
            .flat_map(|t| t.f().iter().copied())
            .collect()
    }

    /// Bytes of [`GatherBrdf::gpu_data`] at `conv_bands` bands.
    pub fn gpu_bytes(conv_bands: u32) -> u64 {
        u64::from(1 + GLOSSY_TABLES)
            * shine_sh::brdf_table::THETA_SAMPLES as u64
            * u64::from(conv_bands * conv_bands)
            * 4
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

/// Adds the `hvl_cache` pass(es): the RSM → `params.count` [`Hvl`] records (in the cell order
/// of [`HvlGrid`]) in a new transient buffer, returned. With [`RadiusHeuristic::R1`] a second
/// dispatch computes the radii from the first one's records.
pub fn hvl_cache(
    rg: &mut RenderGraph,
    rsm: &Rsm,
    params: &HvlParams,
) -> Result<Handle<Buffer>, HvlError> {
    let grid = params.validate_cache(rsm.size)?;
    for (name, image) in [
        ("rsm_position", &rsm.position),
        ("rsm_normal", &rsm.normal),
        ("rsm_flux", &rsm.flux),
    ] {
        check_extent(name, image, [rsm.size, rsm.size])?;
    }
    rsm.projection.validate()?;
    let push = cache_push(
        rsm.light_position,
        rsm.light_direction,
        rsm.projection,
        grid,
        params,
    );
    let desc = BufferDesc::new(cache_bytes(params.count));
    let mut built = rg.create_buffer("hvl_cache", desc);
    rg.compute("hvl_cache", &shaders::HVL_CACHE_COMP_BUILD)
        .read("rsm_position", &rsm.position)
        .read("rsm_normal", &rsm.normal)
        .read("rsm_flux", &rsm.flux)
        .write("hvls", &mut built)
        .push(&push)
        .dispatch([params.count, 1, 1]);
    if params.radius == RadiusHeuristic::R2 {
        return Ok(built);
    }
    let mut sized = rg.create_buffer("hvl_cache_r1", desc);
    rg.compute("hvl_radius_r1", &shaders::HVL_CACHE_COMP_R1)
        .read("source", &built)
        .write("hvls", &mut sized)
        .push(&push)
        .dispatch([params.count, 1, 1]);
    Ok(sized)
}

/// The cache's push constants.
fn cache_push(
    light_position: Vec3,
    light_direction: Vec3,
    projection: RsmProjection,
    grid: HvlGrid,
    params: &HvlParams,
) -> CachePush {
    let (extent, ortho) = projection.encode();
    CachePush {
        light_position_extent: light_position.extend(extent).to_array(),
        light_direction_ortho: light_direction
            .normalize_or(Vec3::NEG_Y)
            .extend(ortho)
            .to_array(),
        rsm_size: grid.size,
        count: grid.count,
        rows: grid.rows,
        use_r2: u32::from(params.radius == RadiusHeuristic::R2),
        radius_scale: params.radius_scale,
        pad: [0.0; 3],
    }
}

/// Adds the `hvl_gather` pass: the `indirect` image (RGBA16F, receiver resolution, outgoing
/// radiance towards `camera` from all `params.count` HVLs of `hvls`, 0 on background), returned.
/// `brdf` holds [`GatherBrdf::gpu_data`] at `params.conv_bands` bands (unused by the zonal
/// path); `bvh` is needed when `params.visibility` is set.
pub fn hvl_gather(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    hvls: &Handle<Buffer>,
    brdf: &Handle<Buffer>,
    bvh: Option<&TraceBuffers>,
    camera: Vec3,
    params: &HvlParams,
) -> Result<Handle<Image>, HvlError> {
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
    let need = cache_bytes(params.count);
    if hvls.desc().size < need {
        return Err(HvlError::Size {
            name: "hvls",
            actual: format!("{} bytes", hvls.desc().size),
            expected: format!("at least {need} bytes for {} HVLs", params.count),
        });
    }
    let table = GatherBrdf::gpu_bytes(params.conv_bands);
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
        emission_bands: params.emission_bands,
        roughness_nodes: [GLOSSY_ROUGHNESS_MIN, glossy_roughness_step()],
        glossy_tables: GLOSSY_TABLES,
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
    if let Some(b) = bvh {
        pass.read("bvh_nodes", &b.nodes)
            .read("bvh_triangles", &b.triangles);
    }
    pass.write("indirect", &mut indirect)
        .push(&push)
        .dispatch([w, h, 1]);
    Ok(indirect)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every texel lies in exactly one cell, every cell holds a texel, rows are found back
    /// from cell indices, and a square count is the regular K×K grid with 8-neighbourhoods.
    #[test]
    fn grid_cells_partition_the_rsm() {
        for (count, size) in [
            (64, 8),
            (64, 16),
            (70, 16),
            (255, 16),
            (256, 16),
            (1000, 40),
        ] {
            let grid = HvlGrid::new(count, size).unwrap();
            let mut owner = vec![u32::MAX; (size * size) as usize];
            for m in 0..count {
                let j = grid.row_of(m);
                assert!(
                    grid.row_start(j) <= m && m < grid.row_start(j + 1),
                    "{count} {m}"
                );
                let (lo, hi) = grid.cell(m);
                assert!(lo[0] < hi[0] && lo[1] < hi[1], "{count}: cell {m} is empty");
                for y in lo[1]..hi[1] {
                    for x in lo[0]..hi[0] {
                        let t = &mut owner[(y * size + x) as usize];
                        assert_eq!(*t, u32::MAX, "{count}: texel ({x}, {y}) in two cells");
                        *t = m;
                    }
                }
                let n = grid.neighbours(m);
                assert!(!n.contains(&m) && n.iter().all(|&q| q < count));
            }
            assert!(
                owner.iter().all(|&m| m != u32::MAX),
                "{count}: texel in no cell"
            );
        }
        let square = HvlGrid::new(64, 16).unwrap();
        assert_eq!(square.rows, 8);
        assert_eq!(square.cell(9), ([2, 2], [4, 4]));
        let mut n = square.neighbours(9);
        n.sort_unstable();
        assert_eq!(n, [0, 1, 2, 8, 10, 16, 17, 18]);
        assert_eq!(square.neighbours(0).len(), 3);
        assert!(HvlGrid::new(257, 16).is_none());
        assert!(HvlGrid::new(0, 16).is_none());
    }

    #[test]
    fn glossy_blend_clamps_and_hits_nodes() {
        assert_eq!(glossy_blend(0.0), (0, 1, 0.0));
        assert_eq!(
            glossy_blend(1.0),
            (GLOSSY_TABLES - 1, GLOSSY_TABLES - 1, 0.0)
        );
        let (k0, k1, t) = glossy_blend(glossy_roughness(2));
        assert!((k0 == 2 && t.abs() < 1e-5) || (k0 == 1 && k1 == 2 && (t - 1.0).abs() < 1e-5));
        let (k0, k1, t) = glossy_blend(0.5 * (glossy_roughness(1) + glossy_roughness(2)));
        assert_eq!((k0, k1), (1, 2));
        assert!((t - 0.5).abs() < 1e-5);
    }
}
