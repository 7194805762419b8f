//! Running the `shine` binary as a user does, for the CLI tests.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs `shine` with `args`; returns what it printed and its exit status.
pub fn shine(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_shine"))
        .args(args)
        .output()
        .expect("run shine")
}

/// An empty scratch directory for `test` under the target directory.
pub fn scratch(test: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

/// Everything `out` printed, stdout then stderr.
pub fn text(out: &Output) -> String {
    format!(
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// Asserts a clean failure: exit status 1, a message containing `needle`, no panic.
pub fn fails_cleanly(out: &Output, needle: &str) {
    let all = text(out);
    assert_eq!(out.status.code(), Some(1), "{all}");
    assert!(all.contains(needle), "expected `{needle}` in:\n{all}");
    assert!(!all.contains("panicked"), "{all}");
}
