//! What the C API's tests share.

use std::path::PathBuf;

/// `target/<profile>`, where cargo put `libshine_capi.so` and build.rs `include/shine.h`.
pub fn profile_dir() -> PathBuf {
    let test_exe = std::env::current_exe().expect("test executable");
    // target/<profile>/deps/c_host-<hash>
    test_exe
        .parent()
        .and_then(|deps| deps.parent())
        .expect("target/<profile>")
        .to_path_buf()
}
