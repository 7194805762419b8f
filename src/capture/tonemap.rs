//! Tonemapping and sRGB encoding on the CPU: the reference of `shaders/include/tonemap.glsl`.
//!
//! Each formula lives once per language: here in Rust, in `tonemap.glsl` in GLSL, and the
//! composite GPU test (tests/composite.rs) checks the two agree on the same inputs. The input
//! is linear Rec.709 radiance with the exposure already applied; negative components (SH
//! ringing) are clamped to 0 first, as every operator assumes non-negative input.
//!
//! - [`Tonemap::None`]: clamp to [0, 1].
//! - [`Tonemap::Aces`]: Krzysztof Narkowicz's per-channel rational fit of ACES RRT+ODT
//!   ("ACES Filmic Tone Mapping Curve", January 2016, usually cited as Narkowicz 2015),
//!   `x(2.51x + 0.03) / (x(2.43x + 0.59) + 0.14)`, clamped. It is the curve as published,
//!   which was fitted to data pre-exposed so that 1 maps to about 0.8; the original ACES
//!   curve is the same with the input multiplied by 0.6 (use `exposure` for that). It is
//!   luminance-only and over-saturates brights; Stephen Hill's RRT+ODT fit is the accurate
//!   alternative should that matter.
//! - [`Tonemap::PbrNeutral`]: the Khronos PBR Neutral specification
//!   (KhronosGroup/ToneMapping, `PBR_Neutral/README.md`): F90 = 0.04, compression starts at
//!   K_s = 0.8 − F90, desaturation speed K_d = 0.15. Identity (minus a small black offset)
//!   below the knee, so base colours render true.
//! - [`Tonemap::Agx`]: Troy Sobotka's AgX, in the form real-time engines use (Blender's AgX
//!   base, as Benjamin Wrensch's minimal approximation fits it): linear Rec.709 through the
//!   inset matrix, log2 over [−12.47393, 4.026069] EV normalised to [0, 1], the default contrast
//!   sigmoid as a 6th-order polynomial, the outset matrix, and a 2.2 power back to linear. It
//!   compresses each channel's log exposure, so a dim channel keeps its share where PBR
//!   Neutral's black offset (2·F90) takes all of it, and it desaturates towards white.
//!
//! The tonemapped value is then encoded with the sRGB OETF (IEC 61966-2-1) and quantized to
//! 8 bits by rounding to nearest.

use glam::Vec3;

/// The operator of captures, previews and the composite unless told otherwise: PBR Neutral,
/// which renders base colours true. AgX was tried as the default and not kept: it keeps a dim
/// channel that PBR Neutral's black offset removes (the cornell box's back wall in sRGB:
/// untonemapped (76, 63, 34), PBR Neutral (68, 53, 5), AgX (87, 71, 32)), but it turns the
/// room's red cube pink and its pale blue wall grey ((214, 220, 230) → (187, 189, 193);
/// docs/quality.md). `--tonemap agx` is one flag away.
pub const DEFAULT_TONEMAP: Tonemap = Tonemap::PbrNeutral;

/// Rec. 709 luminance weights of linear RGB (ITU-R BT.709): exposure metering, TAA's blend
/// space, SSIM, the path tracer's emitter weights, the BRDF sampler's lobe choice. GLSL twin:
/// `REC709_LUMA` in shaders/include/color.glsl.
pub const REC709_LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// Rec. 709 luminance of linear RGB ([`REC709_LUMA`]; GLSL `luminance`).
pub fn luminance(rgb: Vec3) -> f32 {
    rgb.dot(Vec3::from(REC709_LUMA))
}

/// Linear exposure factors a frame takes (`output.exposure`).
pub const EXPOSURE: std::ops::RangeInclusive<f32> = 1e-6..=1e6;

crate::choice::named_choice! {
    /// The tonemapping operator that turns the HDR frame into the LDR one (see [`crate::capture::tonemap`]).
    /// EXR output is never tonemapped.
    pub enum Tonemap ("tonemap operator") {
        /// No curve: exposed radiance clamped to [0, 1].
        None = "none",
        /// ACES filmic (Narkowicz 2015 fit of the RRT+ODT).
        Aces = "aces",
        /// Khronos PBR Neutral: colour-preserving, identity below its knee.
        PbrNeutral = "pbr-neutral",
        /// AgX (Sobotka): log-encoded filmic curve, dim channels kept.
        Agx = "agx",
    }
}

