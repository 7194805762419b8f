//! Rewrites the generated tables section of `shaders/include/sh.glsl` from shine-sh.

use std::process::ExitCode;

fn main() -> ExitCode {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../shaders/include/sh.glsl");
    let glsl = match std::fs::read_to_string(path) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot read {path}: {e}");
            return ExitCode::FAILURE;
        }
    };
    let section = match shine_sh::glsl_tables::generated_section() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("cannot generate the tables: {e}");
            return ExitCode::FAILURE;
        }
    };
    let Some(out) = shine_sh::glsl_tables::splice(&glsl, &section) else {
        eprintln!("{path} lacks the generated-section markers");
        return ExitCode::FAILURE;
    };
    let tmp = format!("{path}.tmp");
    if let Err(e) = std::fs::write(&tmp, out).and_then(|()| std::fs::rename(&tmp, path)) {
        eprintln!("cannot write {path}: {e}");
        return ExitCode::FAILURE;
    }
    println!("updated {path}");
    ExitCode::SUCCESS
}
