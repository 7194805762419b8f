//! Every built-in scene passes the Khronos glTF validator (npm `gltf-validator`) with zero
//! errors. Needs Node.js and `npm ci` in `crates/scene/tests/validator/`; without them the
//! test fails (it never skips) and says what to install.

use std::path::PathBuf;
use std::process::Command;

#[test]
fn builtin_scenes_pass_the_khronos_validator() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/validator");
    let install = format!(
        "install it with `npm ci --prefix {}` (needs Node.js >= 18)",
        dir.display()
    );
    let in_ci = std::env::var_os("CI").is_some();
    assert!(
        dir.join("node_modules/gltf-validator/package.json")
            .exists(),
        "gltf-validator is not installed{}: {install}",
        if in_ci { " in CI" } else { "" }
    );
    let out_dir =
        std::env::temp_dir().join(format!("shine-scene-validator-{}", std::process::id()));
    std::fs::create_dir_all(&out_dir).unwrap();
    let mut files = Vec::new();
    for name in shine_scene::builtin::names() {
        let path = out_dir.join(format!("{name}.glb"));
        shine_scene::builtin::export(name, &path).unwrap();
        files.push(path);
    }
    let output = Command::new("node")
        .arg(dir.join("validate.mjs"))
        .args(&files)
        .output()
        .unwrap_or_else(|e| panic!("cannot run `node` ({e}); install Node.js and then {install}"));
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    std::fs::remove_dir_all(&out_dir).unwrap();
    assert!(
        output.status.success(),
        "validator reported errors or failed:\n{stdout}\n{stderr}"
    );
    let mut checked = 0;
    for line in stdout.lines() {
        let report: serde_json::Value = serde_json::from_str(line)
            .unwrap_or_else(|e| panic!("bad validator output {line:?}: {e}"));
        assert_eq!(report["errors"], 0, "{line}");
        checked += 1;
    }
    assert_eq!(checked, files.len(), "{stdout}");
}
