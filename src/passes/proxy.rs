//! Sphere proxies under the environment light (paper 002): the `proxy_accumulate` and
//! `proxy_shade` passes and their GPU data (CPU twin: [`crate::reference::proxy`]).
//!
//! * [`proxy_accumulate`] sums, at every receiver, the rotated log-occlusion ZH vectors of the
//!   proxies (eq. 4, 8) and their indirect shading `I_i · H(N_p)` with the summed solid angle
//!   `ω_p` (eq. 12–15), occlusion and indirect light in one tiled compute "splat"
//!   (docs/frame.md, "Proxy GI", says why).
//! * [`proxy_shade`] exponentiates the sum (OL, PS or HYB), shades the environment through the
//!   occlusion (eq. 10), normalises the indirect sum (eq. 12) and writes the outgoing diffuse
//!   and glossy radiance at receiver resolution (`proxy_gi`).
//!
//! Every formula comes from shine-sh ([`shine_sh::sphere_blocker`], [`shine_sh::exp_log`],
//! [`shine_sh::proxy_indirect`]) on the CPU and from `shaders/include/sh.glsl` on the GPU;
//! the CPU twin composes the shine-sh functions exactly as the shaders compose their GLSL
//! twins, and `tests/proxy.rs` ties the two.
//!
//! # Decisions
//!
//! * **Tables.** `O^log(α)` and `V(α)` are [`AlphaTable`]s of [`TABLE_ENTRIES`] rows, smoothly
//!   clamped (§4.1) with the shadow and indirect expansion factors; a third, unclamped `V(α)`
//!   serves the brute-force product. A clamped table is exactly 0 at and below its *support*
//!   `α_0` (the last all-zero row), so the sphere of influence of a proxy of radius `r` is
//!   `r / α_0`: slightly larger than `η r` (17.0 r for η = 15 with 256 rows) because the
//!   smooth ramp starts one row below `1/η`. Splatting with that radius loses nothing: splat
//!   and brute force agree exactly.
//! * **Self-shadowing** ([`shine_sh::sphere_blocker::self_shadow_substitute`]) replaces the proxy for both the shadow and
//!   the indirect accumulation, so a receiver on a proxied object neither shadows nor lights
//!   itself through its own proxy.
//! * **Indirect light** is order 3 (the D(θ) fit of eq. 15): `I_i = (ρ_i/π) κ_i V_i`, with the
//!   proxy's albedo `ρ_i` (base colour of its node's first material) turning the irradiance
//!   `L̃` on the proxy into exitant radiance (the paper leaves the albedo implicit).
//! * **Receiver BRDF** (shine's extension: paper 002 shades Lambert receivers). The
//!   metallic-roughness material, as the HVL gather: `kd`, `ks` from `brdf_indirect_weights`
//!   at n·v; the diffuse part `kd/π · max(ψ_p + ξ_p Σ I_i·H, 0)`, the glossy part
//!   `ks · max(L · (O_p ∗ F_w), 0)` per channel, with `F_w` the receiver's GGX row of the BRDF
//!   SH tables ([`GatherBrdf`], at `θ_o` and its roughness) rotated from the receiver frame
//!   (z = n, ω_o in xz) to the world; `ks` carries the tables' Fresnel weight and
//!   `1 − trace_weight`, the share the traced specular pass leaves. Band-limited ringing is
//!   clamped at 0. The proxies' own indirect light reaches the diffuse part only.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use shine_sh::ShError;
use shine_sh::exp_log::ShExp;
use shine_sh::sphere_blocker::AlphaTable;

use crate::declare::Settings;
use crate::gpu_scene::environment_sh::ORDERS;
use crate::graph::{Buffer, BufferDesc, Handle, Image, RenderGraph};
use crate::shaders;

use super::amortise;
use super::brdf_tables::{GLOSSY_ROUGHNESS_MIN, GLOSSY_TABLES, GatherBrdf, glossy_roughness_step};
use super::receivers::Receivers;

crate::choice::named_choice! {
    /// The SH exponential of the accumulated log-occlusion (paper 002 eq. 4, Ren et al. 2006).
    pub enum ExpMethod ("SH exponentiation method") {
        /// Optimal linear: `a(‖f̂‖) 1 + b(‖f̂‖) f̂`.
        Ol = "ol",
        /// Product series: Taylor series on a scaled-down vector, then repeated squaring.
        Ps = "ps",
        /// Hybrid: OL on a scaled-down vector, then repeated squaring (the paper's choice).
        Hyb = "hyb",
    }
}

