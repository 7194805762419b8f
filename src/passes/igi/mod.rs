//! Instant global illumination with interleaved sampling and SH-filtered incoming radiance
//! (paper 000): the `igi_vpls`, `vpl_sh` and `sh_filter` passes.
//!
//! 1. **VPLs** ([`vpls`]): the primary light's RSM cut into exactly M cells by the HVL cache
//!    pass ([`super::hvl::hvl_cache`], its r2 radii the VPLs' footprints): each cell is one Lambertian VPL at its
//!    texel nearest the centre, with the cell's summed reflected flux Φ_j, radiant intensity
//!    `I(ω) = Φ_j max(0, n_j·ω)/π`.
//!    With `distribution = flux` (shine's, [`hvl::Distribution::Flux`]) the VPLs are every
//!    light's samples with identities drawn in proportion to their reflected flux instead
//!    ([`crate::reference::hvl_flux`]).
//! 2. **Interleaved sets** (§2.3): pixel p of an n×m tile uses set `s = (x mod n) + n (y mod m)`.
//!    A VPL's set follows from its identity, `⌊φ₅(j)·nm⌋` of its sample (or grid cell) index j
//!    ([`crate::reference::hvl_flux::sample_set`]): each face's sequence spreads evenly over
//!    the sets, a set's VPLs spread over the whole RSM (the paper's sets of a K×K grid would
//!    otherwise be columns of it), and a VPL keeps its set when the records reorder as the
//!    lights' shares change (issue 43; this replaces a fixed permutation of record indices).
//!    Each contribution is scaled by nm: the filter over whole pattern tiles counts every set
//!    equally, so the filtered sum is the full VPL sum.
//!    [`sets`] groups the records by set once a frame (`igi_sets`), so that a pixel walks only
//!    its own set's list, in record order.
//! 3. **vpl_sh** ([`vpl_sh`]): per pixel, every VPL of its set not below the geometric surface is
//!    tested with a shadow ray through the BVH (`trace_occluded`, shaders/include/trace.glsl)
//!    and its incident radiance `E_j δ(ω_j)`, `E_j = I_j(−ω_j) / max(d, d_min, k r_j)²`, projected to
//!    SH (§3.2: `L_lm += E_j Y_lm(ω_j)`), 4/9/16 coefficients for SH order 2/3/4. Classic IGI
//!    ([`FilterMode::Irradiance`]) stores instead the irradiance about the shading normal,
//!    `Σ E_j max(0, n·ω_j)`, and the glossy radiance `Σ E_j phong(r·ω_j)`.
//! 4. **sh_filter** ([`sh_filter`]): the discontinuity filter (mean over
//!    the pixels within a relative depth tolerance whose GEOMETRIC normals agree, the G-buffer's
//!    `gb_geometric_normal`, over a window of k×k pattern tiles, so that every set is counted
//!    k² times in a continuous region), then the BRDF as SH (§3.3) about the shading normal: Lambert `r_l`
//!    (§3.3.1) and Phong `r_l` (§3.3.2) dotted with the filtered radiance.
//!
//! # Decisions and deviations
//!
//! * **Clamp and footprint.** The VPL singularity 1/d² is evaluated as `1/max(d, d_min, ρ)²`:
//!   `clamp_distance` d_min (default 0.1 m) is the classic bounded-geometry-term clamp of IGI;
//!   the footprint ρ = k r_j (`footprint` k, default 1; r_j the VPL's spacing radius) is
//!   shine's: a receiver nearer a VPL than its neighbours are apart sees a bounded light that
//!   does not sweep across the wall as the VPL moves (issue 43, docs/quality.md; a disc's
//!   `1/(d² + ρ²)` instead kept 0.79 of the room's mean indirect light, against 0.85). The energy
//!   they remove is measured by `tests/igi.rs` against the path-traced reference.
//! * **Glossy BRDF** ([`Glossy`], `igi.glossy`). `ggx` (default): the HVL gather's BRDF SH
//!   tables (Lambert + GGX at 5 roughness nodes blended linearly, [`brdf_tables::GatherBrdf`], built at
//!   `sh_order` bands, the renderer's cached buffer) in the receiver frame (z = shading normal,
//!   ω_o in the xz half-plane); the filtered radiance is rotated into that frame per pixel
//!   (`sh_rotation`, Ivanic–Ruedenberg, twin of `shine_sh::rotation`). Weights as the Phong path
//!   (below), the glossy one divided by the dielectric Schlick F (F0 = 0.04) at n·v because the
//!   tables already hold the exact η = 1.5 Fresnel ([`brdf_tables::table_fresnel_weight`], shared with
//!   the HVL gather): 1 for dielectrics, ≈ albedo/0.04 for metals (weighting the tables by
//!   `mix(1, albedo, metallic)` instead, as the HVL gather first did, left the metallic lobe
//!   ~20× too dark: the IGI mean indirect fell to 0.82 of the reference). `phong`: paper 000 §3.3 literally — Lambert `r_l` about the normal and
//!   a Phong lobe about the reflected direction with exponent `0.5/α² − 0.5`
//!   (`igi_phong_exponent`, α = roughness²), `kd = (1 − F)(1 − metallic) albedo`, `ks = F`
//!   (Schlick at the mirror direction). Irradiance mode always uses the Phong weights.
//! * **Resolution.** Everything runs at full resolution (the interleaving needs the pixel grid):
//!   no receiver buffer, no upsample.
//! * **Storage.** `vpl_sh` holds C rgb coefficients per pixel as two u32 of packed halves
//!   (8 bytes): W·H·C·8 bytes must fit the 128 MiB every Vulkan device allows for one storage
//!   buffer (`maxStorageBufferRange` ≥ 2²⁷): 1280×720 at order 4, 1920×1080 at order 2 only
//!   ([`IgiError::TooLarge`] otherwise). Values are clamped to ±65504 (half range).
//! * **Classic IGI** filters its two normal-dependent values with the same window and the same
//!   geometric-normal test as the SH mode, so the comparison isolates what is filtered.
//! * **hvl + igi**: refused by the settings (both are the one-bounce light of the primary
//!   light).
//!
//! # Measured (lavapipe, `tests/igi.rs`, `shine profile`)
//!
//! * `room` (spot light only, 128², one-bounce indirect against the path tracer at 64 spp):
//!   SH filtering 26.61 dB PSNR / SSIM 0.781 (GGX tables; Phong lobe 26.73 dB / 0.779), classic
//!   irradiance filtering 24.60 dB / 0.745; mean indirect 0.95 of the reference; the 0.1 m clamp
//!   removes 5.5% of the mean indirect radiance and raises PSNR from 26.15 dB.
//! * `shine profile builtin:room --gi igi` at 256², release, host clock per pass: vpl_sh
//!   5785 / 1682 / 555 ms and sh_filter 90 / 93 / 127 ms for n×m = 1×1 / 2×2 / 4×4 (256 VPLs,
//!   order 3); the shadow rays dominate and scale as 1/(nm).

