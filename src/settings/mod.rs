//! Every user-facing knob of a frame, as one serde struct (issue 6).
//!
//! Settings come from a TOML file ([`Settings::load`], [`Settings::from_toml_str`]) and from
//! command-line flags ([`Settings::set`] with a dotted key such as `hvl.count`), over the
//! defaults of [`Settings::default`]. Every field documents its range and default;
//! [`Settings::validate`] rejects a value outside its range with an error naming the field, the
//! value and what is allowed, so an absurd setting never reaches the GPU.
//!
//! The settings only choose: each range, default and named choice belongs to the pass that
//! uses it (`passes::hvl::CACHE_COUNT`, `passes::igi::FilterMode`, …), and
//! `frame::params::FrameParams::from_settings` is the one conversion into pass parameters.
//!
//! ```toml
//! width = 1280
//! height = 720
//! gi = "hvl"            # or "none", "proxy", "hvl,proxy"
//! receiver_scale = 2
//!
//! [output]
//! tonemap = "pbr-neutral"
//! exposure = 1.0
//!
//! [hvl]
//! count = 400
//! radius = "r2"
//! ```

mod cubes;
mod error;
mod gi;
mod io;
mod sky;
mod specular;
mod validate;

pub use cubes::CubeSettings;
pub use error::SettingsError;
pub use gi::{GiTechnique, GiTechniques};
pub use sky::{CavitySettings, SkySettings};
pub use specular::SpecularSettings;
pub use validate::{EXTENT, FRAMES, TIME};

use serde::{Deserialize, Serialize};

use crate::capture::tonemap::Tonemap;
use crate::passes::aaf::AafParams;
use crate::passes::accumulate::AccumulateParams;
use crate::passes::composite::{self, Component, CompositeParams};
use crate::passes::exposure::ExposureParams;
use crate::passes::hvl::near::NearField;
use crate::passes::hvl::{Distribution, Falloff, GatherPath, HvlParams, RadiusHeuristic, Window};
use crate::passes::igi::{FilterMode, Glossy, IgiParams};
use crate::passes::proxy::{DEFAULT_ORDER, ExpMethod, INDIRECT_BANDS, paper_expansion};
use crate::passes::upsample::{DEPTH_SIGMA, NORMAL_POWER_N};
use crate::passes::{rsm, shadows};

/// Everything that decides what a frame computes and how it is written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// Output width in pixels. Range 1..=16384, default 1280.
    pub width: u32,
    /// Output height in pixels. Range 1..=16384, default 720.
    pub height: u32,
    /// Number of frames rendered (accumulated GI caches and animation advance per frame).
    /// Range 1..=100000, default 1.
    pub frames: u32,
    /// Scene animation time of the first frame, in seconds. Range 0.0..=100000.0, default 0.0.
    pub time: f32,
    /// GI techniques combined in the frame: `hvl`, `proxy`, `hvl,proxy` or `none` (direct
    /// light only). Default `hvl`.
    pub gi: GiTechniques,
    /// Receiver-buffer downscale s: expensive GI runs at W/s × H/s (paper 002 §4.2).
    /// One of 1, 2, 4; default 2.
    pub receiver_scale: u32,
    /// Tonemapping and exposure.
    pub output: OutputSettings,
    /// Harmonics Virtual Lights (paper 003).
    pub hvl: HvlSettings,
    /// Reflective shadow map of each primary light.
    pub rsm: RsmSettings,
    /// Shadow maps of the direct light.
    pub shadow: ShadowSettings,
    /// Texture filtering of the raster passes.
    pub texture: TextureSettings,
    /// Joint bilateral upsampling of the receiver-resolution GI (paper 002 eq. 11).
    pub upsample: UpsampleSettings,
    /// Instant GI with SH-filtered incoming radiance (paper 000).
    pub igi: IgiSettings,
    /// Sphere-proxy soft shadows and indirect light under the environment (paper 002).
    pub proxy: ProxySettings,
    /// Axis-aligned filtering of path-traced indirect light (paper 004).
    pub aaf: AafSettings,
    /// The indirect light accumulated over the frames of a sequence (issue 23).
    pub history: HistorySettings,
    /// Traced specular reflections (issue 21).
    pub specular: SpecularSettings,
    /// The sky light of frames without proxies (issue 16).
    pub sky: SkySettings,
    /// Cavity shading of HVL's indirect light (issue 18).
    pub cavity: CavitySettings,
    /// Tiny environment cubes for the dynamic objects (issue 18).
    pub cubes: CubeSettings,
}

