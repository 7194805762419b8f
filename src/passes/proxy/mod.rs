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
//! * **Tables.** `O^log(α)` and `V(α)` are [`AlphaTable`](shine_sh::sphere_blocker::AlphaTable)s of [`TABLE_ENTRIES`] rows, smoothly
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
//!   SH tables ([`GatherBrdf`](crate::passes::brdf_tables::GatherBrdf), at `θ_o` and its roughness) rotated from the receiver frame
//!   (z = n, ω_o in xz) to the world; `ks` carries the tables' Fresnel weight and
//!   `1 − trace_weight`, the share the traced specular pass leaves. Band-limited ringing is
//!   clamped at 0. The proxies' own indirect light reaches the diffuse part only.

use glam::Vec3;
use serde::{Deserialize, Serialize};
use shine_sh::ShError;

use crate::declare::Settings;
use crate::gpu_scene::environment_sh::ORDERS;
use crate::passes::amortise;
use crate::shaders;

mod dispatch;
mod tables;

pub use dispatch::{
    AccumulatePush, ProxyInputs, ProxyOutputs, ProxySlice, ShadePush, TILE, TILE_WORDS, TilesPush,
    proxy_accumulate, proxy_accumulate_slice, proxy_shade, proxy_shade_slice, sums_stride,
};
pub use tables::ProxyTables;

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
