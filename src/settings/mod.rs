//! Every user-facing knob of a frame, as one serde struct (issue 6).
//!
//! Settings come from a TOML file ([`Settings::load`], [`Settings::from_toml_str`]) and from
//! command-line flags ([`Settings::set`] with a dotted key such as `hvl.count`), over the
//! defaults of [`Settings::default`]. Every field documents its range and default;
//! [`Settings::validate`] rejects a value outside its range with an error naming the field, the
//! value and what is allowed, so an absurd setting never reaches the GPU (DESIGN §7).
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

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Why settings were rejected: each variant names the setting and what to do.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// A numeric setting lies outside its documented range (or is not a finite number).
    #[error("setting `{field}` = {value} is out of range: allowed {allowed}")]
    OutOfRange {
        /// Dotted name of the setting, as written in the TOML file (`hvl.count`).
        field: &'static str,
        /// The rejected value, as given.
        value: String,
        /// The allowed values (`64..=10000`, `1, 2 or 4`).
        allowed: String,
    },
    /// A named choice (tonemap operator, GI technique, …) that shine does not know.
    #[error("unknown {what} `{name}`: expected one of {known}")]
    UnknownName {
        /// What was being named (`tonemap operator`).
        what: &'static str,
        /// The name given.
        name: String,
        /// The known names, comma-separated.
        known: String,
    },
    /// A GI technique that a later issue adds, not usable yet.
    #[error(
        "GI technique `{name}` is not implemented yet: available now are {available} \
         (combine them with commas, e.g. `--gi hvl`)"
    )]
    GiNotImplemented {
        /// The planned technique that was asked for.
        name: String,
        /// The techniques that work today.
        available: String,
    },
    /// A GI list that is malformed: empty entry, duplicate, or `none` combined with others.
    #[error("invalid GI technique list `{list}`: {reason}")]
    GiList {
        /// The list as given.
        list: String,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The settings file could not be read.
    #[error("cannot read settings file {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The TOML text is malformed, names an unknown setting, or has a value of the wrong type.
    #[error("invalid settings{}: {message}", origin(path))]
    Parse {
        /// The file the text came from, when it came from one.
        path: Option<PathBuf>,
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A `key=value` override names no setting or has a value the setting cannot take.
    #[error("cannot set `{key}` to `{value}`: {reason}")]
    Override {
        /// The dotted key (`hvl.count`).
        key: String,
        /// The value given.
        value: String,
        /// Why it was refused.
        reason: String,
    },
}

/// ` in FILE` for a parse error from a file, nothing for a string.
fn origin(path: &Option<PathBuf>) -> String {
    path.as_ref()
        .map(|p| format!(" in {}", p.display()))
        .unwrap_or_default()
}

/// Defines an enum of named choices whose names are the single source for TOML, the CLI
/// ([`FromStr`], [`fmt::Display`]) and the error listing the known names.
macro_rules! named_choice {
    (
        $(#[$meta:meta])*
        $vis:vis enum $name:ident ($what:literal) {
            $( $(#[$vmeta:meta])* $variant:ident = $text:literal, )+
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        $vis enum $name {
            $( $(#[$vmeta])* $variant, )+
        }

        impl $name {
            /// Every choice, in documentation order.
            pub const ALL: &'static [$name] = &[$($name::$variant),+];

            /// The name used in settings files and on the command line.
            pub fn name(self) -> &'static str {
                match self {
                    $( $name::$variant => $text, )+
                }
            }
        }

        impl FromStr for $name {
            type Err = SettingsError;

            fn from_str(s: &str) -> Result<Self, SettingsError> {
                Self::ALL
                    .iter()
                    .copied()
                    .find(|c| c.name() == s)
                    .ok_or_else(|| SettingsError::UnknownName {
                        what: $what,
                        name: s.to_owned(),
                        known: Self::ALL.iter().map(|c| c.name()).collect::<Vec<_>>().join(", "),
                    })
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.name())
            }
        }

        impl Serialize for $name {
            fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.name())
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let text = String::deserialize(d)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}

named_choice! {
    /// The tonemapping operator that turns the HDR frame into the LDR one (see [`crate::tonemap`]).
    /// EXR output is never tonemapped.
    pub enum Tonemap ("tonemap operator") {
        /// No curve: exposed radiance clamped to [0, 1].
        None = "none",
        /// ACES filmic (Narkowicz 2015 fit of the RRT+ODT).
        Aces = "aces",
        /// Khronos PBR Neutral: colour-preserving, identity below its knee.
        PbrNeutral = "pbr-neutral",
    }
}

named_choice! {
    /// Which part of the radiance the frame shows (image tests compare each against the
    /// path-traced reference, src/reference.rs).
    pub enum Component ("output component") {
        /// Direct + indirect light.
        Full = "full",
        /// The direct pass only (emission and punctual lights).
        Direct = "direct",
        /// The GI technique's indirect light only (needs a GI technique).
        Indirect = "indirect",
    }
}

named_choice! {
    /// How an HVL's radius is estimated from the HVL cache (paper 003 §5.3).
    pub enum RadiusHeuristic ("HVL radius heuristic") {
        /// Eq. 23: weighted mean distance to the 8-connected neighbours in the HVL cache.
        R1 = "r1",
        /// Eq. 24–26: from the light's field of view, the HVL count and the distance to the light.
        R2 = "r2",
    }
}

named_choice! {
    /// Which SH convolution the HVL gather uses (paper 003 §4.3 and §6).
    pub enum GatherPath ("HVL gather path") {
        /// Full SH convolution, O(n²) in the band count n: any BRDF.
        Full = "full",
        /// Zonal-harmonics convolution, O(n): circularly symmetric lobes only.
        Zonal = "zonal",
    }
}

named_choice! {
    /// What the IGI discontinuity filter averages (paper 000 §2.3 against §3).
    pub enum IgiFilter ("IGI filter mode") {
        /// The per-pixel incident radiance as SH (paper 000): the BRDF is applied after filtering.
        Sh = "sh",
        /// Classic IGI: the per-pixel irradiance (and glossy radiance) about the shading normal.
        Irradiance = "irradiance",
    }
}

named_choice! {
    /// The glossy lobe of IGI's SH resolve (`src/passes/igi.rs`).
    pub enum IgiGlossy ("IGI glossy lobe") {
        /// GGX through the BRDF SH tables of the HVL gather, radiance rotated per pixel.
        Ggx = "ggx",
        /// Paper 000 §3.3: Lambert and Phong r_l, the Phong lobe standing for the GGX.
        Phong = "phong",
    }
}

named_choice! {
    /// One indirect-light technique of DESIGN §4 that shine implements today.
    pub enum GiTechnique ("GI technique") {
        /// Harmonics Virtual Lights (paper 003).
        Hvl = "hvl",
        /// Instant GI with interleaved sampling and SH-filtered incoming radiance (paper 000).
        Igi = "igi",
        /// Sphere proxies under the environment light (paper 002): proxy-shadowed environment
        /// plus proxy indirect light.
        Proxy = "proxy",
    }
}

named_choice! {
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

/// Techniques that later issues add: named so that asking for one says "not implemented yet"
/// rather than "unknown".
const PLANNED_GI: [&str; 1] = ["aaf"];

/// The name of the empty technique list: direct light only.
const NO_GI: &str = "none";

/// The set of GI techniques a frame combines, written `hvl`, `none`, `proxy` or `hvl,proxy`.
///
/// `hvl,proxy` adds both indirect terms at receiver resolution before one upsample: the HVL
/// indirect light of the primary light and the proxy-shadowed environment plus proxy indirect
/// light (paper 002 pairs them the same way). Without `proxy` the environment lights nothing
/// (direct light and HVL only).
///
/// `none` (the empty list) renders direct light only. Order is kept as given; each technique
/// appears at most once.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct GiTechniques(Vec<GiTechnique>);

impl GiTechniques {
    /// Direct light only.
    pub fn none() -> Self {
        Self(Vec::new())
    }

    /// The techniques, in the order given.
    pub fn techniques(&self) -> &[GiTechnique] {
        &self.0
    }

    /// Whether `technique` is part of the frame.
    pub fn contains(&self, technique: GiTechnique) -> bool {
        self.0.contains(&technique)
    }

    /// Whether the frame has no indirect light at all.
    pub fn is_none(&self) -> bool {
        self.0.is_empty()
    }
}

impl Default for GiTechniques {
    /// `hvl`, the technique of issue 6.
    fn default() -> Self {
        Self(vec![GiTechnique::Hvl])
    }
}

impl FromStr for GiTechniques {
    type Err = SettingsError;

    fn from_str(list: &str) -> Result<Self, SettingsError> {
        let invalid = |reason| SettingsError::GiList {
            list: list.to_owned(),
            reason,
        };
        let names: Vec<&str> = list.split(',').map(str::trim).collect();
        if names == [NO_GI] {
            return Ok(Self::none());
        }
        let mut techniques = Vec::with_capacity(names.len());
        for name in names {
            if name.is_empty() {
                return Err(invalid("empty technique name (write e.g. `hvl` or `none`)"));
            }
            if name == NO_GI {
                return Err(invalid("`none` cannot be combined with other techniques"));
            }
            if PLANNED_GI.contains(&name) {
                return Err(SettingsError::GiNotImplemented {
                    name: name.to_owned(),
                    available: available_gi(),
                });
            }
            let technique =
                name.parse::<GiTechnique>()
                    .map_err(|_| SettingsError::UnknownName {
                        what: "GI technique",
                        name: name.to_owned(),
                        known: known_gi(),
                    })?;
            if techniques.contains(&technique) {
                return Err(invalid("a technique is listed twice"));
            }
            techniques.push(technique);
        }
        Ok(Self(techniques))
    }
}

/// The technique names usable today, `none` included.
fn available_gi() -> String {
    let mut names: Vec<&str> = GiTechnique::ALL.iter().map(|t| t.name()).collect();
    names.push(NO_GI);
    names.join(", ")
}

/// Every technique name shine knows, planned ones included.
fn known_gi() -> String {
    let mut names: Vec<&str> = GiTechnique::ALL.iter().map(|t| t.name()).collect();
    names.push(NO_GI);
    names.extend(PLANNED_GI);
    names.join(", ")
}

impl fmt::Display for GiTechniques {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str(NO_GI);
        }
        let names: Vec<&str> = self.0.iter().map(|t| t.name()).collect();
        f.write_str(&names.join(","))
    }
}

impl Serialize for GiTechniques {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for GiTechniques {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

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
    /// Joint bilateral upsampling of the receiver-resolution GI (paper 002 eq. 11).
    pub upsample: UpsampleSettings,
    /// Instant GI with SH-filtered incoming radiance (paper 000).
    pub igi: IgiSettings,
    /// Sphere-proxy soft shadows and indirect light under the environment (paper 002).
    pub proxy: ProxySettings,
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
}

/// `[output]`: how the HDR frame becomes the written image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSettings {
    /// Tonemap operator of the LDR (PNG) output: `none`, `aces`, `pbr-neutral`.
    /// Default `pbr-neutral`. EXR output stays linear HDR.
    pub tonemap: Tonemap,
    /// Linear factor applied to radiance before tonemapping (and in the EXR).
    /// Range 1e-6..=1e6, default 1.0.
    pub exposure: f32,
    /// Radiance shown: `full`, `direct` or `indirect` (GI only). Default `full`.
    pub component: Component,
}

/// `[hvl]`: Harmonics Virtual Lights (paper 003).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HvlSettings {
    /// Number M of HVLs distributed from the RSM (any count: the RSM is cut into M cells).
    /// Range 64..=10000 and at most `rsm.size²`, default 400 (paper 003 fig. 10).
    pub count: u32,
    /// Radius heuristic: `r1` (eq. 23) or `r2` (eq. 24–26). Default `r2`.
    pub radius: RadiusHeuristic,
    /// User factor k scaling every radius (paper 003 §5.3: good between 1 and 2).
    /// Range 1.0..=2.0, default 1.5.
    pub radius_scale: f32,
    /// SH bands n of the convolution at shaded points (n² coefficients). Range 1..=10,
    /// default 5.
    pub convolution_bands: u32,
    /// SH bands of each HVL's emission function. Range 1..=5 and at most
    /// `convolution_bands`, default 3.
    pub emission_bands: u32,
    /// Shadow rays through the scene's BVH from every receiver to every HVL (shine's
    /// extension: paper 003's HVLs are unshadowed). Default false.
    pub visibility: bool,
    /// Gather path: `full` (any BRDF, O(n²)) or `zonal` (symmetric lobes, O(n)).
    /// Default `full`.
    pub gather: GatherPath,
}

/// `[rsm]`: reflective shadow map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RsmSettings {
    /// RSM side S in texels (S×S per primary light). Range 16..=4096, default 512.
    pub size: u32,
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
    /// SH order (bands) of the per-pixel incident radiance: 2, 3 or 4 (4, 9 or 16
    /// coefficients). Default 3 (paper 000 §3.1).
    pub sh_order: u32,
    /// Size k of the discontinuity filter's window in interleaving tiles: k·n × k·m pixels
    /// around the pixel, every set counted k² times (0: no filter; 1: exactly one tile, as
    /// paper 000 §2.3). Range 0..=4, default 1.
    pub filter_radius: u32,
    /// What is filtered: `sh` (paper 000) or `irradiance` (classic IGI). Default `sh`.
    pub filter: IgiFilter,
    /// Glossy lobe of the SH mode: `ggx` (BRDF SH tables) or `phong` (paper 000 §3.3.2).
    /// Default `ggx`.
    pub glossy: IgiGlossy,
    /// Minimum VPL distance d_min in metres: 1/d² is evaluated as 1/max(d², d_min²) (the VPL
    /// singularity clamp). Range 0.0..=10.0, default 0.1.
    pub clamp_distance: f32,
    /// Relative depth tolerance of the filter: a neighbour q is used when
    /// |z_q − z_p| ≤ depth_tolerance · z_p. Range 1e-4..=1.0, default 0.05.
    pub depth_tolerance: f32,
    /// Cosine threshold of the filter's geometric-normal test (n_p · n_q ≥ this).
    /// Range -1.0..=1.0, default 0.9.
    pub normal_threshold: f32,
}

impl Default for IgiSettings {
    fn default() -> Self {
        Self {
            n: 4,
            m: 4,
            vpl_count: 256,
            sh_order: 3,
            filter_radius: 1,
            filter: IgiFilter::Sh,
            glossy: IgiGlossy::Ggx,
            clamp_distance: 0.1,
            depth_tolerance: 0.05,
            normal_threshold: 0.9,
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
            upsample: UpsampleSettings::default(),
            igi: IgiSettings::default(),
            proxy: ProxySettings::default(),
        }
    }
}

impl Default for ProxySettings {
    fn default() -> Self {
        Self {
            sh_order: 4,
            expansion: 0.0,
            indirect_expansion: 10.0,
            exp: ExpMethod::Hyb,
            indirect: true,
            brute_force: false,
            fit_count: 0,
        }
    }
}

impl ProxySettings {
    /// The shadow expansion factor η in use: the setting, or the paper's value for the order
    /// (§4.1: 15 for order 4, 10 for order 3) when it is 0.
    pub fn shadow_expansion(&self) -> f32 {
        if self.expansion > 0.0 {
            self.expansion
        } else if self.sh_order <= 3 {
            10.0 // §4.1, paper 002: order 3
        } else {
            15.0 // §4.1, paper 002: order 4
        }
    }
}

impl Default for OutputSettings {
    fn default() -> Self {
        Self {
            tonemap: Tonemap::PbrNeutral,
            exposure: 1.0,
            component: Component::Full,
        }
    }
}

impl Default for HvlSettings {
    fn default() -> Self {
        Self {
            count: 400,
            radius: RadiusHeuristic::R2,
            radius_scale: 1.5,
            convolution_bands: 5,
            emission_bands: 3,
            visibility: false,
            gather: GatherPath::Full,
        }
    }
}

impl Default for RsmSettings {
    fn default() -> Self {
        Self { size: 512 }
    }
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            size: 2048,
            filter_radius: 1.5,
        }
    }
}

impl Default for UpsampleSettings {
    fn default() -> Self {
        Self {
            depth_epsilon: 0.01,
            normal_power: 32.0,
        }
    }
}

/// The receiver-buffer scales allowed (DESIGN §4).
pub const RECEIVER_SCALES: [u32; 3] = [1, 2, 4];

/// Rejects `value` outside `range` (NaN included) with the field's name. Values print with
/// `Debug` so that floats keep their decimal point (`1.0..=2.0`).
fn check<T: PartialOrd + fmt::Debug>(
    field: &'static str,
    value: T,
    range: RangeInclusive<T>,
) -> Result<(), SettingsError> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(SettingsError::OutOfRange {
            field,
            value: format!("{value:?}"),
            allowed: format!("{:?}..={:?}", range.start(), range.end()),
        })
    }
}