impl Tonemap {
    /// The operator's id in the `op` push constant of `composite.comp`; it matches the
    /// `TONEMAP_*` defines of `tonemap.glsl`.
    pub fn shader_id(self) -> u32 {
        match self {
            Tonemap::None => 0,
            Tonemap::Aces => 1,
            Tonemap::PbrNeutral => 2,
            Tonemap::Agx => 3,
        }
    }
}

/// Narkowicz's ACES fit of one channel, clamped to [0, 1].
pub fn aces_narkowicz(x: f32) -> f32 {
    const A: f32 = 2.51;
    const B: f32 = 0.03;
    const C: f32 = 2.43;
    const D: f32 = 0.59;
    const E: f32 = 0.14;
    ((x * (A * x + B)) / (x * (C * x + D) + E)).clamp(0.0, 1.0)
}

/// Fresnel reflectance at normal incidence of IoR 1.5 materials, F90 of the PBR Neutral spec.
const PBR_NEUTRAL_F90: f32 = 0.04;
/// K_s: where highlight compression starts.
const PBR_NEUTRAL_START: f32 = 0.8 - PBR_NEUTRAL_F90;
/// K_d: how fast compressed highlights desaturate.
const PBR_NEUTRAL_DESATURATION: f32 = 0.15;

/// Khronos PBR Neutral of a non-negative linear colour; the result lies in [0, 1].
pub fn pbr_neutral(color: Vec3) -> Vec3 {
    let x = color.min_element();
    let offset = if x <= 2.0 * PBR_NEUTRAL_F90 {
        x - x * x / (4.0 * PBR_NEUTRAL_F90)
    } else {
        PBR_NEUTRAL_F90
    };
    let color = color - Vec3::splat(offset);
    let peak = color.max_element();
    if peak <= PBR_NEUTRAL_START {
        return color;
    }
    let d = 1.0 - PBR_NEUTRAL_START;
    let new_peak = 1.0 - d * d / (peak + d - PBR_NEUTRAL_START);
    let color = color * (new_peak / peak);
    let g = 1.0 - 1.0 / (PBR_NEUTRAL_DESATURATION * (peak - new_peak) + 1.0);
    color.lerp(Vec3::splat(new_peak), g)
}

/// The sRGB OETF (linear [0, 1] → encoded [0, 1]), piecewise as IEC 61966-2-1.
pub fn srgb_oetf(linear: f32) -> f32 {
    if linear <= 0.003_130_8 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    }
}

/// AgX's log2 exposure range, EV: the encoding maps it to [0, 1].
pub const AGX_MIN_EV: f32 = -12.473_93;
/// The top of AgX's log2 exposure range, EV.
pub const AGX_MAX_EV: f32 = 4.026_069;
/// AgX's power from its display encoding back to linear light.
pub const AGX_GAMMA: f32 = 2.2;

/// AgX's inset matrix (rows: output channels), applied to linear Rec.709. Each row sums to 1,
/// so grey stays grey.
const AGX_INSET: [[f32; 3]; 3] = [
    [0.842_479_06, 0.078_433_6, 0.079_223_745],
    [0.042_328_242, 0.878_468_6, 0.079_166_13],
    [0.042_375_655, 0.078_433_6, 0.879_143],
];
/// AgX's outset matrix (rows: output channels), the inverse of the inset.
const AGX_OUTSET: [[f32; 3]; 3] = [
    [1.196_879, -0.098_020_88, -0.099_029_74],
    [-0.052_896_85, 1.151_903_1, -0.098_961_18],
    [-0.052_971_635, -0.098_043_45, 1.151_073_7],
];

/// The polynomial fit of AgX's default contrast sigmoid on normalised log exposure x ∈ [0, 1].
pub fn agx_contrast(x: f32) -> f32 {
    let x2 = x * x;
    let x4 = x2 * x2;
    15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 + 0.1191 * x
        - 0.002_32
}

