//! Every user-facing knob of a frame, as one serde struct (issue 6).
//!
//! Settings come from a TOML file ([`Settings::load`], [`Settings::from_toml_str`]) and from
//! command-line flags ([`Settings::set`] with a dotted key such as `hvl.count`), over the
//! defaults of [`Settings::default`]. Every field declares its range, default and effect
//! (`#[setting]`, src/declare.rs; the table: docs/settings.md);
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

mod error;
mod gi;
mod io;
mod validate;

pub use error::SettingsError;
pub use gi::{GiTechnique, GiTechniques};
pub use validate::{EXTENT, FRAMES, TIME};

use serde::{Deserialize, Serialize};

use crate::capture::tonemap::{self, Tonemap};
use crate::declare::Settings as DeclareSettings;
use crate::passes::aaf::AafParams;
use crate::passes::accumulate::AccumulateParams;
use crate::passes::composite::{self, Component};
use crate::passes::cubes::CubeParams;
use crate::passes::denoise::DenoiseParams;
use crate::passes::hvl::HvlParams;
use crate::passes::igi::IgiParams;
use crate::passes::proxy::ProxySettings;
use crate::passes::sky::{CavitySettings, SkyParams};
use crate::passes::specular::SpecularParams;
use crate::passes::upsample::UpsampleParams;
use crate::passes::{exposure, receivers, rsm, shadows};

/// Everything that decides what a frame computes and how it is written. Each section is
/// declared once, by the pass or technique that uses it (`#[derive(Settings)]`,
/// src/declare.rs; the table of every setting: docs/settings.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, DeclareSettings)]
#[serde(default, deny_unknown_fields)]
pub struct Settings {
    /// Output width in pixels.
    #[setting(default = 1280, range = EXTENT, affects = both)]
    pub width: u32,
    /// Output height in pixels.
    #[setting(default = 720, range = EXTENT, affects = both)]
    pub height: u32,
    /// Number of frames rendered (accumulated GI caches and animation advance per frame).
    #[setting(default = 1, range = FRAMES, affects = output)]
    pub frames: u32,
    /// Scene animation time of the first frame, in seconds.
    #[setting(default = 0.0, range = TIME, affects = output)]
    pub time: f32,
    /// GI techniques combined in the frame: `hvl`, `igi`, `aaf`, `proxy`, a list such as
    /// `hvl,proxy`, or `none` (direct light only).
    #[setting(default = GiTechniques::default(), affects = both)]
    pub gi: GiTechniques,
    /// Receiver-buffer downscale s: expensive GI runs at W/s × H/s (paper 002 §4.2).
    #[setting(default = 2, one_of = receivers::SCALES, affects = both)]
    pub receiver_scale: u32,
    /// Tonemapping and exposure.
    #[setting(section)]
    pub output: OutputSettings,
    /// Harmonics Virtual Lights (paper 003).
    #[setting(section)]
    pub hvl: HvlParams,
    /// Reflective shadow map of each primary light.
    #[setting(section)]
    pub rsm: RsmSettings,
    /// Shadow maps of the direct light.
    #[setting(section)]
    pub shadow: ShadowSettings,
    /// Texture filtering of the raster passes.
    #[setting(section)]
    pub texture: TextureSettings,
    /// Joint bilateral upsampling of the receiver-resolution GI (paper 002 eq. 11).
    #[setting(section)]
    pub upsample: UpsampleParams,
    /// Instant GI with SH-filtered incoming radiance (paper 000).
    #[setting(section)]
    pub igi: IgiParams,
    /// Sphere-proxy soft shadows and indirect light under the environment (paper 002).
    #[setting(section)]
    pub proxy: ProxySettings,
    /// Axis-aligned filtering of path-traced indirect light (paper 004).
    #[setting(section)]
    pub aaf: AafParams,
    /// The indirect light accumulated over the frames of a sequence (issue 23).
    #[setting(section)]
    pub history: AccumulateParams,
    /// Traced specular reflections (issue 21).
    #[setting(section)]
    pub specular: SpecularParams,
    /// The filter of the traced specular at one sample per pixel (issue 47).
    #[setting(section)]
    pub denoise: DenoiseParams,
    /// The sky light of frames without proxies (issue 16).
    #[setting(section)]
    pub sky: SkyParams,
    /// Cavity shading of HVL's indirect light (issue 18).
    #[setting(section)]
    pub cavity: CavitySettings,
    /// Tiny environment cubes for the dynamic objects (issue 18).
    #[setting(section)]
    pub cubes: CubeParams,
}