/// `[history]`: the indirect light accumulated over frames (`src/passes/accumulate.rs`):
/// reprojected with the motion vectors, rejected on disocclusion, clipped to the current
/// neighbourhood. A single still frame is unchanged (it has no history).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HistorySettings {
    /// Longest history n in frames: each frame blends in at least 1/n of its own light
    /// (1: no accumulation). Range 1..=256, default 8.
    pub frames: u32,
    /// Half-width of the clip box in standard deviations of the current 3×3 neighbourhood
    /// (0: history not clipped). Range 0.0..=16.0, default 3.0.
    pub clip: f32,
}

impl Default for HistorySettings {
    /// The defaults of the accumulate pass ([`AccumulateParams::default`]).
    fn default() -> Self {
        let a = AccumulateParams::default();
        Self {
            frames: a.max_frames,
            clip: a.clip,
        }
    }
}

/// `[aaf]`: axis-aligned filtering of path-traced indirect light (paper 004,
/// `src/passes/aaf/`). Defaults are the paper's, except the filter's fit (`filter_degree`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AafSettings {
    /// Stratified samples per pixel of the first pass. Range 1..=1024, default 16.
    pub samples: u32,
    /// Filter scale μ (eq. 15, 21): larger narrows the filter and samples more. Range
    /// 0.01..=100.0, default 0.9.
    pub mu: f32,
    /// Bandlimit Ω_h of the receiver's transfer function (eq. 18). Range 0.1..=100.0,
    /// default 2.8 (Lambert).
    pub omega_h: f32,
    /// Lower clamp of the samples per pixel. Range 16..=1024, default 16.
    pub spp_min: u32,
    /// Upper clamp of the samples per pixel before the factor μ (the paper's 100μ).
    /// Range 16..=10000, default 100.
    pub spp_max: u32,
    /// Path vertices after the receiver (1: one-bounce indirect). Range 1..=8, default 1.
    pub bounces: u32,
    /// The adaptive second pass (eq. 21); off: uniform sampling at `samples`. Default true.
    pub adaptive: bool,
    /// The screen-space filter; off: the unfiltered Monte-Carlo mean. Default true.
    pub filter: bool,
    /// Degree of the filter's local polynomial fit with the paper's gaussian weights: 0 is
    /// paper 004's gaussian, 1 linear, 2 quadratic (keeps the light's peaks and edges the
    /// gaussian flattens, but removes less noise where the filter has few neighbours;
    /// docs/quality.md). Range 0..=2, default 2.
    pub filter_degree: u32,
    /// Filter the diffuse light as an irradiance vector, neighbours tested by their geometric
    /// normals, evaluated at each pixel's shading normal, so that a normal map does not cut the
    /// filter (shine's; false is the paper's scalar filter, shading normals tested). Default
    /// true.
    pub irradiance_vector: bool,
    /// Pixels per refresh (paper 001): 1 samples every pixel every frame; 4 samples one pixel
    /// per 2×2 cell per frame and reprojects the others' sums from the previous frames
    /// (`aaf_reproject`, src/passes/amortise.rs). Default 1.
    pub slices: u32,
}

impl Default for AafSettings {
    /// The defaults of the AAF passes ([`AafParams::default`]).
    fn default() -> Self {
        let p = AafParams::default();
        Self {
            samples: p.first_samples,
            mu: p.mu,
            omega_h: p.omega_h,
            spp_min: p.spp_min,
            spp_max: p.spp_max,
            bounces: p.bounces,
            adaptive: p.adaptive,
            filter: p.filter,
            filter_degree: p.filter_degree,
            irradiance_vector: p.irradiance_vector,
            slices: p.slices,
        }
    }
}

/// `[proxy]`: sphere proxies under the environment light (paper 002).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProxySettings {
    /// SH order n of the occlusion and the environment (n² coefficients). Range 3..=6,
    /// default 4 (the paper's shadow order).
    pub sh_order: u32,
    /// Radius expansion factor η of the shadow sphere of influence (§4.1); 0 picks the paper's
    /// value for the order: 10 for order 3, 15 for order 4 and above. Range 0 or 2.0..=100.0,
    /// default 0.
    pub expansion: f32,
    /// Expansion factor of the indirect sphere of influence (order-3 indirect: 10 in the
    /// paper). Range 2.0..=100.0, default 10.0.
    pub indirect_expansion: f32,
    /// SH exponential: `ol`, `ps` or `hyb`. Default `hyb`.
    pub exp: ExpMethod,
    /// Proxy indirect light (eq. 12–15) on top of the shadowed environment. Default true.
    pub indirect: bool,
    /// Brute force: every proxy at every receiver, unclamped tables and the exact chain of SH
    /// products instead of log/exp (a reference; slow). Default false.
    pub brute_force: bool,
    /// 0: the scene's proxies; k in 1..=64: refit k spheres to the mesh of every node that has
    /// proxies (for profiling with many proxies). Default 0.
    pub fit_count: u32,
    /// Receivers per refresh (paper 001): 1 shades every receiver every frame; 4 shades one
    /// receiver per 2×2 cell per frame and reprojects the others from the previous frames
    /// (`proxy_resolve`, src/passes/amortise.rs). Default 1.
    pub slices: u32,
}

