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
//! The CPU twin of both passes is [`crate::reference::hvl`]; docs/frame.md, section "Indirect
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
//! * **Distribution by flux** ([`Distribution::Flux`], the default; the grid above is
//!   [`Distribution::Grid`]). Equal image cells of a wide spot's RSM hold very unequal flux (the
//!   cornell spot's put 60% of it into 4 HVLs), and a cell's flux left from one texel's normal.
//!   By flux, M texels are drawn in proportion to their reflected flux through a fixed
//!   low-discrepancy pattern (`shaders/hvl_flux.comp`), each HVL carrying Φ/M of it, with the
//!   r2 radius from the local spacing ([`shine_sh::hvl::radius_spacing`]). Relative RMSE of
//!   the cornell box's indirect light: 0.64 → 0.34 (docs/quality.md).
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
//!   BVH shadow rays to the HVLs' centres lifted off their surfaces (shine's extension): one
//!   per receiver and HVL, or a few per receiver to HVLs drawn by contribution and denoised by
//!   a ratio estimator ([`shadows`]).
//! * **Ringing.** Each HVL's contribution is clamped at 0 per channel so band-limited ringing
//!   never makes `indirect` negative. The paper's sinc window (§4.2) is [`Window::Sinc`], off
//!   by default: it costs 5–7% of the energy for no visible ringing (docs/quality.md).
//! * **Near field.** [`Falloff::Disc`] scales each HVL's light to what a disc of the same area
//!   sends ([`shine_sh::hvl::disc_falloff`]); off by default (measured in docs/quality.md).
//! * **Receiver BRDF.** `kd` times Lambert and `ks` times GGX (its tables hold the dielectric
//!   Fresnel of η = 1.5; [`table_fresnel_weight`] swaps it for the material's, approximately,
//!   at n·v) at the receiver's roughness, with the weights of [`indirect_weights`]: the paper
//!   tabulates one table per material; we tabulate
//!   [`GLOSSY_TABLES`](crate::passes::brdf_tables::GLOSSY_TABLES) roughness nodes
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
//!
//! [`GatherBrdf`]: crate::passes::brdf_tables::GatherBrdf
//! [`table_fresnel_weight`]: crate::passes::brdf_tables::table_fresnel_weight
//! [`indirect_weights`]: crate::passes::brdf_tables::indirect_weights
//! [`glossy_roughness`]: crate::passes::brdf_tables::glossy_roughness

use std::ops::RangeInclusive;

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::declare::{OutOfRange, Settings};
use crate::graph::{Buffer, BufferDesc, Handle, Image, RenderGraph};
use crate::passes::rsm::{Rsm, RsmProjection};
use crate::passes::upsample::UpsampleParams;
use crate::shaders;

pub mod flux;
mod gather;
mod grid;
pub mod near;
mod records;
pub mod shadows;
mod variants;
pub use gather::{
    RECORD_TEXELS, RECORDS_PER_ROW, hvl_gather, hvl_gather_prep, hvl_regather, records_extent,
};
pub use grid::HvlGrid;
pub use records::{CachePush, GatherHvl, GatherPush, Hvl, PrepPush};
pub use variants::{gather_shader, gather_variants};

/// Most emission bands an [`Hvl`] stores (paper 003 §3 uses 0–5 bands for the emission).
pub const EMISSION_MAX_BANDS: usize = 5;

crate::choice::named_choice! {
    /// How an HVL's radius is estimated from the HVL cache (paper 003 §5.3).
    pub enum RadiusHeuristic ("HVL radius heuristic") {
        /// Eq. 23: weighted mean distance to the 8-connected neighbours in the HVL cache.
        R1 = "r1",
        /// Eq. 24–26: from the light's field of view, the HVL count and the distance to the light.
        R2 = "r2",
    }
}

crate::choice::named_choice! {
    /// Where the cache places its M HVLs on the RSM (paper 003 §5.2).
    pub enum Distribution ("HVL distribution") {
        /// The paper's: M cells uniform in the RSM's image plane ([`HvlGrid`]), one HVL per
        /// cell at its valid texel nearest the centre, carrying the cell's summed flux.
        Grid = "grid",
        /// Shine's: M texels drawn in proportion to their reflected flux by a fixed
        /// low-discrepancy pattern (`shaders/hvl_flux.comp`), each HVL carrying Φ/M of the flux
        /// from its own texel's position and normal, with the r2 radius taken from the local
        /// spacing ([`shine_sh::hvl::radius_spacing`]).
        Flux = "flux",
    }
}

