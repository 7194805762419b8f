//! Compiles every shader under shaders/ to SPIR-V 1.5 with glslang, validates and reflects it
//! with naga, and writes `$OUT_DIR/shaders.rs` (docs/architecture.md, "Shaders"). A GLSL error or a construct naga
//! cannot read fails the build with the file and line.

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

#[path = "build/shader_build.rs"]
mod shader_build;

use std::path::PathBuf;

fn main() {
    git_revision();
    let root = manifest_dir().join("shaders");
    println!("cargo::rerun-if-changed={}", root.display());
    let output = match shader_build::build_all(&root) {
        Ok(output) => output,
        Err(error) => {
            eprintln!("error: shader build failed\n{error}");
            std::process::exit(1);
        }
    };
    for input in &output.inputs {
        println!("cargo::rerun-if-changed={}", input.display());
    }
    let Some(out_dir) = std::env::var_os("OUT_DIR") else {
        eprintln!("error: OUT_DIR is not set (build.rs must run under cargo)");
        std::process::exit(1);
    };
    let path = PathBuf::from(out_dir).join("shaders.rs");
    if let Err(error) = std::fs::write(&path, shader_build::codegen::generate_rust(&output.shaders))
    {
        eprintln!("error: cannot write {}: {error}", path.display());
        std::process::exit(1);
    }
}

/// The package's folder, as cargo gives it to this run of the script: a compiled script can
/// be reused for another checkout sharing the target folder (same package, same hash), so
/// the folder it was compiled in may be gone.
fn manifest_dir() -> PathBuf {
    std::env::var_os("CARGO_MANIFEST_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")))
}

/// Sets `SHINE_GIT_REV` (what `shine profile --format json` reports): the short commit HEAD
/// points to, or `unknown` outside a git checkout. Uncommitted changes are not marked: the
/// script reruns when HEAD moves, not when a source file changes.
fn git_revision() {
    let root = manifest_dir();
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(&root)
            .output()
            .ok()
            .filter(|out| out.status.success())
            .map(|out| String::from_utf8_lossy(&out.stdout).trim().to_string())
    };
    let revision = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_else(|| "unknown".into());
    println!("cargo::rustc-env=SHINE_GIT_REV={revision}");
    // Only files that exist: cargo reruns a script that names a missing one every build.
    if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
        let head = git(&["symbolic-ref", "-q", "HEAD"]);
        let watched = ["HEAD", head.as_deref().unwrap_or("HEAD"), "packed-refs"];
        for file in watched.map(|f| PathBuf::from(&dir).join(f)) {
            if file.is_file() {
                println!("cargo::rerun-if-changed={}", file.display());
            }
        }
    }
}