/// `m` (rows) times `v`.
fn rows_times(m: &[[f32; 3]; 3], v: Vec3) -> Vec3 {
    Vec3::new(
        Vec3::from(m[0]).dot(v),
        Vec3::from(m[1]).dot(v),
        Vec3::from(m[2]).dot(v),
    )
}

/// AgX of a non-negative linear colour; the result lies in [0, 1].
pub fn agx(color: Vec3) -> Vec3 {
    let inset = rows_times(&AGX_INSET, color);
    let encode = |c: f32| {
        let ev = c
            .max(f32::MIN_POSITIVE)
            .log2()
            .clamp(AGX_MIN_EV, AGX_MAX_EV);
        agx_contrast((ev - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV))
    };
    let curved = Vec3::new(encode(inset.x), encode(inset.y), encode(inset.z));
    let display = rows_times(&AGX_OUTSET, curved).max(Vec3::ZERO);
    Vec3::new(
        display.x.powf(AGX_GAMMA),
        display.y.powf(AGX_GAMMA),
        display.z.powf(AGX_GAMMA),
    )
    .min(Vec3::ONE)
}

/// The sRGB EOTF (encoded [0, 1] → linear [0, 1]), the inverse of [`srgb_oetf`]: how a PNG's
/// 8-bit values are read back as displayed light.
pub fn srgb_eotf(encoded: f32) -> f32 {
    if encoded <= 0.040_45 {
        encoded / 12.92
    } else {
        ((encoded + 0.055) / 1.055).powf(2.4)
    }
}

/// Tonemaps exposed linear radiance with `op`: linear, in [0, 1].
pub fn tonemap(op: Tonemap, exposed: Vec3) -> Vec3 {
    let c = exposed.max(Vec3::ZERO);
    match op {
        Tonemap::None => c.min(Vec3::ONE),
        Tonemap::Aces => Vec3::new(
            aces_narkowicz(c.x),
            aces_narkowicz(c.y),
            aces_narkowicz(c.z),
        ),
        Tonemap::PbrNeutral => pbr_neutral(c),
        Tonemap::Agx => agx(c),
    }
}

/// Quantizes an encoded [0, 1] value to 8 bits, rounding to nearest (halves up).
pub fn quantize_unorm8(encoded: f32) -> u8 {
    (encoded.clamp(0.0, 1.0) * 255.0 + 0.5).floor() as u8
}