crate::choice::named_choice! {
    /// How an HVL's light falls off near it (`hvl.falloff`).
    pub enum Falloff ("HVL falloff") {
        /// Paper 003's sphere (eq. 20–22): the point-light irradiance up to its surface.
        Sphere = "sphere",
        /// A Lambertian disc of the same area ([`shine_sh::hvl::disc_falloff`]): half the
        /// sphere's at its rim, the same far away.
        Disc = "disc",
    }
}

crate::choice::named_choice! {
    /// The window on the gathered light's SH bands against ringing (paper 003 §4.2).
    pub enum Window ("HVL SH window") {
        /// No window: the bands as projected (each HVL's contribution clamped at 0).
        None = "none",
        /// Sloan's sinc window, `sin(π l / n) / (π l / n)` on band l of n
        /// ([`shine_sh::kernels::Window::Sinc`] of width n).
        Sinc = "sinc",
    }
}

crate::choice::named_choice! {
    /// Which SH convolution the HVL gather uses (paper 003 §4.3 and §6).
    pub enum GatherPath ("HVL gather path") {
        /// Full SH convolution, O(n²) in the band count n: any BRDF.
        Full = "full",
        /// Zonal-harmonics convolution, O(n): circularly symmetric lobes only.
        Zonal = "zonal",
    }
}

/// `[hvl]`: the parameters of the Harmonics Virtual Lights passes (paper 003), each declared
/// once (the settings' keys, ranges and defaults are these fields'). Paper 003's choices but
/// these: 400 HVLs (fig. 10), r2 radii scaled by 1.5 (§5.3: 1–2), 5 convolution and 3
/// emission bands, the full path, the sphere's falloff; placed by flux rather than on the
/// paper's grid (relative RMSE of the cornell box's indirect light 0.64 → 0.34), shadowed by
/// 8 sampled rays per receiver rather than unshadowed (0.32 → 0.25, energy 1.12 → 0.98;
/// docs/quality.md), and a traced near field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
#[settings(check = HvlParams::check_relations)]
pub struct HvlParams {
    /// Number M of HVLs distributed from the RSM (the RSM is cut into M cells; at most
    /// `rsm.size²`; paper 003 fig. 10: 400).
    #[setting(default = 400, range = CACHE_COUNT, lab = 64..=1600, affects = both)]
    pub count: u32,
    /// Where the HVLs are placed on the RSM: `grid` (paper 003 §5.2: cells uniform in the
    /// RSM's image) or `flux` (texels drawn in proportion to the flux they reflect, radii from
    /// the local spacing; needs `radius = "r2"`).
    #[setting(default = Distribution::Flux, affects = quality)]
    pub distribution: Distribution,
    /// Radius heuristic: `r1` (eq. 23) or `r2` (eq. 24–26).
    #[setting(default = RadiusHeuristic::R2, affects = quality)]
    pub radius: RadiusHeuristic,
    /// User factor k scaling every radius (paper 003 §5.3: good between 1 and 2).
    #[setting(default = 1.5, range = RADIUS_SCALE, affects = quality)]
    pub radius_scale: f32,
    /// SH bands n of the convolution at shaded points (n² coefficients).
    #[serde(rename = "convolution_bands")]
    #[setting(default = 5, range = CONV_BANDS, affects = both)]
    pub conv_bands: u32,
    /// SH bands of each HVL's emission function, at most `convolution_bands` (the paper's 3).
    /// Every sender is Lambert today, whose emission is isotropic and needs band 0 only
    /// (paper 003 eq. 20): more bands change nothing until glossy senders exist.
    #[setting(default = 3, range = EMISSION_BANDS, affects = both)]
    pub emission_bands: u32,
    /// Gather path: `full` (any BRDF, O(n²)) or `zonal` (symmetric lobes, O(n)).
    #[serde(rename = "gather")]
    #[setting(default = GatherPath::Full, affects = both)]
    pub path: GatherPath,
    /// Window on each HVL's SH bands against ringing: `none` or `sinc` (paper 003 §4.2,
    /// Sloan's sinc of width `convolution_bands`).
    #[setting(default = Window::None, affects = quality)]
    pub window: Window,
    /// Near-field falloff of each HVL: `sphere` (paper 003 eq. 20–22: the point-light
    /// irradiance up to the sphere's surface) or `disc` (a Lambertian disc of the same area:
    /// half of that at the rim).
    #[setting(default = Falloff::Sphere, affects = quality)]
    pub falloff: Falloff,
    /// Shadow the HVLs through the scene's BVH (shine's extension: paper 003's HVLs are
    /// unshadowed; false gives the paper's).
    #[setting(default = true, affects = both)]
    pub visibility: bool,
    /// With `visibility`: shadow rays per receiver, to HVLs drawn in proportion to their
    /// light and denoised by a ratio estimator (`src/passes/hvl/shadows.rs`); 0 traces one
    /// ray per receiver and HVL (exact, about 10× the gather's cost).
    #[setting(default = shadows::RAYS, range = shadows::RAYS_RANGE, affects = both)]
    pub shadow_rays: u32,
    /// Radius in receivers of the sampled shadows' ratio filter.
    #[setting(default = shadows::FILTER_RADIUS, range = shadows::FILTER_RADIUS_RANGE, affects = both)]
    pub shadow_filter_radius: u32,
    /// R of the traced near field, as a fraction of the scene's largest side: light from
    /// surfaces closer than R comes from `near_rays` traced rays instead of the HVLs, which
    /// cap it, blended over R..2R (`src/passes/hvl/near.rs`). 0: none (paper 003).
    #[setting(default = near::RANGE, range = near::RANGE_RANGE, lab = 0.0..=0.2, affects = both)]
    pub near_range: f32,
    /// Rays per receiver of the near field.
    #[setting(default = near::RAYS, range = near::RAYS_RANGE, lab = 1..=16, affects = both)]
    pub near_rays: u32,
    /// Receivers per gather refresh (paper 001): 1 gathers every receiver every frame; 4
    /// gathers one receiver per 2×2 cell per frame and reprojects the others from the
    /// previous frames (`hvl_resolve`, [`crate::passes::amortise::SLICES`]).
    #[setting(default = 1, one_of = crate::passes::amortise::SLICE_CHOICES, affects = both)]
    pub slices: u32,
    /// The sampled shadows' bilateral match (the frame's upsample's; set by the frame).
    #[serde(skip)]
    #[setting(default = UpsampleParams::default())]
    pub shadow_matching: UpsampleParams,
    /// Seed of the shadow rays' random numbers (the frame index when a history averages
    /// frames; set by the frame).
    #[serde(skip)]
    #[setting(default = 0)]
    pub shadow_seed: u32,
    /// R of the near field in world units (`near_range` times the scene's size; set by the
    /// frame): each HVL's diffuse light is scaled by `smoothstep(R, 2R, d)` (d its centre's
    /// distance) and `hvl_near` traces the rest; 0: none (paper 003).
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub near_radius: f32,
    /// Roughness limit of the frame's traced specular pass (0: none; set by the frame): the
    /// gather's glossy term is scaled by `1 −` [`crate::passes::specular::trace_weight`].
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub specular_limit: f32,
}

