//! Constants that live once in Rust and once in GLSL, tied: each test reads the GLSL source
//! and checks the value there against the Rust constant, so changing one side alone fails.

use shine::capture::tonemap::Tonemap;
use shine::passes::hvl::{EMISSION_MAX_BANDS, GatherHvl, RECORD_TEXELS, RECORDS_PER_ROW};
use shine::passes::path_trace::{
    FLAG_EMISSIVE_LIGHTING, FLAG_JITTER, FLAG_LAMBERT_ONLY, FLAG_LIGHT_SAMPLING,
};
use shine::passes::proxy::{MAX_PROXIES, TABLE_ENTRIES, TILE_WORDS};
use shine_scene::{Light, LightKind, NO_TEXTURE};
use std::path::Path;

/// The value of the integer constant `name` in `shaders/<file>`, written
/// `const uint NAME = 4u;`, `const int NAME = 4;` or `#define NAME 4u`, decimal or `0x` hex.
fn glsl_uint(file: &str, name: &str) -> u32 {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("shaders")
        .join(file);
    let source = std::fs::read_to_string(&path).expect("shader source");
    let value = source
        .lines()
        .map(str::trim)
        .find_map(|line| {
            let rest = line
                .strip_prefix(&format!("const uint {name} ="))
                .or_else(|| line.strip_prefix(&format!("const int {name} =")))
                .or_else(|| line.strip_prefix(&format!("#define {name} ")))?;
            Some(
                rest.trim()
                    .trim_end_matches(';')
                    .trim_end_matches('u')
                    .trim(),
            )
        })
        .unwrap_or_else(|| panic!("{name} is not defined in {}", path.display()));
    let parsed = match value.strip_prefix("0x") {
        Some(hex) => u32::from_str_radix(hex, 16),
        None => value.parse(),
    };
    parsed.unwrap_or_else(|_| panic!("{name} = `{value}` in {} is no integer", path.display()))
}

#[test]
fn path_trace_flags_match_the_shader() {
    for (name, rust) in [
        ("PT_JITTER", FLAG_JITTER),
        ("PT_EMISSIVE_LIGHTING", FLAG_EMISSIVE_LIGHTING),
        ("PT_LAMBERT_ONLY", FLAG_LAMBERT_ONLY),
        ("PT_LIGHT_SAMPLING", FLAG_LIGHT_SAMPLING),
    ] {
        assert_eq!(glsl_uint("include/path.glsl", name), rust, "{name}");
    }
}

#[test]
fn tonemap_ids_match_the_shader() {
    for (name, op) in [
        ("TONEMAP_NONE", Tonemap::None),
        ("TONEMAP_ACES", Tonemap::Aces),
        ("TONEMAP_PBR_NEUTRAL", Tonemap::PbrNeutral),
        ("TONEMAP_AGX", Tonemap::Agx),
    ] {
        assert_eq!(
            glsl_uint("include/tonemap.glsl", name),
            op.shader_id(),
            "{name}"
        );
    }
}

#[test]
fn hvl_emission_bands_and_shadow_rays_match_the_shader() {
    assert_eq!(
        glsl_uint("include/hvl.glsl", "HVL_EMISSION_MAX_BANDS") as usize,
        EMISSION_MAX_BANDS
    );
    assert_eq!(
        glsl_uint("hvl_gather.comp", "HVL_SHADOW_RAYS_MAX"),
        shine::passes::hvl::shadows::RAYS_MAX
    );
}

#[test]
fn table_sizes_match_the_shaders() {
    assert_eq!(
        glsl_uint("include/brdf_table.glsl", "BRDF_TABLE_THETA_SAMPLES") as usize,
        shine_sh::brdf_table::THETA_SAMPLES
    );
    assert_eq!(
        glsl_uint("include/proxy_tables.glsl", "PROXY_TABLE_ENTRIES") as usize,
        TABLE_ENTRIES
    );
    // The tile masks hold one bit per proxy.
    assert_eq!(TILE_WORDS, MAX_PROXIES / 32);
    for file in ["proxy_tiles.comp", "proxy_accumulate.comp"] {
        assert_eq!(glsl_uint(file, "TILE_WORDS"), TILE_WORDS, "{file}");
    }
}

#[test]
fn scene_encodings_match_the_shaders() {
    assert_eq!(glsl_uint("include/scene.glsl", "NO_TEXTURE"), NO_TEXTURE);
    for (name, kind) in [
        ("LIGHT_DIRECTIONAL", LightKind::Directional),
        ("LIGHT_POINT", LightKind::Point),
        ("LIGHT_SPOT", LightKind::Spot),
    ] {
        let light = Light {
            kind: glsl_uint("include/scene.glsl", name),
            ..<Light as bytemuck::Zeroable>::zeroed()
        };
        assert_eq!(light.light_kind(), Some(kind), "{name}");
    }
}

