//! Generates the C API's header with cbindgen: `$OUT_DIR/shine.h`, copied to
//! `target/<profile>/include/shine.h` beside `libshine_capi.so` and `libshine_capi.a` for C hosts.

use std::path::{Path, PathBuf};

fn main() {
    let crate_dir = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets it"));
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets it"));
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("crates/capi/cbindgen.toml: {e}"));
    let bindings = cbindgen::generate_with_config(&crate_dir, config)
        .unwrap_or_else(|e| panic!("generating shine.h: {e}"));
    let header = out.join("shine.h");
    bindings.write_to_file(&header);
    // OUT_DIR is target/<profile>/build/shine-capi-<hash>/out.
    if let Some(profile_dir) = out.ancestors().nth(3) {
        install(&header, &profile_dir.join("include").join("shine.h"));
    }
}

/// Copies `from` to `to` through a temporary file, so a C build never reads half a header.
fn install(from: &Path, to: &Path) {
    let Some(dir) = to.parent() else { return };
    std::fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let partial = to.with_extension("h.partial");
    std::fs::copy(from, &partial).unwrap_or_else(|e| panic!("{}: {e}", partial.display()));
    std::fs::rename(&partial, to).unwrap_or_else(|e| panic!("{}: {e}", to.display()));
}