/// Rows of the α tables (α = sin θ uniformly in [0, 1]).
pub const TABLE_ENTRIES: usize = 256;
/// Most proxies a frame takes: the accumulation shader's tile mask has 64 words of 32 bits.
pub const MAX_PROXIES: u32 = 2048;
/// The paper's shadow expansion factor η for SH order `bands` (§4.1, paper 002: 10 at order 3,
/// 15 at order 4; shine keeps 15 above).
pub fn paper_expansion(bands: u32) -> f32 {
    if bands <= 3 { 10.0 } else { 15.0 }
}

/// Default SH order of the occlusion and environment: paper 002's shadow order.
pub const DEFAULT_ORDER: u32 = 4;

/// Radius expansion factors η of the spheres of influence (§4.1: 10 at order 3, 15 above).
pub const EXPANSION: std::ops::RangeInclusive<f32> = 2.0..=100.0;
/// Spheres refitted to the mesh of each proxied object (0: the scene's own proxies); a
/// profiling knob of the proxy technique.
pub const FIT_COUNT: std::ops::RangeInclusive<u32> = 0..=64;
/// Bands of the proxy indirect light: the averaged operator D(θ) is fitted to order 3
/// (eq. 15, paper 002).
pub const INDIRECT_BANDS: usize = 3;

/// One proxy on the GPU (std430, 32 bytes): `proxies.p[2i]` and `proxies.p[2i + 1]` in
/// `shaders/proxy_accumulate.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuProxy {
    /// xyz world centre, w radius (metres).
    pub sphere: [f32; 4],
    /// rgb albedo of the proxied surface, a unused.
    pub albedo: [f32; 4],
}

impl GpuProxy {
    /// A proxy at `center` of `radius` and `albedo`.
    pub fn new(center: Vec3, radius: f32, albedo: Vec3) -> Self {
        Self {
            sphere: center.extend(radius).to_array(),
            albedo: albedo.extend(0.0).to_array(),
        }
    }

    pub(crate) fn center(&self) -> Vec3 {
        Vec3::new(self.sphere[0], self.sphere[1], self.sphere[2])
    }

    pub(crate) fn albedo(&self) -> Vec3 {
        Vec3::new(self.albedo[0], self.albedo[1], self.albedo[2])
    }
}

/// How proxies are accumulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Accumulation {
    /// Image-space splatting: per 8×8 receiver tile, proxies whose sphere of influence misses
    /// the tile are culled; each receiver takes the proxies whose sphere contains it.
    Splat,
    /// Every proxy at every receiver, log-occlusion sums as [`Accumulation::Splat`] (tests).
    Brute,
    /// Every proxy at every receiver with unclamped tables; the occlusion is the exact chain of
    /// SH products (no log, no exponential): the brute-force reference mode.
    Product,
}

impl Accumulation {
    fn name(self) -> &'static str {
        match self {
            Accumulation::Splat => "splat",
            Accumulation::Brute => "brute",
            Accumulation::Product => "product",
        }
    }
}