/// The value of the float constant `name` in `shaders/<file>`, written
/// `const float NAME = 0.5;`.
fn glsl_float(file: &str, name: &str) -> f32 {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("shaders")
        .join(file);
    let source = std::fs::read_to_string(&path).expect("shader source");
    source
        .lines()
        .map(str::trim)
        .find_map(|line| {
            let rest = line.strip_prefix(&format!("const float {name} ="))?;
            rest.trim().trim_end_matches(';').trim().parse().ok()
        })
        .unwrap_or_else(|| panic!("{name} is not a float constant in {}", path.display()))
}

#[test]
fn amortise_constants_match_the_shader() {
    use shine::passes::amortise::{
        RECORD_BLOCK, REGATHER_SLICE, RESOLVE_ALPHA, RESOLVE_CHANGE_LIMIT, RESOLVE_DEPTH_TOLERANCE,
        RESOLVE_NORMAL_COS,
    };
    let file = "include/amortise.glsl";
    assert_eq!(glsl_uint(file, "AMORTISE_REGATHER_SLICE"), REGATHER_SLICE);
    assert_eq!(glsl_uint(file, "AMORTISE_RECORD_BLOCK"), RECORD_BLOCK);
    assert_eq!(glsl_float(file, "RESOLVE_ALPHA"), RESOLVE_ALPHA);
    assert_eq!(
        glsl_float(file, "RESOLVE_DEPTH_TOLERANCE"),
        RESOLVE_DEPTH_TOLERANCE
    );
    assert_eq!(glsl_float(file, "RESOLVE_NORMAL_COS"), RESOLVE_NORMAL_COS);
    assert_eq!(
        glsl_float(file, "RESOLVE_CHANGE_LIMIT"),
        RESOLVE_CHANGE_LIMIT
    );
}

#[test]
fn agx_constants_match_the_shader() {
    use shine::capture::tonemap::{AGX_GAMMA, AGX_MAX_EV, AGX_MIN_EV};
    let file = "include/tonemap.glsl";
    assert_eq!(glsl_float(file, "AGX_MIN_EV"), AGX_MIN_EV);
    assert_eq!(glsl_float(file, "AGX_MAX_EV"), AGX_MAX_EV);
    assert_eq!(glsl_float(file, "AGX_GAMMA"), AGX_GAMMA);
}

#[test]
fn accumulate_constant_matches_the_shader() {
    use shine::passes::accumulate::{
        ACCUMULATE_CHANGE, ACCUMULATE_MIN_LUMINANCE, ACCUMULATE_MIN_WEIGHT, TAA_MIN_INVERSE,
        TAA_MOVING_FRAMES, TAA_STILL_PIXELS,
    };
    let file = "include/accumulate.glsl";
    assert_eq!(glsl_float(file, "ACCUMULATE_CHANGE"), ACCUMULATE_CHANGE);
    assert_eq!(
        glsl_float(file, "ACCUMULATE_MIN_LUMINANCE"),
        ACCUMULATE_MIN_LUMINANCE
    );
    assert_eq!(
        glsl_float("include/color.glsl", "HALF_MAX"),
        shine::reference::denoise::HALF_MAX
    );
    assert_eq!(
        glsl_float(file, "ACCUMULATE_MIN_WEIGHT"),
        ACCUMULATE_MIN_WEIGHT
    );
    assert_eq!(glsl_float(file, "TAA_MIN_INVERSE"), TAA_MIN_INVERSE);
    assert_eq!(glsl_float(file, "TAA_STILL_PIXELS"), TAA_STILL_PIXELS);
    assert_eq!(
        glsl_float(file, "TAA_MOVING_FRAMES"),
        TAA_MOVING_FRAMES as f32
    );
}

#[test]
fn hvl_incidence_clamp_matches_the_shader() {
    assert_eq!(
        glsl_float("include/sh.glsl", "HVL_MIN_INCIDENCE_COS"),
        shine_sh::hvl::MIN_INCIDENCE_COS
    );
}

#[test]
fn diffuse_fresnel_fit_matches_the_shader() {
    use shine::passes::brdf_tables::{DIFFUSE_FRESNEL_POWER, DIFFUSE_FRESNEL_SCALE};
    let file = "include/brdf.glsl";
    assert_eq!(
        glsl_float(file, "BRDF_DIFFUSE_FRESNEL_SCALE"),
        DIFFUSE_FRESNEL_SCALE
    );
    assert_eq!(
        glsl_float(file, "BRDF_DIFFUSE_FRESNEL_POWER"),
        DIFFUSE_FRESNEL_POWER
    );
}

#[test]
fn specular_fade_matches_the_shader() {
    assert_eq!(
        glsl_float("include/brdf.glsl", "SPECULAR_FADE"),
        shine::passes::specular::FADE
    );
}

#[test]
fn exposure_floor_matches_the_shader() {
    assert_eq!(
        glsl_float("exposure.comp", "EXPOSURE_LUMINANCE_FLOOR"),
        shine::passes::exposure::LUMINANCE_FLOOR
    );
}

#[test]
fn aaf_fit_condition_matches_the_shader() {
    assert_eq!(
        glsl_float("include/aaf.glsl", "AAF_FIT_CONDITION_MIN"),
        shine_sh::aaf::FIT_CONDITION_MIN
    );
}