use std::ops::RangeInclusive;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::declare::{Section, Settings};
use crate::gpu_scene::bvh::TraceImages;
use crate::graph::{Buffer, BufferDesc, Handle, Image, ImageDesc, RenderGraph, vk};
use crate::passes::amortise;
use crate::passes::brdf_tables;
use crate::passes::gbuffer::GBuffer;
use crate::passes::hvl::{self, HvlError, HvlParams, near};
use crate::passes::rsm::Rsm;
use crate::shaders;

mod vpl_sets;

pub use vpl_sets::{SETS_MAX, SetsPush, VplSets, sets, sets_bytes};

/// Largest storage buffer every Vulkan device allows (`maxStorageBufferRange` ≥ 2²⁷ bytes):
/// [`IgiParams::storage_limit`]'s default, which the frame replaces with its device's limit.
pub const MAX_STORAGE_BUFFER: u64 = 1 << 27;

/// Bytes per stored rgb coefficient of `vpl_sh` (two u32 of packed halves).
pub const COEFFICIENT_BYTES: u64 = 8;
/// uints per stored rgb coefficient ([`COEFFICIENT_BYTES`] / 4).
pub const COEFFICIENT_WORDS: u32 = (COEFFICIENT_BYTES / 4) as u32;

/// Interleaving pattern sides n and m (paper 000 §2.2 uses 4×4 and 8×8 patterns).
pub const PATTERN: RangeInclusive<u32> = 1..=8;