/// `[output]`: how the HDR frame becomes the written image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSettings {
    /// Tonemap operator of the LDR (PNG) output: `none`, `aces`, `pbr-neutral`, `agx`.
    /// Default `pbr-neutral`. EXR output stays linear HDR.
    pub tonemap: Tonemap,
    /// Linear factor applied to radiance before tonemapping (and in the EXR); with
    /// `auto_exposure` a compensation on top of the automatic exposure.
    /// Range 1e-6..=1e6, default 1.0.
    pub exposure: f32,
    /// Automatic exposure of the tonemapped (PNG) frame: each frame's log-average luminance
    /// is mapped to middle grey (Reinhard et al. 2002, key 0.18; `src/passes/exposure.rs`).
    /// The EXR frame stays scene-referred (`exposure` only). Default true.
    pub auto_exposure: bool,
    /// Fraction of the way (in log exposure) each frame of a sequence moves towards its
    /// automatic exposure (1: at once). Range 0.001..=1.0, default 0.1.
    pub adaptation: f32,
    /// Radiance shown: `full`, `direct` or `indirect` (GI only). Default `full`.
    pub component: Component,
    /// Supersampling N: the frame is rendered at N × width by N × height and each output pixel
    /// is the box average of N×N of them, before tonemapping (antialiasing for captures; GI
    /// contexts render at the host's G-buffer size and ignore it). 0: automatic, the largest N
    /// ≤ 2 whose rendered frame has at most 1024² pixels (`shine render`'s default without a
    /// settings file). Range 0..=4 with N × width and N × height at most 16384, default 1.
    pub ssaa: u32,
    /// Temporal antialiasing for sequences and real time: the camera jitters through 8 Halton
    /// points and the direct light is accumulated over up to 16 frames, reprojected with the
    /// motion vectors and clipped to the current neighbourhood (the indirect light has its
    /// own history, `[history]`). A single frame is unchanged. Default false.
    pub taa: bool,
}

/// `[hvl]`: Harmonics Virtual Lights (paper 003).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HvlSettings {
    /// Number M of HVLs distributed from the RSM (any count: the RSM is cut into M cells).
    /// Range 64..=10000 and at most `rsm.size²`, default 400 (paper 003 fig. 10).
    pub count: u32,
    /// Where the HVLs are placed on the RSM: `grid` (paper 003 §5.2: cells uniform in the
    /// RSM's image) or `flux` (texels drawn in proportion to the flux they reflect, radii from
    /// the local spacing; needs `radius = "r2"`). Default `flux`.
    pub distribution: Distribution,
    /// Radius heuristic: `r1` (eq. 23) or `r2` (eq. 24–26). Default `r2`.
    pub radius: RadiusHeuristic,
    /// User factor k scaling every radius (paper 003 §5.3: good between 1 and 2).
    /// Range 1.0..=2.0, default 1.5.
    pub radius_scale: f32,
    /// SH bands n of the convolution at shaded points (n² coefficients). Range 1..=10,
    /// default 5.
    pub convolution_bands: u32,
    /// SH bands of each HVL's emission function. Range 1..=5 and at most
    /// `convolution_bands`, default 3 (the paper's). Every sender is Lambert today, whose
    /// emission is isotropic and needs band 0 only (paper 003 eq. 20): more bands change
    /// nothing until glossy senders exist.
    pub emission_bands: u32,
    /// Shadow the HVLs through the scene's BVH (shine's extension: paper 003's HVLs are
    /// unshadowed; false gives the paper's). Default true.
    pub visibility: bool,
    /// With `visibility`: shadow rays per receiver, to HVLs drawn in proportion to their
    /// light and denoised by a ratio estimator (`src/passes/hvl/shadows.rs`); 0 traces one
    /// ray per receiver and HVL (exact, about 10× the gather's cost). Range 0..=16, default 8.
    pub shadow_rays: u32,
    /// Radius in receivers of the sampled shadows' ratio filter. Range 0..=8, default 4.
    pub shadow_filter_radius: u32,
    /// R of the traced near field, as a fraction of the scene's largest side: light from
    /// surfaces closer than R comes from `near_rays` traced rays instead of the HVLs, which
    /// cap it, blended over R..2R (`src/passes/hvl/near.rs`). 0: none (paper 003). Range
    /// 0.0..=0.5, default 0.05.
    pub near_range: f32,
    /// Rays per receiver of the near field. Range 1..=256, default 4.
    pub near_rays: u32,
    /// Gather path: `full` (any BRDF, O(n²)) or `zonal` (symmetric lobes, O(n)).
    /// Default `full`.
    pub gather: GatherPath,
    /// Window on each HVL's SH bands against ringing: `none` or `sinc` (paper 003 §4.2,
    /// Sloan's sinc of width `convolution_bands`). Default `none`.
    pub window: Window,
    /// Near-field falloff of each HVL: `sphere` (paper 003 eq. 20–22: the point-light
    /// irradiance up to the sphere's surface) or `disc` (a Lambertian disc of the same area:
    /// half of that at the rim). Default `sphere`.
    pub falloff: Falloff,
    /// Receivers per gather refresh (paper 001): 1 gathers every receiver every frame; 4
    /// gathers one receiver per 2×2 cell per frame and reprojects the others from the
    /// previous frames (`hvl_resolve`). Default 1.
    pub slices: u32,
}