/// `[proxy]`: sphere proxies under the environment light (paper 002), each setting declared
/// once: the proxy passes' parameters ([`ProxySettings::pass`]) and how the technique's GPU
/// data is built (α tables, refitted spheres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Settings)]
#[serde(default, deny_unknown_fields)]
pub struct ProxySettings {
    /// SH order n of the occlusion and the environment (n² coefficients; the paper's shadow
    /// order is 4).
    #[setting(default = DEFAULT_ORDER, range = ORDERS, affects = both)]
    pub sh_order: u32,
    /// Radius expansion factor η of the shadow sphere of influence (§4.1); 0 picks the paper's
    /// value for the order ([`paper_expansion`]: 10 for order 3, 15 for order 4 and above).
    #[setting(default = 0.0, zero_or = EXPANSION, affects = both)]
    pub expansion: f32,
    /// Expansion factor of the indirect sphere of influence (order-3 indirect: 10 in the
    /// paper).
    #[setting(default = paper_expansion(INDIRECT_BANDS as u32), range = EXPANSION, lab = 5.0..=30.0, affects = both)]
    pub indirect_expansion: f32,
    /// SH exponential: `ol`, `ps` or `hyb`.
    #[setting(default = ExpMethod::Hyb, affects = both)]
    pub exp: ExpMethod,
    /// Proxy indirect light (eq. 12–15) on top of the shadowed environment.
    #[setting(default = true, affects = both)]
    pub indirect: bool,
    /// Brute force: every proxy at every receiver, unclamped tables and the exact chain of SH
    /// products instead of log/exp (a reference; slow).
    #[setting(default = false, affects = both)]
    pub brute_force: bool,
    /// 0: the scene's proxies; k: refit k spheres to the mesh of every node that has proxies
    /// (for profiling with many proxies).
    #[setting(default = 0, range = FIT_COUNT, lab = 0..=16, affects = both)]
    pub fit_count: u32,
    /// Receivers per refresh (paper 001): 1 shades every receiver every frame; 4 shades one
    /// receiver per 2×2 cell per frame and reprojects the others from the previous frames
    /// (`proxy_resolve`, src/passes/amortise.rs).
    #[setting(default = 1, one_of = amortise::SLICE_CHOICES, affects = both)]
    pub slices: u32,
    /// Roughness limit of the frame's traced specular pass (0: none; set by the frame).
    #[serde(skip)]
    #[setting(default = 0.0)]
    pub specular_limit: f32,
}

impl ProxySettings {
    /// The parameters of the proxy passes.
    pub fn pass(&self) -> ProxyParams {
        ProxyParams {
            bands: self.sh_order,
            accumulation: if self.brute_force {
                Accumulation::Product
            } else {
                Accumulation::Splat
            },
            exp: self.exp,
            indirect: self.indirect,
            specular_limit: self.specular_limit,
        }
    }

    /// Shadow expansion factor η of the α tables: `expansion`, or the paper's for the order.
    pub fn shadow_expansion(&self) -> f32 {
        if self.expansion > 0.0 {
            self.expansion
        } else {
            paper_expansion(self.sh_order)
        }
    }
}

/// Parameters of the proxy passes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProxyParams {
    /// SH bands n of the occlusion and environment, in [`ORDERS`].
    pub bands: u32,
    /// How proxies are accumulated.
    pub accumulation: Accumulation,
    /// The SH exponential (unused by [`Accumulation::Product`]).
    pub exp: ExpMethod,
    /// Whether the proxy indirect light is accumulated.
    pub indirect: bool,
    /// Roughness limit of the frame's traced specular pass (0: none): the shade pass's glossy
    /// term is scaled by `1 −` [`crate::passes::specular::trace_weight`].
    pub specular_limit: f32,
}

/// What the proxy passes refuse.
#[derive(Debug, thiserror::Error)]
pub enum ProxyError {
    /// A parameter out of its range.
    #[error("proxy parameter `{name}` = {value} is out of range: {expected}")]
    OutOfRange {
        /// The parameter.
        name: &'static str,
        /// Its value.
        value: f64,
        /// The allowed range.
        expected: String,
    },
    /// An input of the wrong size.
    #[error("proxy input `{name}` is {actual}, expected {expected}")]
    Size {
        /// Which input.
        name: &'static str,
        /// What it is.
        actual: String,
        /// What it should be.
        expected: String,
    },
    /// No compiled shader for the parameters.
    #[error("no compiled shader `{0}` (see the variants of shaders/proxy_*.comp)")]
    Variant(String),
    /// An amortised dispatch's slice without its marks, or out of range.
    #[error(transparent)]
    Slice(#[from] amortise::AmortiseError),
    /// An SH table or projection failed.
    #[error("proxy SH: {0}")]
    Sh(#[from] ShError),
    /// The scene has no environment to light it.
    #[error(
        "--gi proxy needs an environment light: this scene has none (add `shine_environment` \
         to the glTF root extras, or pass --environment FILE)"
    )]
    NoEnvironment,
    /// More proxy spheres than one frame takes.
    #[error("{0} proxy spheres: at most {max} are supported", max = MAX_PROXIES)]
    TooMany(usize),
}

impl ProxyParams {
    pub(crate) fn check(&self) -> Result<usize, ProxyError> {
        if !ORDERS.contains(&self.bands) {
            return Err(ProxyError::OutOfRange {
                name: "bands",
                value: f64::from(self.bands),
                expected: format!("{ORDERS:?}"),
            });
        }
        Ok(self.bands as usize)
    }

