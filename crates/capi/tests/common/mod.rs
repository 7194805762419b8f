//! What the C API's tests share: where cargo put the library and build.rs the header.

use std::path::PathBuf;

/// `target/<profile>`: build.rs writes `include/shine.h` there.
pub fn profile_dir() -> PathBuf {
    let test_exe = std::env::current_exe().expect("test executable");
    // target/<profile>/deps/<test>-<hash>
    test_exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("target/<profile>")
        .to_path_buf()
}

/// The directory of `shine.h`.
pub fn include_dir() -> PathBuf {
    profile_dir().join("include")
}

/// The directory of the `libshine_capi.so` this test run built: `target/<profile>/deps`
/// (`cargo test` leaves it there; only `cargo build` copies it up to `target/<profile>`).
pub fn library_dir() -> PathBuf {
    profile_dir().join("deps")
}