/// The LDR texel of exposed radiance: tonemapped, sRGB-encoded, quantized; alpha opaque.
pub fn encode_ldr(op: Tonemap, exposed: Vec3) -> [u8; 4] {
    let mapped = tonemap(op, exposed);
    let [r, g, b] = mapped.to_array().map(|c| quantize_unorm8(srgb_oetf(c)));
    [r, g, b, 255]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f32, b: f32, tolerance: f32) -> bool {
        (a - b).abs() <= tolerance
    }

    #[test]
    fn agx_keeps_grey_grey_and_spans_black_to_white() {
        // Mid grey lands near the middle of the display range; grey stays grey.
        let grey = agx(Vec3::splat(0.18));
        assert!((grey.x - grey.y).abs() < 1e-4 && (grey.y - grey.z).abs() < 1e-4);
        assert!(close(srgb_oetf(grey.y), 0.5, 0.03), "{grey}");
        assert_eq!(agx(Vec3::ZERO), Vec3::ZERO);
        assert!(agx(Vec3::splat(1e4)).min_element() > 0.99);
        // Monotonic in exposure.
        let mut last = 0.0;
        for k in 0..200 {
            let v = agx(Vec3::splat(2f32.powf(-12.0 + k as f32 * 0.08))).y;
            assert!(v >= last, "{k}: {v} < {last}");
            last = v;
        }
        // The outset undoes the inset.
        let back = rows_times(
            &AGX_OUTSET,
            rows_times(&AGX_INSET, Vec3::new(0.3, 0.5, 0.7)),
        );
        assert!((back - Vec3::new(0.3, 0.5, 0.7)).abs().max_element() < 1e-4);
    }

    #[test]
    fn srgb_eotf_inverts_the_oetf() {
        for k in 0..=1000 {
            let x = k as f32 / 1000.0;
            assert!(close(srgb_eotf(srgb_oetf(x)), x, 1e-5), "{x}");
        }
        assert_eq!(srgb_eotf(0.0), 0.0);
        assert!(close(srgb_eotf(1.0), 1.0, 1e-6));
    }

    #[test]
    fn srgb_oetf_hand_values() {
        assert_eq!(srgb_oetf(0.0), 0.0);
        assert!(close(srgb_oetf(1.0), 1.0, 1e-6));
        // The linear segment and the power segment meet at 0.0031308 (≈ 0.04045 encoded).
        assert!(close(srgb_oetf(0.003_130_8), 0.040_45, 1e-5));
        assert!(close(srgb_oetf(0.003_131), 0.040_45, 1e-5));
        // 18% grey encodes to 0.4613561.
        assert!(close(srgb_oetf(0.18), 0.461_356_1, 1e-6));
        assert_eq!(quantize_unorm8(srgb_oetf(0.18)), 118);
    }

    #[test]
    fn aces_hand_values() {
        assert_eq!(aces_narkowicz(0.0), 0.0);
        // 1 → (2.51 + 0.03) / (2.43 + 0.59 + 0.14) = 2.54 / 3.16.
        assert!(close(aces_narkowicz(1.0), 2.54 / 3.16, 1e-6));
        // Saturates: the rational tends to 2.51 / 2.43 > 1 and is clamped.
        assert_eq!(aces_narkowicz(1e6), 1.0);
        assert!(close(
            aces_narkowicz(0.18),
            0.18 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14),
            1e-7
        ));
    }

    #[test]
    fn pbr_neutral_hand_values() {
        // Below the knee and above 2·F90: identity minus F90.
        let grey = pbr_neutral(Vec3::splat(0.5));
        assert!(grey.abs_diff_eq(Vec3::splat(0.46), 1e-6));
        // Small values: offset x − x²/0.16 (x = 0.04 → 0.03).
        let dark = pbr_neutral(Vec3::splat(0.04));
        assert!(dark.abs_diff_eq(Vec3::splat(0.01), 1e-7));
        // Exactly at the knee (0.76 + 0.04): continuous, peak stays 0.76.
        let knee = pbr_neutral(Vec3::splat(0.8));
        assert!(knee.abs_diff_eq(Vec3::splat(0.76), 1e-6));
        // Grey above the knee: p = 1.96, p_n = 1 − 0.0576 / (1.96 + 0.24 − 0.76) = 0.96.
        let bright = pbr_neutral(Vec3::splat(2.0));
        assert!(bright.abs_diff_eq(Vec3::splat(0.96), 1e-6));
        // Huge values approach white and never exceed 1.
        let huge = pbr_neutral(Vec3::new(1e5, 1e4, 1.0));
        assert!(
            huge.max_element() <= 1.0 && huge.min_element() > 0.9,
            "{huge}"
        );
    }

    #[test]
    fn pbr_neutral_keeps_hue_below_the_knee() {
        let c = Vec3::new(0.6, 0.3, 0.1);
        assert!(pbr_neutral(c).abs_diff_eq(c - Vec3::splat(0.04), 1e-6));
    }

    #[test]
    fn operators_clamp_and_encode() {
        for op in Tonemap::ALL.iter().copied() {
            assert_eq!(encode_ldr(op, Vec3::ZERO), [0, 0, 0, 255], "{op}");
            assert_eq!(encode_ldr(op, Vec3::splat(-3.0)), [0, 0, 0, 255], "{op}");
            let white = encode_ldr(op, Vec3::splat(1e9));
            assert!(white[..3].iter().all(|&c| c >= 254), "{op}: {white:?}");
        }
        assert_eq!(
            encode_ldr(Tonemap::None, Vec3::new(0.18, 1.0, 7.0)),
            [118, 255, 255, 255]
        );
    }

    #[test]
    fn shader_ids_are_distinct() {
        let mut ids: Vec<u32> = Tonemap::ALL.iter().map(|t| t.shader_id()).collect();
        ids.dedup();
        assert_eq!(ids, [0, 1, 2, 3]);
    }
}