/// VPL counts: the RSM is cut into cells by the HVL cache pass, one VPL each.
pub const VPL_COUNT: RangeInclusive<u32> = hvl::CACHE_COUNT;
/// Default VPL count M: 512 since issue 43's change 14 (256 before). With 256, IGI's frames
/// without a screen history flickered 4.4× (`motion-orbit`) and 5.2× (`motion-sun`) the
/// path-traced truth's, above the 4×, and neither the filter (every pixel gathering
/// every VPL: `sun` 4.9×) nor a wider near field (its error on `builtin:animated`) took it
/// under; 512 read 3.4× and 3.6×, with every motion scene's and the still frames' error lower
/// (the cornell box 0.134 → 0.127), for `vpl_sh` 150 → 267 ms at 256² on lavapipe, about
/// +16% of IGI's frame (docs/quality.md, docs/performance.md).
pub const DEFAULT_VPL_COUNT: u32 = 512;
/// SH orders of the per-pixel incident radiance (paper 000 §3.1 uses 3).
pub const SH_ORDERS: RangeInclusive<u32> = 2..=4;
/// Discontinuity-filter window sizes k, in interleaving tiles (0: no filter).
pub const FILTER_RADIUS: RangeInclusive<u32> = 0..=4;
/// VPL singularity clamp distances d_min, metres.
pub const CLAMP_DISTANCE: RangeInclusive<f32> = 0.0..=10.0;

/// Footprint factors k ([`IgiParams::footprint`]).
pub const FOOTPRINT: RangeInclusive<f32> = 0.0..=4.0;
/// Relative depth tolerances of the discontinuity filter.
pub const DEPTH_TOLERANCE: RangeInclusive<f32> = 1e-4..=1.0;
/// Cosine thresholds of the filter's geometric-normal test.
pub const NORMAL_THRESHOLD: RangeInclusive<f32> = -1.0..=1.0;

crate::choice::named_choice! {
    /// What the discontinuity filter averages (paper 000 §2.3 against §3).
    pub enum FilterMode ("IGI filter mode") {
        /// The per-pixel incident radiance as SH (paper 000): the BRDF is applied after filtering.
        Sh = "sh",
        /// Classic IGI: the per-pixel irradiance (and glossy radiance) about the shading normal.
        Irradiance = "irradiance",
    }
}

crate::choice::named_choice! {
    /// How the discontinuity filter measures a neighbour's depth against the pixel's
    /// ([`IgiParams::depth_tolerance`]).
    pub enum GeometryTest ("IGI filter geometry test") {
        /// The neighbour's distance off the pixel's geometric tangent plane (shine's, issue 43):
        /// a plane seen at a grazing angle keeps its neighbours, whose depths differ by more
        /// than the tolerance from row to row while they lie on the same plane.
        Plane = "plane",
        /// The linear depths' difference (paper 000 §2.3): at grazing view a floor or
        /// ceiling keeps only its own row, so its pixels average a few of the sets and stripe.
        Depth = "depth",
    }
}

crate::choice::named_choice! {
    /// The glossy lobe of IGI's SH resolve (`src/passes/igi.rs`).
    pub enum Glossy ("IGI glossy lobe") {
        /// GGX through the BRDF SH tables ([`crate::passes::brdf_tables`]), the filtered
        /// radiance rotated into the receiver frame (sh.glsl `sh_rotation`).
        Ggx = "ggx",
        /// Paper 000 §3.3: Lambert and Phong r_l, the Phong lobe standing for the GGX.
        Phong = "phong",
    }
}