    fn accumulate_shader(&self) -> Result<&'static crate::gpu::ShaderDesc, ProxyError> {
        self.check()?;
        let name = format!(
            "proxy_accumulate.comp:{}_b{}",
            self.accumulation.name(),
            self.bands
        );
        shaders::get(&name).ok_or(ProxyError::Variant(name))
    }

    fn shade_shader(&self) -> Result<&'static crate::gpu::ShaderDesc, ProxyError> {
        self.check()?;
        let method = match (self.accumulation, self.exp) {
            (Accumulation::Product, _) => "product",
            (_, ExpMethod::Hyb) => "hyb",
            (_, ExpMethod::Ps) => "ps",
            (_, ExpMethod::Ol) => "ol",
        };
        let name = format!("proxy_shade.comp:{method}_b{}", self.bands);
        shaders::get(&name).ok_or(ProxyError::Variant(name))
    }
}

/// The α tables of the accumulation (GPU buffer `tables`): clamped log-occlusion, clamped
/// visibility, unclamped visibility, each [`TABLE_ENTRIES`] rows of `bands` floats, then the
/// OL exponential's table of shine-sh (step, `a`, `b`; read by the OL shading variant).
#[derive(Debug, Clone, PartialEq)]
pub struct ProxyTables {
    /// `O^log(α)` smoothly clamped with the shadow expansion factor.
    pub log_occlusion: AlphaTable,
    /// `V(α)` smoothly clamped with the indirect expansion factor.
    pub visibility: AlphaTable,
    /// `V(α)` unclamped (brute-force product).
    pub visibility_full: AlphaTable,
    /// Largest α at which `log_occlusion` is exactly 0 (its rows up to it are all zero).
    pub support_shadow: f32,
    /// Largest α at which `visibility` is exactly 0.
    pub support_indirect: f32,
    /// [`shine_sh::exp_log::OlTable`] of the band count: step, `a` samples, `b` samples.
    pub ol: Vec<f32>,
    /// [`shine_sh::glsl_tables::tensor_pairs`] of the band count: the entry count, packed
    /// `ijk` (as floats, exact below 2²⁴), then values.
    pub tensor: Vec<f32>,
}

/// The largest α such that every row of `table` at or below it is all zeros.
fn support(table: &AlphaTable) -> f32 {
    let n = table.bands();
    let zero_rows = table
        .data()
        .chunks_exact(n)
        .take_while(|row| row.iter().all(|&x| x == 0.0))
        .count();
    if zero_rows == 0 {
        0.0
    } else {
        (zero_rows - 1) as f32 / (table.entries() - 1) as f32
    }
}

impl ProxyTables {
    /// Builds the tables for `bands` bands and the shadow / indirect expansion factors η
    /// (§4.1: 15 for order 4, 10 for order 3).
    pub fn build(bands: u32, eta_shadow: f32, eta_indirect: f32) -> Result<Self, ProxyError> {
        let bands = ProxyParams {
            bands,
            accumulation: Accumulation::Splat,
            exp: ExpMethod::Hyb,
            indirect: true,
            specular_limit: 0.0,
        }
        .check()?;
        let mut log_occlusion = AlphaTable::log_visibility(bands, TABLE_ENTRIES)?;
        log_occlusion.smooth_clamp(eta_shadow)?;
        let mut visibility = AlphaTable::visibility(bands, TABLE_ENTRIES)?;
        visibility.smooth_clamp(eta_indirect)?;
        let visibility_full = AlphaTable::visibility(bands, TABLE_ENTRIES)?;
        let exp = ShExp::new(bands)?;
        let (a, b) = exp.ol_table().samples();
        let ol = std::iter::once(exp.ol_table().step())
            .chain(a.iter().copied())
            .chain(b.iter().copied())
            .map(|x| x as f32)
            .collect();
        let (ijk, values) = shine_sh::glsl_tables::tensor_pairs(bands)?;
        let tensor = std::iter::once(ijk.len() as f32)
            .chain(ijk.iter().map(|&x| x as f32))
            .chain(values)
            .collect();
        Ok(Self {
            ol,
            tensor,
            support_shadow: support(&log_occlusion),
            support_indirect: support(&visibility),
            log_occlusion,
            visibility,
            visibility_full,
        })
    }