impl HvlParams {
    /// How the gather shadows its HVLs when `visibility` is on.
    pub fn shadows(&self) -> shadows::ShadowSampling {
        shadows::ShadowSampling {
            rays: self.shadow_rays,
            filter_radius: self.shadow_filter_radius,
            matching: self.shadow_matching,
            seed: self.shadow_seed,
        }
    }

    /// The settings' rules between fields: emission bands at most the convolution's, and
    /// `r1` radii only on the grid (they take their neighbours from it).
    fn check_relations(&self, prefix: &str) -> Result<(), OutOfRange> {
        if self.emission_bands > self.conv_bands {
            return Err(OutOfRange {
                field: format!("{prefix}emission_bands"),
                value: self.emission_bands.to_string(),
                allowed: format!(
                    "1..={} (at most hvl.convolution_bands)",
                    self.conv_bands.min(*EMISSION_BANDS.end())
                ),
            });
        }
        if self.radius == RadiusHeuristic::R1 && self.distribution == Distribution::Flux {
            return Err(OutOfRange {
                field: format!("{prefix}radius"),
                value: "r1".to_owned(),
                allowed: "r2 with hvl.distribution = \"flux\" (r1 takes its neighbours from the grid: set hvl.distribution = \"grid\")".to_owned(),
            });
        }
        Ok(())
    }
}

