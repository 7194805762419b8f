//! The HVL passes' GPU records (std430, mirrored by `shaders/include/hvl.glsl`) and push
//! constants.

use super::EMISSION_MAX_BANDS;

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
    /// ZH coefficients (about `n_j`) of the sender's `F'` (eq. 20).
    pub emission: [f32; EMISSION_MAX_BANDS],
    /// Identity, part 1: the sample sequence it belongs to (the flux distribution: one per RSM
    /// face, [`flux::sequence_id`](super::flux::sequence_id) of its light and face; 0 on the grid).
    pub light: u32,
    /// Identity, part 2: the sample's index in its sequence (by flux) or its grid
    /// cell. IGI's interleaved set follows from it ([`crate::reference::hvl_flux::sample_set`]),
    /// so a VPL keeps its set when the records reorder.
    pub sample_index: u32,
    /// The samples its light keeps (`n_k`; the cell count on the grid): a light's records are
    /// consecutive from slot − `sample_index`, so the sampled shadows can stratify by identity
    /// (`hvl_gather.comp`). 0 for an empty slot of the flux distribution.
    pub light_samples: u32,
}

impl Hvl {
    /// Whether the record holds a light (an empty RSM cell gives an invalid one).
    pub fn is_valid(&self) -> bool {
        self.flux[3] != 0.0
    }
}

/// One HVL as the gather reads it (80 bytes, one RGBA32F texel per field of the records image:
/// `HVL_RECORD_*` of `shaders/include/hvl.glsl`, [`RECORDS_PER_ROW`](super::RECORDS_PER_ROW)): what depends on the HVL
/// alone, computed once per frame by `hvl_gather_prep` instead of once per receiver
/// ([`crate::reference::hvl::gather_records`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GatherHvl {
    /// xyz: centre `y_j`; w: radius `r_j`, 0 for an empty cell (skipped).
    pub position_radius: [f32; 4],
    /// xyz: unit normal `n_j`; w: `1 / (π r_j²)`, eq. 21's denominator.
    pub normal_area: [f32; 4],
    /// rgb: flux `Φ_j`; a: `a_0` of the emission polynomial
    /// ([`crate::reference::hvl::zh_poly`]).
    pub flux_e0: [f32; 4],
    /// `a_1 ..= a_4` of the emission polynomial.
    pub emission: [f32; 4],
    /// x: the HVL's light ([`Hvl::light`]), y: its sample index ([`Hvl::sample_index`]), z:
    /// the samples its light keeps ([`Hvl::light_samples`]), as floats: its identity, which
    /// keys and stratifies the sampled shadows' draw (`hvl_gather.comp`).
    pub identity: [f32; 4],
}

/// Push constants of `shaders/hvl_gather_prep.comp`, 8 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct PrepPush {
    /// HVLs in the cache.
    pub count: u32,
    /// Bands of the HVL emission reconstructed (1–5).
    pub emission_bands: u32,
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
    /// Rows R of the [`HvlGrid`](super::HvlGrid).
    pub rows: u32,
    /// 1: the build stage sets r2; 0: the r1 stage sets the radius.
    pub use_r2: u32,
    /// User radius scale k.
    pub radius_scale: f32,
    /// Padding.
    pub pad: [f32; 3],
}

/// Push constants of `shaders/hvl_gather.comp`, 64 bytes.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GatherPush {
    /// xyz: camera position; w: the specular pass's roughness limit (0: none).
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// HVLs in the cache.
    pub hvl_count: u32,
    /// Bands of the HVL emission reconstructed (1–5).
    pub emission_bands: u32,
    /// Roughness of the first glossy table and the step between tables
    /// ([`glossy_roughness`](crate::passes::brdf_tables::glossy_roughness)).
    pub roughness_nodes: [f32; 2],
    /// Number of glossy tables ([`GLOSSY_TABLES`](crate::passes::brdf_tables::GLOSSY_TABLES)).
    pub glossy_tables: u32,
    /// 0: every receiver; 1 + k: one receiver per 2×2 cell, at offset (k & 1, k >> 1)
    /// ([`crate::passes::amortise::slice_of_frame`]).
    pub slice: u32,
    /// Width of the sinc window on the light's SH bands (the convolution's band count), 0 for
    /// none.
    pub window_width: f32,
    /// 1: [`Falloff::Disc`](super::Falloff::Disc); 0: the paper's sphere.
    pub disc_falloff: u32,
    /// `_shadows` variants: shadow rays per receiver ([`shadows::ShadowSampling::rays`](super::shadows::ShadowSampling::rays)).
    pub shadow_rays: u32,
    /// Seed of the sampled shadow rays.
    pub seed: u32,
    /// R of the near field in world units ([`HvlParams::near_radius`](super::HvlParams::near_radius)), 0: none.
    pub near_range: f32,
    /// Padding.
    pub pad: [u32; 3],
}