impl Settings {
    /// Parses settings from TOML text over the defaults, then validates them.
    ///
    /// Unknown settings and wrongly typed values are errors (with line and column).
    pub fn from_toml_str(text: &str) -> Result<Self, SettingsError> {
        Self::parse(text, None)
    }

    /// Reads a TOML settings file over the defaults, then validates it.
    pub fn load(path: &Path) -> Result<Self, SettingsError> {
        let text = std::fs::read_to_string(path).map_err(|source| SettingsError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, Some(path))
    }

    /// Parses and validates `text`, naming `path` in errors.
    fn parse(text: &str, path: Option<&Path>) -> Result<Self, SettingsError> {
        let settings: Self = toml::from_str(text).map_err(|e| SettingsError::Parse {
            path: path.map(Path::to_owned),
            message: e.to_string(),
        })?;
        settings.validate()?;
        Ok(settings)
    }

    /// The settings as a TOML document that [`Settings::from_toml_str`] reads back unchanged.
    pub fn to_toml_string(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(self)
    }

    /// Overrides one setting by its dotted TOML key (`width`, `hvl.count`, `output.tonemap`)
    /// with a value written as in TOML (`2000`, `1.5`) or as a bare word (`aces`, `hvl,proxy`).
    ///
    /// This is how command-line flags apply over a settings file. The result is not validated:
    /// call [`Settings::validate`] once every override is applied.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), SettingsError> {
        let refuse = |reason: String| SettingsError::Override {
            key: key.to_owned(),
            value: value.to_owned(),
            reason,
        };
        let mut table = toml::Table::try_from(&*self).map_err(|e| refuse(e.to_string()))?;
        let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(value.to_owned()));
        let mut slot = &mut table;
        let mut section = String::from("the top level");
        let mut parts = key.split('.').peekable();
        while let Some(part) = parts.next() {
            let known = slot.keys().cloned().collect::<Vec<_>>().join(", ");
            let entry = slot.get_mut(part).ok_or_else(|| {
                refuse(format!("no setting `{part}` in {section} (known: {known})"))
            })?;
            if parts.peek().is_none() {
                if entry.is_table() {
                    return Err(refuse(format!("`{key}` is a section, not a setting")));
                }
                *entry = parsed;
                break;
            }
            slot = entry
                .as_table_mut()
                .ok_or_else(|| refuse(format!("`{part}` is a setting, not a section")))?;
            section = format!("[{part}]");
        }
        *self = table
            .try_into()
            .map_err(|e: toml::de::Error| refuse(e.message().trim().to_owned()))?;
        Ok(())
    }

    /// Checks every setting against its documented range.
    ///
    /// The error names the first offending field (dotted, as in the TOML file), its value and
    /// the allowed range.
    pub fn validate(&self) -> Result<(), SettingsError> {
        check("width", self.width, 1..=16384)?;
        check("height", self.height, 1..=16384)?;
        check("frames", self.frames, 1..=100_000)?;
        check("time", self.time, 0.0..=100_000.0)?;
        if !RECEIVER_SCALES.contains(&self.receiver_scale) {
            return Err(SettingsError::OutOfRange {
                field: "receiver_scale",
                value: self.receiver_scale.to_string(),
                allowed: "1, 2 or 4".to_owned(),
            });
        }
        check("output.exposure", self.output.exposure, 1e-6..=1e6)?;
        check("hvl.count", self.hvl.count, 64..=10_000)?;
        check("hvl.radius_scale", self.hvl.radius_scale, 1.0..=2.0)?;
        check("hvl.convolution_bands", self.hvl.convolution_bands, 1..=10)?;
        check("hvl.emission_bands", self.hvl.emission_bands, 1..=5)?;
        check("rsm.size", self.rsm.size, 16..=4096)?;
        let rsm_texels = u64::from(self.rsm.size).pow(2);
        if u64::from(self.hvl.count) > rsm_texels {
            return Err(SettingsError::OutOfRange {
                field: "hvl.count",
                value: self.hvl.count.to_string(),
                allowed: format!(
                    "at most rsm.size² = {rsm_texels} (one RSM texel per HVL at least): raise rsm.size"
                ),
            });
        }
        if self.hvl.emission_bands > self.hvl.convolution_bands {
            return Err(SettingsError::OutOfRange {
                field: "hvl.emission_bands",
                value: self.hvl.emission_bands.to_string(),
                allowed: format!(
                    "1..={} (at most hvl.convolution_bands)",
                    self.hvl.convolution_bands.min(5)
                ),
            });
        }
        check("shadow.size", self.shadow.size, 64..=16384)?;
        check(
            "shadow.filter_radius",
            self.shadow.filter_radius,
            0.0..=16.0,
        )?;
        check(
            "upsample.depth_epsilon",
            self.upsample.depth_epsilon,
            1e-6..=10.0,
        )?;
        check(
            "upsample.normal_power",
            self.upsample.normal_power,
            1.0..=256.0,
        )?;
        check("proxy.sh_order", self.proxy.sh_order, 3..=6)?;
        if self.proxy.expansion != 0.0 {
            check("proxy.expansion", self.proxy.expansion, 2.0..=100.0)?;
        }
        check(
            "proxy.indirect_expansion",
            self.proxy.indirect_expansion,
            2.0..=100.0,
        )?;
        check("proxy.fit_count", self.proxy.fit_count, 0..=64)?;
        self.validate_igi()?;
        Ok(())
    }

    /// The `[igi]` checks of [`Settings::validate`], and the combination rule: `igi` and `hvl`
    /// both compute the one-bounce indirect light of the primary light, so a frame takes one.
    fn validate_igi(&self) -> Result<(), SettingsError> {
        let i = &self.igi;
        check("igi.n", i.n, 1..=8)?;
        check("igi.m", i.m, 1..=8)?;
        check("igi.vpl_count", i.vpl_count, 64..=10_000)?;
        check("igi.sh_order", i.sh_order, 2..=4)?;
        check("igi.filter_radius", i.filter_radius, 0..=4)?;
        check("igi.clamp_distance", i.clamp_distance, 0.0..=10.0)?;
        check("igi.depth_tolerance", i.depth_tolerance, 1e-4..=1.0)?;
        check("igi.normal_threshold", i.normal_threshold, -1.0..=1.0)?;
        let rsm_texels = u64::from(self.rsm.size).pow(2);
        if u64::from(i.vpl_count) > rsm_texels {
            return Err(SettingsError::OutOfRange {
                field: "igi.vpl_count",
                value: i.vpl_count.to_string(),
                allowed: format!(
                    "at most rsm.size² = {rsm_texels} (one RSM texel per VPL at least): raise rsm.size"
                ),
            });
        }
        if self.gi.contains(GiTechnique::Igi) && self.gi.contains(GiTechnique::Hvl) {
            return Err(SettingsError::GiList {
                list: self.gi.to_string(),
                reason: "`igi` and `hvl` both compute the one-bounce indirect light of the \
                         primary light: choose one",
            });
        }
        Ok(())
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
        let cases: [(&str, &str, Edit); 28] = [
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
            },
            hvl: HvlSettings {
                radius: RadiusHeuristic::R1,
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
        assert!(unknown.contains("hvl, igi, proxy, none, aaf"), "{unknown}");
        let planned = "hvl,aaf".parse::<GiTechniques>().unwrap_err().to_string();
        assert!(
            planned.contains("`aaf` is not implemented yet"),
            "{planned}"
        );
        for bad in ["", "hvl,", "none,hvl", "hvl,hvl"] {
            let message = bad.parse::<GiTechniques>().unwrap_err().to_string();
            assert!(
                message.contains("invalid GI technique list"),
                "{bad}: {message}"
            );
        }
        let in_file = Settings::from_toml_str("gi = \"aaf\"")
            .unwrap_err()
            .to_string();
        assert!(
            in_file.contains("`aaf` is not implemented yet"),
            "{in_file}"
        );
    }

    #[test]
    fn igi_settings_are_checked() {
        let igi =
            Settings::from_toml_str("gi = \"igi\"\n[igi]\nn = 2\nfilter = \"irradiance\"").unwrap();
        assert!(igi.gi.contains(GiTechnique::Igi));
        assert_eq!((igi.igi.n, igi.igi.filter), (2, IgiFilter::Irradiance));
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
