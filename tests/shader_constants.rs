//! Constants that live once in Rust and once in GLSL, tied: each test reads the GLSL source
//! and checks the value there against the Rust constant, so changing one side alone fails.

use shine::capture::tonemap::Tonemap;
use shine::passes::hvl::EMISSION_MAX_BANDS;
use shine::passes::path_trace::{FLAG_EMISSIVE_LIGHTING, FLAG_JITTER, FLAG_LAMBERT_ONLY};
use std::path::Path;

/// The value of the unsigned integer constant `name` in `shaders/<file>`, written either
/// `const uint NAME = 4u;` or `#define NAME 4u` (or without the `u`).
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
                .or_else(|| line.strip_prefix(&format!("#define {name} ")))?;
            Some(
                rest.trim()
                    .trim_end_matches(';')
                    .trim_end_matches('u')
                    .trim(),
            )
        })
        .unwrap_or_else(|| panic!("{name} is not defined in {}", path.display()));
    value
        .parse()
        .unwrap_or_else(|_| panic!("{name} = `{value}` in {} is no integer", path.display()))
}

#[test]
fn path_trace_flags_match_the_shader() {
    for (name, rust) in [
        ("PT_JITTER", FLAG_JITTER),
        ("PT_EMISSIVE_LIGHTING", FLAG_EMISSIVE_LIGHTING),
        ("PT_LAMBERT_ONLY", FLAG_LAMBERT_ONLY),
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
    ] {
        assert_eq!(
            glsl_uint("include/tonemap.glsl", name),
            op.shader_id(),
            "{name}"
        );
    }
}

#[test]
fn hvl_emission_bands_match_the_shader() {
    assert_eq!(
        glsl_uint("include/hvl.glsl", "HVL_EMISSION_MAX_BANDS") as usize,
        EMISSION_MAX_BANDS
    );
}