/// `[igi]`: instant global illumination with interleaved sampling and SH-filtered incident
/// radiance (paper 000): the parameters of the IGI passes, each declared once (the settings'
/// keys, ranges and defaults are these fields').
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct IgiParams {
    /// Interleaving pattern width n (VPL sets per row of a tile).
    #[setting(default = 4, range = PATTERN, affects = both)]
    pub n: u32,
    /// Interleaving pattern height m.
    #[setting(default = 4, range = PATTERN, affects = both)]
    pub m: u32,
    /// Number M of VPLs taken from the RSM (cut into exactly this many cells), shared out over
    /// the n·m sets; at most `rsm.size²`.
    #[setting(default = DEFAULT_VPL_COUNT, range = VPL_COUNT, lab = 64..=1024, affects = both)]
    pub vpl_count: u32,
    /// Where the VPLs are placed on the RSM: `grid` (cells uniform in the RSM's image) or
    /// `flux` (texels drawn in proportion to their reflected flux), as `hvl.distribution`.
    #[setting(default = hvl::Distribution::Flux, affects = quality)]
    pub distribution: hvl::Distribution,
    /// SH order (bands) of the per-pixel incident radiance (order² coefficients; paper 000
    /// §3.1: 3).
    #[setting(default = 3, range = SH_ORDERS, affects = both)]
    pub sh_order: u32,
    /// Size k of the discontinuity filter's window in interleaving tiles: k·n × k·m pixels
    /// around the pixel, every set counted k² times (0: no filter; 1: exactly one tile, as
    /// paper 000 §2.3).
    #[setting(default = 1, range = FILTER_RADIUS, affects = both)]
    pub filter_radius: u32,
    /// What is filtered: `sh` (paper 000) or `irradiance` (classic IGI).
    #[serde(rename = "filter")]
    #[setting(default = FilterMode::Sh, affects = both)]
    pub mode: FilterMode,
    /// Glossy lobe of the SH mode: `ggx` (BRDF SH tables) or `phong` (paper 000 §3.3.2).
    #[setting(default = Glossy::Ggx, affects = quality)]
    pub glossy: Glossy,
    /// Minimum VPL distance d_min in metres: 1/d² is evaluated as 1/max(d², d_min²) (the VPL
    /// singularity clamp).
    #[setting(default = 0.1, range = CLAMP_DISTANCE, lab = 0.0..=0.5, affects = quality)]
    pub clamp_distance: f32,
    /// Footprint k: a VPL is evaluated no closer than ρ = k r_j (r_j the spacing of the VPLs
    /// around it, r2 of paper 003 eq. 24–26 from the flux density), so a receiver nearer than
    /// its neighbours are apart sees a bounded light, not a 1/d² spike that sweeps across the
    /// wall as the VPL moves (issue 43). 0: the clamp d_min alone (paper 000).
    #[setting(default = 1.0, range = FOOTPRINT, lab = 0.0..=2.0, affects = quality)]
    pub footprint: f32,
    /// Relative depth tolerance of the filter: a neighbour q is used when its depth offset
    /// (by `geometry_test`) is at most depth_tolerance · z_p.
    #[setting(default = 0.05, range = DEPTH_TOLERANCE, lab = 0.01..=0.2, affects = quality)]
    pub depth_tolerance: f32,
    /// The filter's depth offset: `plane` (|n_p · (x_q − x_p)|, the distance off the pixel's
    /// geometric tangent plane; shine's, issue 43) or `depth` (|z_q − z_p|, paper 000 §2.3,
    /// which parts a grazing floor's rows and stripes it).
    #[setting(default = GeometryTest::Plane, affects = quality)]
    pub geometry_test: GeometryTest,
    /// Cosine threshold of the filter's geometric-normal test (n_p · n_q ≥ this).
    #[setting(default = 0.9, range = NORMAL_THRESHOLD, lab = 0.5..=0.99, affects = quality)]
    pub normal_threshold: f32,
    /// Roughness limit of the frame's traced specular pass (0: none; set by the frame): the
    /// filter's glossy term is scaled by `1 −` [`crate::passes::specular::trace_weight`].
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub specular_limit: f32,
    /// R of a traced near field, as a fraction of the scene's largest side, as
    /// `hvl.near_range` (`src/passes/hvl/near.rs`): a VPL's light fades out over 2R..R of
    /// its distance and `near_rays` traced rays give what surfaces closer than 2R send. The
    /// footprint bounds a near VPL's light, so a receiver beside a lit wall (a thin object's
    /// side, a room's corner) got a fraction of it and flickered as the VPLs slid past (issue
    /// 43). 0: none (paper 000).
    #[setting(default = near::RANGE, range = near::RANGE_RANGE, lab = 0.0..=0.2, affects = both)]
    pub near_range: f32,
    /// Rays per receiver of the near field.
    #[setting(default = near::RAYS, range = near::RAYS_RANGE, lab = 1..=16, affects = both)]
    pub near_rays: u32,
    /// R of the near field in world units (`near_range` times the scene's size; set by the
    /// frame; 0: none).
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub near_radius: f32,
    /// Pixels per refresh (paper 001): 1 gathers every pixel's VPL set every frame; 4 gathers
    /// the sets of one pixel per 2×2 cell per frame and reprojects the others' SH from the
    /// previous frames ([`IgiSlice`], `igi_reproject`: [`amortise::reproject_records`]).
    #[setting(default = 1, one_of = amortise::SLICE_CHOICES, affects = both)]
    pub slices: u32,
    /// Bytes one storage buffer may hold on the device (`maxStorageBufferRange`; lavapipe's
    /// is [`MAX_STORAGE_BUFFER`], NVIDIA's 4 GiB; set by the frame): bounds the per-pixel SH
    /// buffer.
    #[serde(skip)]
    #[setting(default = MAX_STORAGE_BUFFER)]
    pub storage_limit: u64,
}