/// `[rsm]`: reflective shadow map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RsmSettings {
    /// RSM side S in texels (S×S per primary light). Range 16..=4096, default 512.
    pub size: u32,
}

/// `[texture]`: how the raster passes filter the scene's textures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureSettings {
    /// Trilinear filtering over the mip chains built at upload (false: the full-resolution
    /// level only, point-exact against the path tracer, which reads level 0 at each hit).
    /// Default true.
    pub mipmaps: bool,
}

impl Default for TextureSettings {
    fn default() -> Self {
        Self { mipmaps: true }
    }
}

/// `[shadow]`: shadow maps of the direct light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// Shadow-map side in texels. Range 64..=16384, default 2048.
    pub size: u32,
    /// Percentage-closer filter radius in shadow-map texels (0: a single hard tap).
    /// Range 0.0..=16.0, default 1.5.
    pub filter_radius: f32,
}

/// `[upsample]`: joint bilateral upsampling weights (paper 002 eq. 11).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UpsampleSettings {
    /// σ_z of the depth weight 1 / (1 + |z_p − z_i| / (σ_z z_p)): paper 002 eq. 11's ε made
    /// relative to the pixel's linear depth z_p, so it does not depend on the scene's scale.
    /// Range 1e-6..=10.0, default 0.01.
    pub depth_epsilon: f32,
    /// Exponent p of the normal weight (N_p · N_i)^p. Range 1.0..=256.0, default 32.0
    /// (paper 002).
    pub normal_power: f32,
}

/// `[igi]`: instant global illumination with interleaved sampling and SH-filtered incident
/// radiance (paper 000, `src/passes/igi.rs`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IgiSettings {
    /// Interleaving pattern width n (VPL sets per row of a tile). Range 1..=8, default 4.
    pub n: u32,
    /// Interleaving pattern height m. Range 1..=8, default 4.
    pub m: u32,
    /// Number of VPLs taken from the RSM (cut into exactly this many cells), shared out over
    /// the n·m sets. Range 64..=10000 and at most `rsm.size²`, default 256.
    pub vpl_count: u32,
    /// Where the VPLs are placed on the RSM: `grid` (cells uniform in the RSM's image) or
    /// `flux` (texels drawn in proportion to their reflected flux), as `hvl.distribution`.
    /// Default `flux`.
    pub distribution: Distribution,
    /// SH order (bands) of the per-pixel incident radiance: 2, 3 or 4 (4, 9 or 16
    /// coefficients). Default 3 (paper 000 §3.1).
    pub sh_order: u32,
    /// Size k of the discontinuity filter's window in interleaving tiles: k·n × k·m pixels
    /// around the pixel, every set counted k² times (0: no filter; 1: exactly one tile, as
    /// paper 000 §2.3). Range 0..=4, default 1.
    pub filter_radius: u32,
    /// What is filtered: `sh` (paper 000) or `irradiance` (classic IGI). Default `sh`.
    pub filter: FilterMode,
    /// Glossy lobe of the SH mode: `ggx` (BRDF SH tables) or `phong` (paper 000 §3.3.2).
    /// Default `ggx`.
    pub glossy: Glossy,
    /// Minimum VPL distance d_min in metres: 1/d² is evaluated as 1/max(d², d_min²) (the VPL
    /// singularity clamp). Range 0.0..=10.0, default 0.1.
    pub clamp_distance: f32,
    /// Relative depth tolerance of the filter: a neighbour q is used when
    /// |z_q − z_p| ≤ depth_tolerance · z_p. Range 1e-4..=1.0, default 0.05.
    pub depth_tolerance: f32,
    /// Cosine threshold of the filter's geometric-normal test (n_p · n_q ≥ this).
    /// Range -1.0..=1.0, default 0.9.
    pub normal_threshold: f32,
    /// Pixels per refresh (paper 001): 1 gathers every pixel's VPL set every frame; 4 gathers
    /// the sets of one pixel per 2×2 cell per frame and reprojects the others' SH from the
    /// previous frames (`igi_reproject`, src/passes/amortise.rs). Default 1.
    pub slices: u32,
}