#[test]
fn aaf_sums_layout_and_weight_floor_match_the_shader() {
    assert_eq!(
        u64::from(glsl_uint("include/aaf.glsl", "AAF_SUMS_STRIDE")),
        shine::passes::aaf::SUMS_STRIDE
    );
    assert_eq!(
        u64::from(glsl_uint("include/aaf.glsl", "AAF_ROWS_STRIDE")),
        shine::passes::aaf::ROWS_STRIDE
    );
    assert_eq!(
        glsl_float("include/aaf.glsl", "AAF_WEIGHT_MIN"),
        shine::reference::aaf::WEIGHT_MIN
    );
    assert_eq!(
        glsl_float("include/aaf.glsl", "AAF_TANGENT_SCALE"),
        shine_sh::aaf::TANGENT_SCALE
    );
}

#[test]
fn rec709_luma_matches_the_shader() {
    let file = "include/color.glsl";
    let source = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("shaders")
            .join(file),
    )
    .expect("shader source");
    let [r, g, b] = shine::capture::tonemap::REC709_LUMA;
    assert!(
        source.contains(&format!("const vec3 REC709_LUMA = vec3({r}, {g}, {b});")),
        "REC709_LUMA differs from {:?}",
        [r, g, b]
    );
}

#[test]
fn hvl_records_layout_matches_the_shader() {
    assert_eq!(
        glsl_uint("include/hvl.glsl", "HVL_RECORDS_PER_ROW"),
        RECORDS_PER_ROW
    );
    assert_eq!(
        glsl_uint("include/hvl.glsl", "HVL_RECORD_TEXELS"),
        RECORD_TEXELS
    );
    assert_eq!(
        std::mem::size_of::<GatherHvl>(),
        16 * RECORD_TEXELS as usize
    );
    // One texel per field, in GatherHvl's order.
    for (name, offset) in [
        (
            "HVL_RECORD_POSITION_RADIUS",
            std::mem::offset_of!(GatherHvl, position_radius),
        ),
        (
            "HVL_RECORD_NORMAL_AREA",
            std::mem::offset_of!(GatherHvl, normal_area),
        ),
        (
            "HVL_RECORD_FLUX_E0",
            std::mem::offset_of!(GatherHvl, flux_e0),
        ),
        (
            "HVL_RECORD_EMISSION",
            std::mem::offset_of!(GatherHvl, emission),
        ),
        (
            "HVL_RECORD_IDENTITY",
            std::mem::offset_of!(GatherHvl, identity),
        ),
    ] {
        assert_eq!(
            glsl_uint("include/hvl.glsl", name) as usize * 16,
            offset,
            "{name}"
        );
    }
}

#[test]
fn bvh_image_rows_match_the_shader() {
    assert_eq!(
        glsl_uint("include/trace.glsl", "TRACE_ROW_TEXELS"),
        shine::gpu_scene::bvh::TRACE_ROW_TEXELS
    );
}

#[test]
fn igi_sets_max_matches_the_shader() {
    assert_eq!(
        glsl_uint("include/sample_identity.glsl", "IGI_SETS_MAX"),
        shine::passes::igi::SETS_MAX
    );
}

#[test]
fn denoise_constants_match_the_shader() {
    use shine::reference::denoise as d;
    for (name, value) in [
        ("DENOISE_LOBE_FRACTION", d::LOBE_FRACTION),
        ("DENOISE_MAX_LOBE_ANGLE", d::MAX_LOBE_ANGLE),
        ("DENOISE_MAX_RADIUS", d::MAX_RADIUS),
        ("DENOISE_SHARP_RADIUS", d::SHARP_RADIUS),
        ("DENOISE_MIN_PARALLAX", d::MIN_PARALLAX),
        ("DENOISE_PLANE_SIGMA", d::PLANE_SIGMA),
        ("DENOISE_MIN_NORMAL_TOLERANCE", d::MIN_NORMAL_TOLERANCE),
        ("DENOISE_ROUGHNESS_SIGMA", d::ROUGHNESS_SIGMA),
        ("DENOISE_LUMINANCE_SIGMA", d::LUMINANCE_SIGMA),
        ("DENOISE_MIN_WEIGHT", d::MIN_WEIGHT),
        (
            "DENOISE_DIFFUSE_NORMAL_TOLERANCE",
            d::DIFFUSE_NORMAL_TOLERANCE,
        ),
        ("DENOISE_FIREFLY_RATIO", d::FIREFLY_RATIO),
        ("DENOISE_MATCH", d::MATCH),
        ("DENOISE_LUMINANCE_EPSILON", d::LUMINANCE_EPSILON),
        ("DENOISE_RAY_FLOOR", d::RAY_FLOOR),
        ("DENOISE_RAY_KEEP_TAN", d::RAY_KEEP_TAN),
        ("DENOISE_RAY_MAX_FACTOR", d::RAY_MAX_FACTOR),
    ] {
        assert_eq!(glsl_float("include/denoise.glsl", name), value, "{name}");
    }
}