/// Which pixels one `vpl_sh` dispatch gathers, and into which buffer: paper 001's amortised
/// frames (`igi.slices`, [`crate::passes::amortise`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct IgiSlice {
    /// 0: every pixel; 1 + k: the pixel at (k & 1, k >> 1) of every 2×2 cell;
    /// [`amortise::REGATHER_SLICE`]: the pixels `marks` marks with alpha −1. Each pixel
    /// gathers its own set, so four frames gather every set of the pattern.
    pub slice: u32,
    /// The marks of `igi_reproject` ([`amortise::reproject_records`]); required by the
    /// regather slice.
    pub marks: Option<Handle<Image>>,
    /// The buffer to gather into (the amortised frame's SH history; `None`: a new one).
    pub into: Option<Handle<Buffer>>,
}

/// Push constants of `shaders/vpl_sh.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct VplShPush {
    /// xyz: camera position; w: clamp distance d_min.
    pub camera_clamp: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// Interleaving pattern n, m.
    pub pattern: [u32; 2],
    /// VPL count M.
    pub vpl_count: u32,
    /// Footprint k ([`IgiParams::footprint`]).
    pub footprint: f32,
    /// The pixels shaded ([`IgiSlice::slice`]).
    pub slice: u32,
    /// R of the near field in world units ([`IgiParams::near_radius`]; 0: none).
    pub near_radius: f32,
}

/// Push constants of `shaders/sh_filter.comp` (64 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FilterPush {
    /// xyz: camera position; w: the specular pass's roughness limit (0: none).
    pub camera: [f32; 4],
    /// Image size.
    pub extent: [u32; 2],
    /// Interleaving pattern n, m.
    pub pattern: [u32; 2],
    /// Window size k in pattern tiles (k n × k m pixels; 0: no filter).
    pub radius: u32,
    /// Relative depth tolerance.
    pub depth_tolerance: f32,
    /// Cosine threshold of the geometric normals.
    pub normal_threshold: f32,
    /// Number of glossy tables ([`brdf_tables::GLOSSY_TABLES`], GGX path).
    pub glossy_tables: u32,
    /// Roughness of the first glossy table and the step between tables (GGX path).
    pub roughness_nodes: [f32; 2],
    /// 1: the depth offset is the distance off the tangent plane ([`GeometryTest::Plane`]);
    /// 0: the depths' difference.
    pub plane_test: u32,
    /// Padding.
    pub pad: f32,
}