    /// The GPU buffer `tables`.
    pub fn gpu_data(&self) -> Vec<f32> {
        [
            self.log_occlusion.data(),
            self.visibility.data(),
            self.visibility_full.data(),
            &self.ol,
            &self.tensor,
        ]
        .concat()
    }

    /// Float offset of the OL table in [`ProxyTables::gpu_data`].
    pub fn ol_offset(&self) -> usize {
        3 * TABLE_ENTRIES * self.log_occlusion.bands()
    }
}

/// Push constants of `shaders/proxy_accumulate.comp` (32 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct AccumulatePush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Number of proxies.
    pub proxy_count: u32,
    /// Rows of each α table.
    pub table_entries: u32,
    /// [`ProxyTables::support_shadow`].
    pub support_shadow: f32,
    /// [`ProxyTables::support_indirect`] (the shadow one when indirect light is off).
    pub support_indirect: f32,
    /// 1: accumulate the indirect sums.
    pub indirect: u32,
    /// The receivers of this dispatch ([`ProxySlice::slice`]).
    pub slice: u32,
}

/// Push constants of `shaders/proxy_tiles.comp` (16 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TilesPush {
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Number of proxies.
    pub proxy_count: u32,
    /// The smaller of the two supports in [`AccumulatePush`].
    pub support: f32,
}

/// Side of a culling tile in receivers.
pub const TILE: u32 = 8;
/// Words of a tile's proxy mask (`MAX_PROXIES / 32`).
pub const TILE_WORDS: u32 = MAX_PROXIES / 32;

/// Push constants of `shaders/proxy_shade.comp` (48 bytes).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct ShadePush {
    /// xyz: camera position; w: the specular pass's roughness limit (0: none).
    pub camera: [f32; 4],
    /// Receiver buffer size.
    pub extent: [u32; 2],
    /// Roughness of the first glossy table, step between tables.
    pub roughness_nodes: [f32; 2],
    /// Number of glossy tables.
    pub glossy_tables: u32,
    /// The receivers of this dispatch ([`ProxySlice::slice`]).
    pub slice: u32,
    /// Padding.
    pub pad: [u32; 2],
}

/// Floats per receiver in the `proxy_sums` buffer: `bands²` (log-occlusion, or occlusion for
/// [`Accumulation::Product`]), then rgb `Σ I_i · H(N_p)` and `ω_p`.
pub fn sums_stride(bands: u32) -> usize {
    (bands * bands) as usize + 4
}

/// The GPU buffers the proxy passes read.
#[derive(Debug, Clone, Copy)]
pub struct ProxyInputs {
    /// [`GpuProxy`] records.
    pub proxies: Handle<Buffer>,
    /// How many records `proxies` holds (at most [`MAX_PROXIES`]).
    pub count: u32,
    /// [`ProxyTables::gpu_data`] at the parameters' band count.
    pub tables: Handle<Buffer>,
    /// [`EnvironmentSh::gpu_data`] at the parameters' band count.
    ///
    /// [`EnvironmentSh::gpu_data`]: crate::gpu_scene::environment_sh::EnvironmentSh::gpu_data
    pub environment: Handle<Buffer>,
    /// [`GatherBrdf::gpu_data`] at the parameters' band count: the shade pass's glossy
    /// receivers.
    pub brdf: Handle<Buffer>,
}

/// Which receivers one dispatch of the proxy passes shades: paper 001's amortised frames
/// (`proxy.slices`, [`crate::passes::amortise`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct ProxySlice {
    /// 0: every receiver; 1 + k: the receiver at (k & 1, k >> 1) of every 2×2 cell;
    /// [`amortise::REGATHER_SLICE`]: the receivers `marks` marks with alpha −1.
    pub slice: u32,
    /// The proxy light after `proxy_regather_mask` (the regather reads its marks and writes
    /// into it); required by the regather slice.
    pub marks: Option<Handle<Image>>,
    /// The tile lists of the frame's first dispatch, which the regather reuses (`None`: built
    /// by this dispatch).
    pub masks: Option<Handle<Buffer>>,
}

/// The outputs of [`proxy_shade`].
#[derive(Debug, Clone, Copy)]
pub struct ProxyOutputs {
    /// `proxy_gi`: RGBA16F at receiver resolution, outgoing radiance (a = 0, 0 on background).
    pub radiance: Handle<Image>,
    /// `proxy_occlusion`: `bands²` floats per receiver, the occlusion vector `O_p` (at the
    /// receivers of the dispatch's slice only).
    pub occlusion: Handle<Buffer>,
}

