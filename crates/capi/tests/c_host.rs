//! The C API from C: `tests/handles.c` compiled as C99 (`-std=c99 -pedantic -Wall -Werror`,
//! so the generated header is pure C99) against `libshine_capi`, and run: null, stale,
//! destroyed and wrong-kind handles, bad paths and NaN arguments each get their code and a
//! message, and nothing crashes.

use std::path::PathBuf;
use std::process::Command;

mod common;

#[test]
fn bad_handles_and_arguments_get_codes_and_messages() {
    let (include, lib) = (common::include_dir(), common::library_dir());
    assert!(
        include.join("shine.h").is_file() && lib.join("libshine_capi.so").is_file(),
        "no shine.h in {} or no libshine_capi.so in {}",
        include.display(),
        lib.display()
    );
    let out = std::env::temp_dir().join(format!("shine-capi-handles-{}", std::process::id()));
    let source = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/handles.c");
    let compiled = Command::new("cc")
        .args(["-std=c99", "-pedantic", "-Wall", "-Wextra", "-Werror"])
        .arg(format!("-I{}", include.display()))
        .arg(&source)
        .arg("-o")
        .arg(&out)
        .arg(format!("-L{}", lib.display()))
        .arg("-lshine_capi")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .output()
        .expect("run cc (a C compiler is part of the test's set-up)");
    assert!(
        compiled.status.success(),
        "{}",
        String::from_utf8_lossy(&compiled.stderr)
    );
    // The library just linked, first (cargo's LD_LIBRARY_PATH may name an older copy).
    let run = Command::new(&out)
        .env("LD_LIBRARY_PATH", &lib)
        .output()
        .expect("run the C test");
    let stdout = String::from_utf8_lossy(&run.stdout);
    println!("{stdout}");
    let _ = std::fs::remove_file(&out);
    assert!(
        run.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(stdout.contains("0 failure(s)"), "{stdout}");
}