/// Errors of the IGI passes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IgiError {
    /// A parameter out of its range.
    #[error("IGI {0}")]
    OutOfRange(#[from] crate::passes::OutOfRange),
    /// A setting outside its declared domain.
    #[error("IGI: {0}")]
    Setting(#[from] crate::declare::OutOfRange),
    /// The per-pixel SH buffer would exceed one storage buffer.
    #[error(
        "IGI per-pixel radiance of {width}×{height} pixels × {coefficients} coefficients needs {bytes} bytes, more than the {limit} bytes of one storage buffer on this device: lower igi.sh_order or the resolution"
    )]
    TooLarge {
        /// Image width.
        width: u32,
        /// Image height.
        height: u32,
        /// Coefficients per pixel.
        coefficients: u32,
        /// Bytes needed.
        bytes: u64,
        /// Bytes one storage buffer may hold ([`IgiParams::storage_limit`]).
        limit: u64,
    },
    /// The VPL construction (the HVL cache pass) refused its inputs.
    #[error(transparent)]
    Vpls(#[from] HvlError),
    /// An amortised dispatch's slice without its marks, or out of range.
    #[error(transparent)]
    Slice(#[from] amortise::AmortiseError),
}

impl IgiParams {
    /// Checks every parameter against its declared range.
    pub fn validate(&self) -> Result<(), IgiError> {
        Ok(self.check_in("igi.")?)
    }

    /// The interleaving pattern `[n, m]`.
    pub fn pattern(&self) -> [u32; 2] {
        [self.n, self.m]
    }

    /// Coefficients stored per pixel: order² (SH) or 2 (irradiance and glossy radiance).
    pub fn coefficients(&self) -> u32 {
        match self.mode {
            FilterMode::Sh => self.sh_order * self.sh_order,
            FilterMode::Irradiance => 2,
        }
    }

    /// The shader variant name (`o2`–`o4`, `g2`–`g4` for the filter's GGX path, or `irr`).
    fn variant(&self, filter: bool) -> String {
        match (self.mode, self.glossy) {
            (FilterMode::Sh, Glossy::Ggx) if filter => format!("g{}", self.sh_order),
            (FilterMode::Sh, _) => format!("o{}", self.sh_order),
            (FilterMode::Irradiance, _) => "irr".to_owned(),
        }
    }

    /// Whether the filter reads the BRDF SH tables (SH mode with GGX).
    pub fn needs_brdf_tables(&self) -> bool {
        self.mode == FilterMode::Sh && self.glossy == Glossy::Ggx
    }

    /// Bytes of the `vpl_sh` buffer for an image of `extent`, or [`IgiError::TooLarge`].
    pub fn sh_bytes(&self, extent: [u32; 2]) -> Result<u64, IgiError> {
        let coefficients = self.coefficients();
        let bytes = u64::from(extent[0])
            * u64::from(extent[1])
            * u64::from(coefficients)
            * COEFFICIENT_BYTES;
        if bytes > self.storage_limit {
            return Err(IgiError::TooLarge {
                width: extent[0],
                height: extent[1],
                coefficients,
                bytes,
                limit: self.storage_limit,
            });
        }
        Ok(bytes)
    }
}

/// The interleaved set of pixel `(x, y)` (the CPU twin of `igi_set`).
pub fn pixel_set(x: u32, y: u32, pattern: [u32; 2]) -> u32 {
    x % pattern[0] + pattern[0] * (y % pattern[1])
}

/// Adds the VPL construction: the HVL cache pass with `params.vpl_count` VPLs over the RSM
/// faces `rsm` (records in the layout of [`hvl::Hvl`]; radius and emission unused).
pub fn vpls(
    rg: &mut RenderGraph,
    rsm: &[Rsm],
    params: &IgiParams,
) -> Result<Handle<Buffer>, IgiError> {
    params.validate()?;
    let cache = HvlParams {
        count: params.vpl_count,
        distribution: params.distribution,
        radius: hvl::RadiusHeuristic::R2,
        radius_scale: 1.0,
        conv_bands: 3,
        emission_bands: 1,
        path: hvl::GatherPath::Zonal,
        window: hvl::Window::None,
        falloff: hvl::Falloff::Sphere,
        visibility: false,
        shadow_rays: 0,
        slices: 1,
        ..HvlParams::default()
    };
    Ok(hvl::hvl_cache(rg, rsm, &cache)?)
}

/// [`IgiError::OutOfRange`] unless `vpls` holds `params.vpl_count` records.
pub(crate) fn check_vpls(vpls: &Handle<Buffer>, params: &IgiParams) -> Result<(), IgiError> {
    if vpls.desc().size < hvl::cache_bytes(params.vpl_count) {
        return Err(IgiError::OutOfRange(super::OutOfRange {
            name: "vpls buffer bytes",
            value: vpls.desc().size as f64,
            expected: "at least vpl_count × 80 bytes".to_owned(),
        }));
    }
    Ok(())
}

/// Adds `vpl_sh` (`igi_regather` for the regather slice): the per-pixel incident radiance of
/// the pixel's VPL set, shadowed through `bvh`, as `params.coefficients()` packed rgb
/// coefficients per pixel, at the pixels of `slice` ([`IgiSlice::default`]: every pixel, into
/// a new buffer); returns the buffer.
pub fn vpl_sh(
    rg: &mut RenderGraph,
    g: &GBuffer,
    vpls: &VplSets,
    bvh: &TraceImages,
    camera: Vec3,
    params: &IgiParams,
    slice: IgiSlice,
) -> Result<Handle<Buffer>, IgiError> {
    params.validate()?;
    amortise::check_slice(slice.slice, slice.marks.is_some())?;
    let regather = slice.slice == amortise::REGATHER_SLICE;
    let bytes = params.sh_bytes(g.extent)?;
    check_vpls(&vpls.vpls, params)?;
    if vpls.sets.desc().size < sets_bytes(params.vpl_count) {
        return Err(IgiError::OutOfRange(super::OutOfRange {
            name: "igi_sets buffer bytes",
            value: vpls.sets.desc().size as f64,
            expected: format!("({} + vpl_count) × 4 bytes (igi::sets)", SETS_MAX + 1),
        }));
    }
    let shader = shader("vpl_sh.comp", params, false)?;
    let mut sh = match slice.into {
        Some(into) if into.desc().size >= bytes => into,
        Some(into) => {
            return Err(IgiError::OutOfRange(super::OutOfRange {
                name: "vpl_sh buffer bytes",
                value: into.desc().size as f64,
                expected: "W × H × coefficients × 8 bytes".to_owned(),
            }));
        }
        None => rg.create_buffer("vpl_sh", BufferDesc::new(bytes)),
    };
    let push = VplShPush {
        camera_clamp: camera.extend(params.clamp_distance).to_array(),
        extent: g.extent,
        pattern: params.pattern(),
        vpl_count: params.vpl_count,
        footprint: params.footprint,
        slice: slice.slice,
        near_radius: params.near_radius,
    };
    let name = if regather { "igi_regather" } else { "vpl_sh" };
    let mut pass = rg.compute(name, shader);
    pass.read("gb_position", &g.position)
        .read("gb_geometric_normal", &g.geometric_normal);
    if params.mode == FilterMode::Irradiance {
        pass.read("gb_normal", &g.normal)
            .read("gb_material", &g.material);
    }
    bvh.bind(&mut pass);
    // Read only by the regather slice; the G-buffer's normals (any full-resolution RGBA16F
    // image the frame writes) fill the binding of the others.
    pass.read("vpls", &vpls.vpls)
        .read("sets", &vpls.sets)
        .read("marks", slice.marks.as_ref().unwrap_or(&g.normal))
        .write("vpl_sh", &mut sh)
        .push(&push)
        .dispatch(amortise::slice_threads(g.extent, slice.slice));
    Ok(sh)
}

/// Adds `sh_filter`: the discontinuity filter over `sh` and the BRDF at every pixel; returns
/// the full-resolution `indirect` image (RGBA16F outgoing radiance towards `camera`). `brdf`
/// holds [`brdf_tables::GatherBrdf::gpu_data`] at `params.sh_order` bands; only the GGX path reads it.
pub fn sh_filter(
    rg: &mut RenderGraph,
    g: &GBuffer,
    sh: &Handle<Buffer>,
    brdf: Option<&Handle<Buffer>>,
    camera: Vec3,
    params: &IgiParams,
) -> Result<Handle<Image>, IgiError> {
    params.validate()?;
    let bytes = params.sh_bytes(g.extent)?;
    if sh.desc().size < bytes {
        return Err(IgiError::OutOfRange(super::OutOfRange {
            name: "vpl_sh buffer bytes",
            value: sh.desc().size as f64,
            expected: "W × H × coefficients × 8 bytes".to_owned(),
        }));
    }
    let shader = shader("sh_filter.comp", params, true)?;
    let brdf = match (params.needs_brdf_tables(), brdf) {
        (false, _) => None,
        (true, Some(b)) if b.desc().size == brdf_tables::GatherBrdf::gpu_bytes(params.sh_order) => {
            Some(b)
        }
        (true, _) => {
            return Err(IgiError::OutOfRange(super::OutOfRange {
                name: "brdf tables bytes",
                value: brdf.map_or(0.0, |b| b.desc().size as f64),
                expected: "GatherBrdf::gpu_data at sh_order bands (the GGX path needs them)"
                    .to_owned(),
            }));
        }
    };
    let [w, h] = g.extent;
    let mut indirect = rg.create_image(
        "indirect",
        ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, w, h),
    );
    let push = FilterPush {
        camera: camera.extend(params.specular_limit).to_array(),
        extent: g.extent,
        pattern: params.pattern(),
        radius: params.filter_radius,
        depth_tolerance: params.depth_tolerance,
        normal_threshold: params.normal_threshold,
        glossy_tables: brdf_tables::GLOSSY_TABLES,
        roughness_nodes: [
            brdf_tables::GLOSSY_ROUGHNESS_MIN,
            brdf_tables::glossy_roughness_step(),
        ],
        plane_test: u32::from(params.geometry_test == GeometryTest::Plane),
        pad: 0.0,
    };
    let mut pass = rg.compute("sh_filter", shader);
    pass.read("gb_position", &g.position)
        .read("gb_normal", &g.normal)
        .read("gb_geometric_normal", &g.geometric_normal)
        .read("gb_albedo", &g.albedo)
        .read("gb_material", &g.material)
        .read("vpl_sh", sh);
    if let Some(brdf) = brdf {
        pass.read("brdf", brdf);
    }
    pass.write("indirect", &mut indirect)
        .push(&push)
        .dispatch([w, h, 1]);
    Ok(indirect)
}