/// `[output]`: how the HDR frame becomes the written image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, DeclareSettings)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSettings {
    /// Tonemap operator of the LDR (PNG) output. EXR output stays linear HDR.
    #[setting(default = tonemap::DEFAULT_TONEMAP, affects = output)]
    pub tonemap: Tonemap,
    /// Linear factor applied to radiance before tonemapping (and in the EXR); with
    /// `auto_exposure` a compensation on top of the automatic exposure.
    #[setting(default = 1.0, range = tonemap::EXPOSURE, affects = output)]
    pub exposure: f32,
    /// Automatic exposure of the tonemapped (PNG) frame: each frame's log-average luminance
    /// is mapped to middle grey (Reinhard et al. 2002, key 0.18; `src/passes/exposure.rs`).
    /// The EXR frame stays scene-referred (`exposure` only).
    #[setting(default = true, affects = output)]
    pub auto_exposure: bool,
    /// Fraction of the way (in log exposure) each frame of a sequence moves towards its
    /// automatic exposure (1: at once).
    #[setting(default = exposure::ADAPTATION, range = exposure::ADAPTATION_RANGE, affects = output)]
    pub adaptation: f32,
    /// Radiance shown: `full`, `direct` or `indirect` (GI only), or `normal`.
    #[setting(default = Component::Full, affects = output)]
    pub component: Component,
    /// Supersampling N: the frame is rendered at N × width by N × height and each output pixel
    /// is the box average of N×N of them, before tonemapping (antialiasing for captures; GI
    /// contexts render at the host's G-buffer size and ignore it). 0: automatic, the largest N
    /// ≤ 2 whose rendered frame has at most 1024² pixels (`shine render`'s default without a
    /// settings file). N × width and N × height at most 16384.
    #[setting(default = 1, zero_or = composite::SSAA, affects = both)]
    pub ssaa: u32,
    /// Temporal antialiasing for sequences and real time: the camera jitters through 8 Halton
    /// points and the direct light is accumulated over up to 16 frames, reprojected with the
    /// motion vectors and clipped to the current neighbourhood (the indirect light has its
    /// own history, `[history]`). A single frame is unchanged.
    #[setting(default = false, affects = both)]
    pub taa: bool,
}

/// `[rsm]`: reflective shadow map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, DeclareSettings)]
#[serde(default, deny_unknown_fields)]
pub struct RsmSettings {
    /// RSM side S in texels (S×S per primary light).
    #[setting(default = rsm::DEFAULT_SIZE, range = rsm::SIZE, affects = both)]
    pub size: u32,
}

/// `[texture]`: how the raster passes filter the scene's textures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, DeclareSettings)]
#[serde(default, deny_unknown_fields)]
pub struct TextureSettings {
    /// Trilinear filtering over the mip chains built at upload (false: the full-resolution
    /// level only, point-exact against the path tracer, which reads level 0 at each hit).
    #[setting(default = true, affects = quality)]
    pub mipmaps: bool,
}

/// `[shadow]`: shadow maps of the direct light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, DeclareSettings)]
#[serde(default, deny_unknown_fields)]
pub struct ShadowSettings {
    /// Shadow-map side in texels.
    #[setting(default = shadows::DEFAULT_TILE_SIZE, range = shadows::TILE_SIZE, affects = both)]
    pub size: u32,
    /// Percentage-closer filter radius in shadow-map texels (0: a single hard tap).
    #[setting(default = shadows::DEFAULT_FILTER_RADIUS, range = shadows::FILTER_RADIUS, affects = both)]
    pub filter_radius: f32,
}

/// `docs/settings.md`: every setting as declared, the page `shine settings` prints (a test
/// keeps the file equal to it).
pub fn settings_page() -> String {
    format!(
        "# Settings\n\n\
         Every setting of shine, generated from the declarations (`#[derive(Settings)]`, \
         src/declare.rs) by `shine settings > docs/settings.md`; a test fails when this page \
         is stale. Keys are those of a settings file (`--settings FILE`, TOML) and of \
         `--set KEY=VALUE`. \"changes\" says what a setting moves: the frame's cost, its \
         quality, both, or only how it is written (output).\n\n{}",
        crate::declare::markdown_table(&<Settings as crate::declare::Section>::specs())
    )
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

#[cfg(test)]
mod tests;