fn check_inputs(
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
) -> Result<(), ProxyError> {
    let bands = params.check()?;
    if inputs.count > MAX_PROXIES {
        return Err(ProxyError::OutOfRange {
            name: "proxy count",
            value: f64::from(inputs.count),
            expected: format!("0..={MAX_PROXIES}"),
        });
    }
    let need = u64::from(inputs.count.max(1)) * std::mem::size_of::<GpuProxy>() as u64;
    let sizes = [
        ("proxies", inputs.proxies.desc().size, need),
        (
            "tables",
            inputs.tables.desc().size,
            (tables.gpu_data().len() * 4) as u64,
        ),
        (
            "environment",
            inputs.environment.desc().size,
            (6 * bands * bands * 4) as u64,
        ),
        (
            "brdf",
            inputs.brdf.desc().size,
            GatherBrdf::gpu_bytes(params.bands),
        ),
    ];
    for (name, actual, expected) in sizes {
        let ok = if name == "proxies" {
            actual >= expected
        } else {
            actual == expected
        };
        if !ok {
            return Err(ProxyError::Size {
                name,
                actual: format!("{actual} bytes"),
                expected: format!("{expected} bytes"),
            });
        }
    }
    if tables.log_occlusion.bands() != bands {
        return Err(ProxyError::Size {
            name: "tables",
            actual: format!("{} bands", tables.log_occlusion.bands()),
            expected: format!("{bands} bands"),
        });
    }
    let [w, h] = receivers.extent;
    if w == 0 || h == 0 {
        return Err(ProxyError::Size {
            name: "receivers",
            actual: format!("{w}×{h}"),
            expected: "a non-empty extent".into(),
        });
    }
    Ok(())
}

/// Adds the `proxy_accumulate` pass at every receiver: a new `proxy_sums` buffer
/// ([`sums_stride`] floats per receiver, row-major), returned.
pub fn proxy_accumulate(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
) -> Result<Handle<Buffer>, ProxyError> {
    let (sums, _) =
        proxy_accumulate_slice(rg, receivers, inputs, tables, params, ProxySlice::default())?;
    Ok(sums)
}

/// Adds `proxy_tiles` (for splatting, unless `slice` brings the frame's tile lists) and
/// `proxy_accumulate` (`proxy_reaccumulate` for the regather slice) at the receivers of
/// `slice`: returns a new `proxy_sums` buffer, valid at those receivers, and the tile lists.
pub fn proxy_accumulate_slice(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    slice: ProxySlice,
) -> Result<(Handle<Buffer>, Option<Handle<Buffer>>), ProxyError> {
    check_inputs(receivers, inputs, tables, params)?;
    let marks = checked_marks(&slice)?;
    let shader = params.accumulate_shader()?;
    let [w, h] = receivers.extent;
    let support_indirect = if params.indirect {
        tables.support_indirect
    } else {
        tables.support_shadow
    };
    let masks = if params.accumulation != Accumulation::Splat {
        None
    } else if let Some(masks) = slice.masks {
        Some(masks)
    } else {
        let tiles = [w.div_ceil(TILE), h.div_ceil(TILE)];
        let bytes = u64::from(tiles[0]) * u64::from(tiles[1]) * u64::from(TILE_WORDS) * 4;
        let mut masks = rg.create_buffer("proxy_tile_masks", BufferDesc::new(bytes));
        rg.compute("proxy_tiles", &shaders::PROXY_TILES_COMP)
            .read("recv_position", &receivers.position)
            .read("proxies", &inputs.proxies)
            .write("tile_masks", &mut masks)
            .push(&TilesPush {
                extent: receivers.extent,
                proxy_count: inputs.count,
                support: tables.support_shadow.min(support_indirect),
            })
            .dispatch([tiles[0], tiles[1], 1]);
        Some(masks)
    };
    let bytes = u64::from(w) * u64::from(h) * sums_stride(params.bands) as u64 * 4;
    let mut sums = rg.create_buffer("proxy_sums", BufferDesc::new(bytes));
    let push = AccumulatePush {
        extent: receivers.extent,
        proxy_count: inputs.count,
        table_entries: TABLE_ENTRIES as u32,
        support_shadow: tables.support_shadow,
        support_indirect,
        indirect: u32::from(params.indirect),
        slice: slice.slice,
    };
    let name = if slice.slice == amortise::REGATHER_SLICE {
        "proxy_reaccumulate"
    } else {
        "proxy_accumulate"
    };
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("proxies", &inputs.proxies)
        .read("tables", &inputs.tables)
        .read("environment", &inputs.environment);
    if let Some(masks) = &masks {
        pass.read("tile_masks", masks);
    }
    // Read only by the regather slice; any receiver-sized RGBA16F image fills the binding
    // of the others.
    pass.read("marks", marks.unwrap_or(&receivers.normal))
        .write("sums", &mut sums)
        .push(&push)
        .dispatch(amortise::slice_threads([w, h], slice.slice));
    Ok((sums, masks))
}