/// The compiled variant of `file` for `params` (`filter`: the sh_filter variants).
fn shader(
    file: &str,
    params: &IgiParams,
    filter: bool,
) -> Result<&'static crate::gpu::ShaderDesc, IgiError> {
    shaders::get(&format!("{file}:{}", params.variant(filter))).ok_or(IgiError::OutOfRange(
        super::OutOfRange {
            name: "sh_order",
            value: f64::from(params.sh_order),
            expected: format!("a compiled variant: SH order {SH_ORDERS:?}"),
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_sets_tile_the_pattern() {
        assert_eq!(pixel_set(5, 6, [4, 4]), 1 + 4 * 2);
    }

    #[test]
    fn storage_limit_is_enforced() {
        let p = IgiParams {
            sh_order: 4,
            ..IgiParams::default()
        };
        assert!(p.sh_bytes([1280, 720]).is_ok());
        assert!(matches!(
            p.sh_bytes([1920, 1080]),
            Err(IgiError::TooLarge { .. })
        ));
        // A device with a larger limit (NVIDIA's 4 GiB) takes the 1080p frame.
        let large = IgiParams {
            storage_limit: 1 << 32,
            ..p
        };
        assert_eq!(large.sh_bytes([1920, 1080]), Ok(1920 * 1080 * 16 * 8));
        let bad = IgiParams {
            n: 0,
            ..IgiParams::default()
        };
        assert!(bad.validate().is_err());
    }
}