impl Default for IgiSettings {
    /// The defaults of the IGI passes ([`IgiParams::default`]).
    fn default() -> Self {
        let p = IgiParams::default();
        Self {
            n: p.pattern[0],
            m: p.pattern[1],
            vpl_count: p.vpl_count,
            distribution: p.distribution,
            sh_order: p.sh_order,
            filter_radius: p.filter_radius,
            filter: p.mode,
            glossy: p.glossy,
            clamp_distance: p.clamp_distance,
            depth_tolerance: p.depth_tolerance,
            normal_threshold: p.normal_threshold,
            slices: p.slices,
        }
    }
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            width: 1280,
            height: 720,
            frames: 1,
            time: 0.0,
            gi: GiTechniques::default(),
            receiver_scale: 2,
            output: OutputSettings::default(),
            hvl: HvlSettings::default(),
            rsm: RsmSettings::default(),
            shadow: ShadowSettings::default(),
            texture: TextureSettings::default(),
            upsample: UpsampleSettings::default(),
            igi: IgiSettings::default(),
            proxy: ProxySettings::default(),
            aaf: AafSettings::default(),
            history: HistorySettings::default(),
            specular: SpecularSettings::default(),
            sky: SkySettings::default(),
            cavity: CavitySettings::default(),
            cubes: CubeSettings::default(),
        }
    }
}

impl Default for ProxySettings {
    fn default() -> Self {
        Self {
            sh_order: DEFAULT_ORDER,
            expansion: 0.0,
            indirect_expansion: paper_expansion(INDIRECT_BANDS as u32),
            exp: ExpMethod::Hyb,
            indirect: true,
            brute_force: false,
            fit_count: 0,
            slices: 1,
        }
    }
}

impl OutputSettings {
    /// The supersampling factor of a `width` × `height` frame: `ssaa`, or
    /// [`composite::auto_ssaa`] when it is 0.
    pub fn ssaa_for(&self, width: u32, height: u32) -> u32 {
        match self.ssaa {
            0 => composite::auto_ssaa([width, height]),
            n => n,
        }
    }
}

impl Default for OutputSettings {
    /// The composite's defaults ([`CompositeParams::default`]), the full radiance.
    fn default() -> Self {
        let c = CompositeParams::default();
        Self {
            tonemap: c.tonemap,
            exposure: c.exposure,
            component: Component::Full,
            ssaa: c.ssaa,
            taa: false,
            auto_exposure: true,
            adaptation: ExposureParams::default().adaptation,
        }
    }
}

impl Default for HvlSettings {
    /// The defaults of the HVL passes ([`HvlParams::default`]).
    fn default() -> Self {
        let h = HvlParams::default();
        Self {
            count: h.count,
            distribution: h.distribution,
            radius: h.radius,
            radius_scale: h.radius_scale,
            convolution_bands: h.conv_bands,
            emission_bands: h.emission_bands,
            visibility: h.visibility,
            shadow_rays: h.shadows.rays,
            shadow_filter_radius: h.shadows.filter_radius,
            near_range: NearField::default().range_fraction,
            near_rays: NearField::default().rays,
            gather: h.path,
            window: h.window,
            falloff: h.falloff,
            slices: h.slices,
        }
    }
}

impl Default for RsmSettings {
    fn default() -> Self {
        Self {
            size: rsm::DEFAULT_SIZE,
        }
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            size: shadows::DEFAULT_TILE_SIZE,
            filter_radius: shadows::DEFAULT_FILTER_RADIUS,
        }
    }
}