/// Errors of the HVL passes: parameters out of range or inconsistent inputs.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HvlError {
    /// The HVL count is outside [`CACHE_COUNT`] or exceeds the RSM's texel count.
    #[error(
        "HVL count {count} is not usable with a {rsm_size}×{rsm_size} RSM: it must lie in {range:?} and not exceed the RSM's texel count (raise rsm.size)",
        range = CACHE_COUNT
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
        path: GatherPath,
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
        expected: String,
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
    /// The r1 heuristic was asked for with the flux distribution, which has no cache
    /// neighbourhood to take it from.
    #[error(
        "the HVL radius heuristic r1 needs hvl.distribution = \"grid\" (its neighbours are cells of the grid); use r2 with \"flux\""
    )]
    R1NeedsGrid,
    /// The cache was given no RSM face.
    #[error("the HVL cache needs at least one RSM face")]
    NoFaces,
    /// HVL visibility was asked for without the scene's BVH.
    #[error("HVL visibility needs the scene's BVH buffers")]
    NoBvh,
    /// An SH computation of the CPU twin failed (a band count outside shine-sh's range).
    #[error("HVL SH: {0}")]
    Sh(#[from] shine_sh::ShError),
}

/// Convolution band counts of the gather (paper 003: 1–10).
pub const CONV_BANDS: RangeInclusive<u32> = 1..=10;

/// Emission band counts of an HVL (paper 003: 1–5, at most the convolution's).
pub const EMISSION_BANDS: RangeInclusive<u32> = 1..=EMISSION_MAX_BANDS as u32;

/// Most HVLs a cache or a gather takes.
pub const MAX_HVLS: u32 = 10_000;

/// HVL counts M the cache builds from an RSM (at most one per RSM texel as well).
pub const CACHE_COUNT: RangeInclusive<u32> = 64..=MAX_HVLS;

/// HVL records the gather takes (tests gather a single HVL).
pub const GATHER_COUNT: RangeInclusive<u32> = 1..=MAX_HVLS;

/// The user scale k of the radii (paper 003 §5.3: "between 1 and 2").
pub const RADIUS_SCALE: RangeInclusive<f32> = 1.0..=2.0;

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

/// `(λ or W, 1 for orthographic)`, the shader's encoding of an RSM projection.
pub(crate) fn encode_projection(projection: RsmProjection) -> (f32, f32) {
    match projection {
        RsmProjection::Perspective { fov } => (fov, 0.0),
        RsmProjection::Orthographic { width } => (width, 1.0),
    }
}

/// Checks an RSM projection's λ in (0, π) or W > 0.
fn validate_projection(projection: RsmProjection) -> Result<(), HvlError> {
    match projection {
        RsmProjection::Perspective { fov } if !(fov > 0.0 && fov < std::f32::consts::PI) => {
            Err(HvlError::OutOfRange {
                name: "RSM fov",
                value: f64::from(fov),
                expected: "0 < λ < π radians".to_owned(),
            })
        }
        RsmProjection::Orthographic { width } if !(width > 0.0 && width.is_finite()) => {
            Err(HvlError::OutOfRange {
                name: "RSM width",
                value: f64::from(width),
                expected: "a finite width > 0 metres".to_owned(),
            })
        }
        _ => Ok(()),
    }
}

/// Bytes of a cache of `count` HVLs.
pub fn cache_bytes(count: u32) -> u64 {
    u64::from(count) * std::mem::size_of::<Hvl>() as u64
}

/// Adds the `hvl_cache` pass(es): RSM faces → `params.count` [`Hvl`] records in a new
/// transient buffer, returned. On the grid (paper 003), only the first face counts (the
/// primary light's RSM): the records follow the cell order of [`HvlGrid`], and with
/// [`RadiusHeuristic::R1`] a second dispatch computes the radii from the first one's records.
/// With [`Distribution::Flux`], the HVLs are drawn over every face, so the budget is split
/// between the lights by the flux they reflect ([`flux`]).
pub fn hvl_cache(
    rg: &mut RenderGraph,
    faces: &[Rsm],
    params: &HvlParams,
) -> Result<Handle<Buffer>, HvlError> {
    let rsm = faces.first().ok_or(HvlError::NoFaces)?;
    let grid = params.validate_cache(rsm.size)?;
    for face in faces {
        for (name, image) in [
            ("rsm_position", &face.position),
            ("rsm_normal", &face.normal),
            ("rsm_flux", &face.flux),
        ] {
            check_extent(name, image, [face.size, face.size])?;
        }
        validate_projection(face.projection)?;
    }
    let desc = BufferDesc::new(cache_bytes(params.count));
    let mut built = rg.create_buffer("hvl_cache", desc);
    if params.distribution == Distribution::Flux {
        flux::flux_cache(rg, faces, params, &mut built)?;
        return Ok(built);
    }
    let push = cache_push(
        rsm.light_position,
        rsm.light_direction,
        rsm.projection,
        grid,
        params,
    );
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
    let (extent, ortho) = encode_projection(projection);
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
