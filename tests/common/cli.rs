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

/// Asserts that each file named in `names` is the same, byte for byte, in `a` and in `b`.
pub fn assert_same_files(a: &std::path::Path, b: &std::path::Path, names: &[String]) {
    for name in names {
        let x = std::fs::read(a.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        let y = std::fs::read(b.join(name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(
            x == y,
            "{name} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

/// The largest per-channel difference of two RGBA images relative to `reference`'s value
/// (plus 1e-6, for black pixels).
pub fn worst_relative(image: &[[f32; 4]], reference: &[[f32; 4]]) -> f32 {
    assert_eq!(image.len(), reference.len(), "image sizes differ");
    image
        .iter()
        .zip(reference)
        .flat_map(|(x, y)| (0..3).map(move |c| (x[c] - y[c]).abs() / (y[c].abs() + 1e-6)))
        .fold(0.0f32, f32::max)
}