impl Default for UpsampleSettings {
    fn default() -> Self {
        Self {
            depth_epsilon: DEPTH_SIGMA,
            normal_power: NORMAL_POWER_N,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_validate() {
        Settings::default().validate().unwrap();
        assert_eq!(Settings::from_toml_str("").unwrap(), Settings::default());
    }

    /// Each case breaks one field; the error must name it and its value.
    #[test]
    fn every_out_of_range_field_is_named() {
        type Edit = fn(&mut Settings);
        let cases: [(&str, &str, Edit); 29] = [
            ("proxy.sh_order", "7", |s| s.proxy.sh_order = 7),
            ("proxy.expansion", "1.0", |s| s.proxy.expansion = 1.0),
            ("proxy.indirect_expansion", "NaN", |s| {
                s.proxy.indirect_expansion = f32::NAN
            }),
            ("proxy.fit_count", "65", |s| s.proxy.fit_count = 65),
            ("width", "0", |s| s.width = 0),
            ("width", "16385", |s| s.width = 16385),
            ("height", "0", |s| s.height = 0),
            ("height", "20000", |s| s.height = 20000),
            ("frames", "0", |s| s.frames = 0),
            ("time", "-1.0", |s| s.time = -1.0),
            ("time", "NaN", |s| s.time = f32::NAN),
            ("receiver_scale", "3", |s| s.receiver_scale = 3),
            ("output.exposure", "0.0", |s| s.output.exposure = 0.0),
            ("output.exposure", "inf", |s| {
                s.output.exposure = f32::INFINITY
            }),
            ("hvl.count", "0", |s| s.hvl.count = 0),
            ("hvl.count", "10001", |s| s.hvl.count = 10001),
            ("hvl.count", "257", |s| {
                s.rsm.size = 16;
                s.hvl.count = 257;
            }),
            ("hvl.emission_bands", "3", |s| {
                s.hvl.convolution_bands = 2;
                s.hvl.emission_bands = 3;
            }),
            ("hvl.radius_scale", "0.5", |s| s.hvl.radius_scale = 0.5),
            ("hvl.radius_scale", "2.5", |s| s.hvl.radius_scale = 2.5),
            ("hvl.convolution_bands", "100", |s| {
                s.hvl.convolution_bands = 100
            }),
            ("hvl.emission_bands", "0", |s| s.hvl.emission_bands = 0),
            ("hvl.radius", "r1", |s| s.hvl.radius = RadiusHeuristic::R1),
            ("rsm.size", "8", |s| s.rsm.size = 8),
            ("shadow.size", "32", |s| s.shadow.size = 32),
            ("shadow.filter_radius", "-1.0", |s| {
                s.shadow.filter_radius = -1.0
            }),
            ("upsample.depth_epsilon", "0.0", |s| {
                s.upsample.depth_epsilon = 0.0
            }),
            ("upsample.normal_power", "0.5", |s| {
                s.upsample.normal_power = 0.5
            }),
            ("upsample.normal_power", "1000.0", |s| {
                s.upsample.normal_power = 1000.0
            }),
        ];
        for (field, value, edit) in cases {
            let mut settings = Settings::default();
            edit(&mut settings);
            let message = settings.validate().unwrap_err().to_string();
            assert!(
                message.contains(&format!("`{field}` = {value}")),
                "{field}: {message}"
            );
            assert!(message.contains("allowed"), "{field}: {message}");
        }
    }

    #[test]
    fn range_message_states_the_range() {
        let mut settings = Settings::default();
        settings.hvl.count = 10;
        assert_eq!(
            settings.validate().unwrap_err().to_string(),
            "setting `hvl.count` = 10 is out of range: allowed 64..=10000"
        );
    }

    #[test]
    fn toml_round_trip() {
        let settings = Settings {
            width: 320,
            height: 200,
            time: 1.25,
            gi: GiTechniques::none(),
            receiver_scale: 4,
            output: OutputSettings {
                tonemap: Tonemap::Aces,
                exposure: 0.1,
                component: Component::Indirect,
                ssaa: 2,
                taa: true,
                auto_exposure: true,
                adaptation: 0.5,
            },
            hvl: HvlSettings {
                radius: RadiusHeuristic::R1,
                distribution: Distribution::Grid,
                gather: GatherPath::Zonal,
                ..HvlSettings::default()
            },
            upsample: UpsampleSettings {
                depth_epsilon: 0.003,
                ..UpsampleSettings::default()
            },
            ..Settings::default()
        };
        let text = settings.to_toml_string().unwrap();
        assert_eq!(Settings::from_toml_str(&text).unwrap(), settings);
    }

    #[test]
    fn sections_parse() {
        let settings = Settings::from_toml_str(
            "width = 64\ngi = \"none\"\n[output]\ntonemap = \"aces\"\n[hvl]\ncount = 1000\n",
        )
        .unwrap();
        assert_eq!(settings.width, 64);
        assert!(settings.gi.is_none());
        assert_eq!(settings.output.tonemap, Tonemap::Aces);
        assert_eq!(settings.hvl.count, 1000);
        assert_eq!(settings.hvl.convolution_bands, 5);
    }

    #[test]
    fn files_load_and_errors_name_them() {
        let dir = std::env::temp_dir();
        let good = dir.join(format!("shine-settings-{}-good.toml", std::process::id()));
        let bad = dir.join(format!("shine-settings-{}-bad.toml", std::process::id()));
        std::fs::write(&good, "height = 64\n[rsm]\nsize = 256\n").unwrap();
        std::fs::write(&bad, "[shadow]\nsize = \"big\"\n").unwrap();
        let loaded = Settings::load(&good);
        let refused = Settings::load(&bad).unwrap_err().to_string();
        std::fs::remove_file(&good).unwrap();
        std::fs::remove_file(&bad).unwrap();
        let loaded = loaded.unwrap();
        assert_eq!((loaded.height, loaded.rsm.size), (64, 256));
        assert!(refused.contains(&bad.display().to_string()), "{refused}");
        assert!(refused.contains("size"), "{refused}");
        let missing = dir.join("shine-no-such-settings.toml");
        let message = Settings::load(&missing).unwrap_err().to_string();
        assert!(message.contains("shine-no-such-settings.toml"), "{message}");
    }

    #[test]
    fn unknown_fields_are_rejected() {
        let top = Settings::from_toml_str("widht = 64")
            .unwrap_err()
            .to_string();
        assert!(top.contains("widht"), "{top}");
        let nested = Settings::from_toml_str("[hvl]\ncuont = 64")
            .unwrap_err()
            .to_string();
        assert!(nested.contains("cuont"), "{nested}");
        let section = Settings::from_toml_str("[hlv]\ncount = 64")
            .unwrap_err()
            .to_string();
        assert!(section.contains("hlv"), "{section}");
    }

    #[test]
    fn float_ranges_keep_their_decimal_point() {
        let message = Settings::from_toml_str("[hvl]\nradius_scale = 2.5")
            .unwrap_err()
            .to_string();
        assert_eq!(
            message,
            "setting `hvl.radius_scale` = 2.5 is out of range: allowed 1.0..=2.0"
        );
    }

    #[test]
    fn out_of_range_toml_is_rejected() {
        let message = Settings::from_toml_str("[hvl]\nconvolution_bands = 100")
            .unwrap_err()
            .to_string();
        assert!(message.contains("hvl.convolution_bands"), "{message}");
    }

    #[test]
    fn unknown_choice_lists_the_known_names() {
        let message = Settings::from_toml_str("[output]\ntonemap = \"filmic\"")
            .unwrap_err()
            .to_string();
        assert!(message.contains("none, aces, pbr-neutral"), "{message}");
    }

    #[test]
    fn gi_lists_parse() {
        let both: GiTechniques = "hvl,proxy".parse().unwrap();
        assert_eq!(both.techniques(), [GiTechnique::Hvl, GiTechnique::Proxy]);
        assert_eq!(both.to_string(), "hvl,proxy");
        let hvl: GiTechniques = "hvl".parse().unwrap();
        assert_eq!(hvl.techniques(), [GiTechnique::Hvl]);
        assert!(hvl.contains(GiTechnique::Hvl));
        assert!("none".parse::<GiTechniques>().unwrap().is_none());
        assert_eq!(" hvl ".parse::<GiTechniques>().unwrap(), hvl);
        assert_eq!(hvl.to_string(), "hvl");
        assert_eq!(GiTechniques::none().to_string(), "none");
    }

    #[test]
    fn gi_errors_are_clear() {
        let unknown = "hvl,foo".parse::<GiTechniques>().unwrap_err().to_string();
        assert!(unknown.contains("`foo`"), "{unknown}");
        assert!(unknown.contains("hvl, igi, proxy, aaf, none"), "{unknown}");
        for bad in ["", "hvl,", "none,hvl", "hvl,hvl"] {
            let message = bad.parse::<GiTechniques>().unwrap_err().to_string();
            assert!(
                message.contains("invalid GI technique list"),
                "{bad}: {message}"
            );
        }
        let both = Settings::from_toml_str("gi = \"hvl,aaf\"")
            .unwrap_err()
            .to_string();
        assert!(both.contains("choose one"), "{both}");
    }

    #[test]
    fn aaf_settings_are_checked() {
        let aaf = Settings::from_toml_str("gi = \"aaf,proxy\"\n[aaf]\nmu = 2.0").unwrap();
        assert!(aaf.gi.contains(GiTechnique::Aaf));
        assert_eq!(aaf.aaf.mu, 2.0);
        type Edit = fn(&mut Settings);
        let cases: [(&str, &str, Edit); 6] = [
            ("aaf.mu", "0.0", |s| s.aaf.mu = 0.0),
            ("aaf.mu", "-1.0", |s| s.aaf.mu = -1.0),
            ("aaf.spp_min", "8", |s| s.aaf.spp_min = 8),
            ("aaf.omega_h", "0.0", |s| s.aaf.omega_h = 0.0),
            ("aaf.filter_degree", "3", |s| s.aaf.filter_degree = 3),
            ("aaf.spp_max", "8", |s| {
                s.aaf.spp_max = 8;
            }),
        ];
        for (field, value, edit) in cases {
            let mut settings = Settings::default();
            edit(&mut settings);
            let message = settings.validate().unwrap_err().to_string();
            assert!(
                message.contains(&format!("`{field}` = {value}")),
                "{field}: {message}"
            );
        }
    }

    #[test]
    fn igi_settings_are_checked() {
        let igi =
            Settings::from_toml_str("gi = \"igi\"\n[igi]\nn = 2\nfilter = \"irradiance\"").unwrap();
        assert!(igi.gi.contains(GiTechnique::Igi));
        assert_eq!((igi.igi.n, igi.igi.filter), (2, FilterMode::Irradiance));
        type Edit = fn(&mut Settings);
        let cases: [(&str, &str, Edit); 8] = [
            ("igi.n", "0", |s| s.igi.n = 0),
            ("igi.m", "9", |s| s.igi.m = 9),
            ("igi.sh_order", "5", |s| s.igi.sh_order = 5),
            ("igi.sh_order", "1", |s| s.igi.sh_order = 1),
            ("igi.vpl_count", "10", |s| s.igi.vpl_count = 10),
            ("igi.filter_radius", "5", |s| s.igi.filter_radius = 5),
            ("igi.clamp_distance", "NaN", |s| {
                s.igi.clamp_distance = f32::NAN
            }),
            ("igi.vpl_count", "300", |s| {
                s.rsm.size = 16;
                s.hvl.count = 64;
                s.igi.vpl_count = 300;
            }),
        ];
        for (field, value, edit) in cases {
            let mut settings = Settings::default();
            edit(&mut settings);
            let message = settings.validate().unwrap_err().to_string();
            assert!(
                message.contains(&format!("`{field}` = {value}")),
                "{field}: {message}"
            );
        }
        let both = Settings::from_toml_str("gi = \"hvl,igi\"")
            .unwrap_err()
            .to_string();
        assert!(both.contains("choose one"), "{both}");
    }

    #[test]
    fn overrides_apply_by_dotted_key() {
        let mut settings = Settings::default();
        settings.set("width", "640").unwrap();
        settings.set("hvl.count", "2000").unwrap();
        settings.set("hvl.radius_scale", "1.25").unwrap();
        settings.set("hvl.radius_scale", "2").unwrap();
        settings.set("output.tonemap", "aces").unwrap();
        settings.set("gi", "none").unwrap();
        assert_eq!(settings.width, 640);
        assert_eq!(settings.hvl.count, 2000);
        assert_eq!(settings.hvl.radius_scale, 2.0);
        assert_eq!(settings.output.tonemap, Tonemap::Aces);
        assert!(settings.gi.is_none());
        settings.validate().unwrap();
    }

    #[test]
    fn bad_overrides_are_refused() {
        let mut settings = Settings::default();
        for (key, value) in [
            ("hvl.cuont", "5"),
            ("hvl", "5"),
            ("width.x", "5"),
            ("width", "wide"),
            ("width", "-3"),
            ("output.tonemap", "filmic"),
        ] {
            let message = settings.set(key, value).unwrap_err().to_string();
            assert!(message.contains(key), "{key}: {message}");
        }
        assert_eq!(settings, Settings::default());
        let message = settings.set("hvl.cuont", "5").unwrap_err().to_string();
        assert!(
            message.contains("no setting `cuont` in [hvl] (known: convolution_bands, count,"),
            "{message}"
        );
    }
}