/// The marks of `slice`, after checking that the regather slice has them and no other slice
/// is out of range.
fn checked_marks(slice: &ProxySlice) -> Result<Option<&Handle<Image>>, ProxyError> {
    amortise::check_slice(slice.slice, slice.marks.is_some())?;
    Ok(slice.marks.as_ref())
}

/// Adds the `proxy_shade` pass over the sums of [`proxy_accumulate`] (`inputs.proxies` is not
/// read), the receivers seen from `camera` (their glossy lobes).
pub fn proxy_shade(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    sums: &Handle<Buffer>,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    camera: Vec3,
) -> Result<ProxyOutputs, ProxyError> {
    let slice = ProxySlice::default();
    proxy_shade_slice(rg, receivers, sums, inputs, tables, params, camera, slice)
}

/// [`proxy_shade`] at the receivers of `slice` (`proxy_reshade` for the regather slice, which
/// writes into its marks; a new `proxy_gi` otherwise, valid at the slice's receivers).
#[allow(clippy::too_many_arguments)]
pub fn proxy_shade_slice(
    rg: &mut RenderGraph,
    receivers: &Receivers,
    sums: &Handle<Buffer>,
    inputs: &ProxyInputs,
    tables: &ProxyTables,
    params: &ProxyParams,
    camera: Vec3,
    slice: ProxySlice,
) -> Result<ProxyOutputs, ProxyError> {
    check_inputs(receivers, inputs, tables, params)?;
    let marks = checked_marks(&slice)?.copied();
    let shader = params.shade_shader()?;
    let table_bytes = (tables.gpu_data().len() * 4) as u64;
    if inputs.tables.desc().size != table_bytes {
        return Err(ProxyError::Size {
            name: "tables",
            actual: format!("{} bytes", inputs.tables.desc().size),
            expected: format!("{table_bytes} bytes"),
        });
    }
    let [w, h] = receivers.extent;
    let texels = u64::from(w) * u64::from(h);
    let need = texels * sums_stride(params.bands) as u64 * 4;
    if sums.desc().size != need {
        return Err(ProxyError::Size {
            name: "proxy_sums",
            actual: format!("{} bytes", sums.desc().size),
            expected: format!("{need} bytes"),
        });
    }
    let (mut radiance, name) = match marks {
        Some(marks) if slice.slice == amortise::REGATHER_SLICE => (marks, "proxy_reshade"),
        _ => (receivers.light_image(rg, "proxy_gi"), "proxy_shade"),
    };
    let coeffs = u64::from(params.bands * params.bands);
    let mut occlusion = rg.create_buffer("proxy_occlusion", BufferDesc::new(texels * coeffs * 4));
    let push = ShadePush {
        camera: camera.extend(params.specular_limit).to_array(),
        extent: receivers.extent,
        roughness_nodes: [GLOSSY_ROUGHNESS_MIN, glossy_roughness_step()],
        glossy_tables: GLOSSY_TABLES,
        slice: slice.slice,
        pad: [0; 2],
    };
    let mut pass = rg.compute(name, shader);
    pass.read("recv_position", &receivers.position)
        .read("recv_normal", &receivers.normal)
        .read("recv_albedo", &receivers.albedo)
        .read("recv_material", &receivers.material)
        .read("sums", sums)
        .read("environment", &inputs.environment)
        .read("brdf", &inputs.brdf);
    pass.read("tables", &inputs.tables)
        .write("occlusion", &mut occlusion)
        .write("proxy_gi", &mut radiance)
        .push(&push)
        .dispatch(amortise::slice_threads([w, h], slice.slice));
    Ok(ProxyOutputs {
        radiance,
        occlusion,
    })
}
