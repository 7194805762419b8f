//! The loader over a directory of broken files (`tests/broken/`): each gives an error (or,
//! where the scene survives, a warning) naming the file and the element, and none panics.
//! Then truncations and byte flips of the built-in scenes, which must never panic.
//!
//! The files are generated here; after changing a case, refresh the directory with
//! `SHINE_UPDATE_BROKEN=1 cargo test -p shine-scene --test broken_files`. They also seed the
//! fuzz corpus (`crates/scene/fuzz`).

mod common;

use std::collections::BTreeMap;
use std::path::PathBuf;

use glam::{Vec2, Vec3};
use serde_json::{Value, json};
use shine_scene::builtin::shapes::MeshData;
use shine_scene::glb_writer::GlbWriter;

/// What loading a case must give: an error or a warning containing every listed fragment.
enum Expect {
    Error(&'static [&'static str]),
    Warning(&'static [&'static str]),
}

fn broken_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/broken")
}

fn mesh_writer(positions: Vec<Vec3>, indices: Vec<u32>) -> GlbWriter {
    let mut w = GlbWriter::new();
    let n = positions.len();
    let m = MeshData {
        positions,
        normals: vec![Vec3::Z; n],
        uvs: vec![Vec2::ZERO; n],
        indices,
    };
    let mat = w.push("materials", json!({"name": "grey"}));
    let mesh = w.mesh("bad mesh", &[(&m, mat)]);
    let node = w.push("nodes", json!({"name": "n", "mesh": mesh}));
    w.scene("s", &[node]);
    w
}

fn text(v: &Value) -> Vec<u8> {
    serde_json::to_vec_pretty(v).unwrap()
}

fn tri() -> Value {
    common::gltf_json(&common::triangle())
}

fn cases() -> Vec<(&'static str, Vec<u8>, Expect)> {
    let mut out: Vec<(&'static str, Vec<u8>, Expect)> = Vec::new();
    let glb = common::triangle().to_glb();

    out.push((
        "empty.glb",
        Vec::new(),
        Expect::Error(&["not a valid glTF"]),
    ));
    out.push((
        "not-gltf.glb",
        b"hello, I am not a model".to_vec(),
        Expect::Error(&["not a valid glTF"]),
    ));
    let cornell = shine_scene::builtin::build("cornell-box").unwrap();
    out.push((
        "truncated.glb",
        cornell[..2000].to_vec(),
        Expect::Error(&["not a valid glTF"]),
    ));
    // A GLB whose BIN chunk is shorter than its buffer claims (headers patched to match).
    let mut short = glb[..glb.len() - 16].to_vec();
    let total = short.len() as u32;
    short[8..12].copy_from_slice(&total.to_le_bytes());
    let json_len = u32::from_le_bytes(short[12..16].try_into().unwrap()) as usize;
    let bin_at = 20 + json_len;
    let bin_len = u32::from_le_bytes(short[bin_at..bin_at + 4].try_into().unwrap()) - 16;
    short[bin_at..bin_at + 4].copy_from_slice(&bin_len.to_le_bytes());
    out.push((
        "short-bin-chunk.glb",
        short,
        Expect::Error(&["buffers[0]", "truncated"]),
    ));
    out.push((
        "bad-json.gltf",
        br#"{"asset": {"version": "2.0"}, "nodes": ["#.to_vec(),
        Expect::Error(&["not a valid glTF"]),
    ));

    let mut j = tri();
    j["buffers"][0]["uri"] = json!("missing.bin");
    out.push((
        "missing-buffer.gltf",
        text(&j),
        Expect::Error(&["buffers[0]", "missing.bin"]),
    ));
    let mut j = tri();
    j["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@");
    out.push((
        "bad-base64.gltf",
        text(&j),
        Expect::Error(&["buffers[0]", "base64"]),
    ));

    let mut j = tri();
    j["images"] = json!([{"uri": "missing.png"}]);
    j["textures"] = json!([{"source": 0}]);
    j["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = json!({"index": 0});
    out.push((
        "missing-image.gltf",
        text(&j),
        Expect::Warning(&["materials[0]", "images[0]", "missing.png"]),
    ));
    let mut j = tri();
    j["images"] = json!([{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAAB"}]);
    j["textures"] = json!([{"source": 0}]);
    j["materials"][0]["normalTexture"] = json!({"index": 0});
    out.push((
        "corrupt-image.gltf",
        text(&j),
        Expect::Warning(&["materials[0]", "images[0]", "decode"]),
    ));

    let w = mesh_writer(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![0, 1, 2, 0, 2, 99]);
    out.push((
        "index-out-of-range.gltf",
        text(&common::gltf_json(&w)),
        Expect::Error(&["meshes[0]", "\"bad mesh\"", "indices", "99"]),
    ));
    for (name, bad) in [
        ("nan-position.gltf", f32::NAN),
        ("infinite-position.gltf", f32::INFINITY),
    ] {
        let w = mesh_writer(
            vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, bad, 0.0)],
            vec![0, 1, 2],
        );
        let mut j = common::gltf_json(&w);
        // Keep min/max valid so the file gets past the JSON checks to the data.
        j["accessors"][0]["min"] = json!([0.0, 0.0, 0.0]);
        j["accessors"][0]["max"] = json!([1.0, 1.0, 0.0]);
        out.push((
            name,
            text(&j),
            Expect::Error(&["meshes[0]", "POSITION", "element 2", "NaN or infinite"]),
        ));
    }
    let mut j = tri();
    j["accessors"][0]["count"] = json!(1000);
    out.push((
        "accessor-past-buffer.gltf",
        text(&j),
        Expect::Error(&["POSITION", "accessors[0]", "do not fit"]),
    ));
    let mut j = tri();
    j["accessors"][0]
        .as_object_mut()
        .unwrap()
        .remove("bufferView");
    j["accessors"][0]["count"] = json!(1u64 << 40);
    j["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": 0, "componentType": 5121}, "values": {"bufferView": 0}});
    out.push((
        "huge-viewless-accessor.gltf",
        text(&j),
        Expect::Error(&["POSITION", "no bufferView"]),
    ));
    let mut j = tri();
    j["bufferViews"][0]["byteStride"] = json!(4);
    out.push((
        "stride-too-small.gltf",
        text(&j),
        Expect::Error(&["accessors[0]", "byteStride"]),
    ));
    let mut j = tri();
    j["nodes"][0]["mesh"] = json!(7);
    out.push((
        "bad-reference.gltf",
        text(&j),
        Expect::Error(&["not a valid glTF", "mesh"]),
    ));
    let mut j = tri();
    j["nodes"] = json!([{"name": "a", "children": [1]}, {"name": "b", "children": [0]}]);
    j["scenes"][0]["nodes"] = json!([]);
    out.push((
        "node-cycle.gltf",
        text(&j),
        Expect::Error(&["nodes[", "cycle"]),
    ));
    let mut j = tri();
    j["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    out.push((
        "required-extension.gltf",
        text(&j),
        Expect::Error(&["extensionsRequired", "KHR_draco_mesh_compression"]),
    ));
    let mut j = tri();
    j["nodes"][0]["extras"] = json!({"shine_proxies": [{"center": [0, 0, 0], "radius": -1}]});
    out.push((
        "bad-proxies.gltf",
        text(&j),
        Expect::Error(&["nodes[0]", "shine_proxies", "entry 0"]),
    ));
    let mut j = tri();
    j["extras"] = json!({"shine_environment": {"type": "cubemap"}});
    out.push((
        "bad-environment.gltf",
        text(&j),
        Expect::Error(&["extras.shine_environment", "cubemap"]),
    ));
    // Key times read from the box's index data (0, 1, ...): fine; reversed they are not.
    let mut j = common::gltf_json(&common::animated_boxes(None));
    let input = j["animations"][0]["samplers"][0]["input"].as_u64().unwrap() as usize;
    let output = j["animations"][0]["samplers"][0]["output"]
        .as_u64()
        .unwrap() as usize;
    j["accessors"][input]["min"] = json!([-1.0]);
    j["accessors"][input]["max"] = json!([0.0]);
    // The output holds (0,0,0) then (4,0,0): read its first two floats as times 0, 0.
    j["accessors"][input]["bufferView"] = j["accessors"][output]["bufferView"].clone();
    out.push((
        "bad-animation-times.gltf",
        text(&j),
        Expect::Error(&["animations[0]", "channels[0]", "strictly increasing"]),
    ));
    let mut j = tri();
    j["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.0, "znear": 0.1}}]);
    j["nodes"][0]["camera"] = json!(0);
    out.push((
        "bad-camera.gltf",
        text(&j),
        Expect::Error(&["cameras[0]", "invalid projection"]),
    ));
    let mut j = tri();
    j["nodes"][0]["extensions"] = json!({"KHR_lights_punctual": {"light": 3}});
    out.push(("missing-light.gltf", text(&j), Expect::Error(&["light"])));
    skin_cases(&mut out);
    out
}

/// Broken skins, skinning attributes and morph weights, edited from the skinned bar.
fn skin_cases(out: &mut Vec<(&'static str, Vec<u8>, Expect)>) {
    let bar = || common::gltf_json(&common::skinned_bar(|_| {}));
    let attrs = "/meshes/0/primitives/0/attributes";
    let mut j = bar();
    j["skins"][0]["joints"] = json!([]);
    j["skins"][0]
        .as_object_mut()
        .unwrap()
        .remove("inverseBindMatrices");
    j["skins"][0].as_object_mut().unwrap().remove("skeleton");
    out.push((
        "skin-without-joints.gltf",
        text(&j),
        Expect::Error(&["skins[0]", "no joints"]),
    ));
    let mut j = bar();
    j["skins"][0]["joints"] = json!([1, 99]);
    out.push((
        "skin-dangling-joint.gltf",
        text(&j),
        Expect::Error(&["skins[0].joints"]),
    ));
    let mut j = bar();
    j["skins"][0]["joints"] = json!([1, 0, 2]);
    out.push((
        "inverse-bind-count.gltf",
        text(&j),
        Expect::Error(&["skins[0]", "inverseBindMatrices", "2 matrices for 3 joints"]),
    ));
    let mut j = bar();
    j["skins"][0]["joints"] = json!([1]);
    j["skins"][0]
        .as_object_mut()
        .unwrap()
        .remove("inverseBindMatrices");
    out.push((
        "joint-out-of-range.gltf",
        text(&j),
        Expect::Error(&[
            "meshes[0]",
            "JOINTS_0",
            "joint index 1",
            "1 joints",
            "nodes[2]",
        ]),
    ));
    const NO_WEIGHTS: &[&str] = &["meshes[0]", "primitives[0]", "no WEIGHTS_0"];
    const NO_JOINTS: &[&str] = &["meshes[0]", "primitives[0]", "no JOINTS_0"];
    for (name, semantic, missing) in [
        ("joints-without-weights.gltf", "WEIGHTS_0", NO_WEIGHTS),
        ("weights-without-joints.gltf", "JOINTS_0", NO_JOINTS),
    ] {
        let mut j = bar();
        j.pointer_mut(attrs)
            .unwrap()
            .as_object_mut()
            .unwrap()
            .remove(semantic);
        out.push((name, text(&j), Expect::Error(missing)));
    }
    let mut j = bar();
    let joints = j.pointer(attrs).unwrap()["JOINTS_0"].as_u64().unwrap() as usize;
    j["accessors"][joints]["componentType"] = json!(5126);
    out.push((
        "float-joints.gltf",
        text(&j),
        Expect::Error(&["JOINTS_0", "unsigned byte or short"]),
    ));
    const NEGATIVE: &[&str] = &["WEIGHTS_0", "element 5", "negative weight"];
    const NAN: &[&str] = &["WEIGHTS_0", "element 5", "NaN or infinite"];
    const ZERO: &[&str] = &["WEIGHTS_0", "element 5", "all four zero"];
    for (name, value, fragments) in [
        ("negative-weight.gltf", -0.5, NEGATIVE),
        ("nan-weight.gltf", f32::NAN, NAN),
        ("zero-weights.gltf", 0.0, ZERO),
    ] {
        let w = common::skinned_bar(|w| w[5] = glam::Vec4::new(value, 0.0, 0.0, 0.0));
        out.push((name, text(&common::gltf_json(&w)), Expect::Error(fragments)));
    }
    let mut j = bar();
    j["nodes"][2]["weights"] = json!([1.0]);
    out.push((
        "node-weight-count.gltf",
        text(&j),
        Expect::Error(&["nodes[2]", "1 weights for 2 morph targets"]),
    ));
    let mut j = bar();
    j["animations"][0]["channels"][1]["target"]["node"] = json!(0);
    out.push((
        "weights-without-targets.gltf",
        text(&j),
        Expect::Error(&["channels[1]", "no morph targets"]),
    ));
    let mut j = bar();
    j["nodes"][2].as_object_mut().unwrap().remove("skin");
    out.push((
        "joints-without-skin.gltf",
        text(&j),
        Expect::Warning(&["nodes[2]", "no skin", "drawn rigid"]),
    ));
}

fn check(name: &str, result: Result<shine_scene::Scene, shine_scene::Error>, expect: &Expect) {
    match (expect, result) {
        (Expect::Error(fragments), Err(e)) => {
            let msg = e.to_string();
            assert!(
                msg.contains(name),
                "{name}: the error does not name the file: {msg}"
            );
            for f in *fragments {
                assert!(
                    msg.contains(f),
                    "{name}: expected {f:?} in the error: {msg}"
                );
            }
        }
        (Expect::Warning(fragments), Ok(scene)) => {
            let found = scene
                .warnings
                .iter()
                .any(|w| w.contains(name) && fragments.iter().all(|f| w.contains(f)));
            assert!(
                found,
                "{name}: expected a warning with {fragments:?}, got {:?}",
                scene.warnings
            );
        }
        (Expect::Error(_), Ok(s)) => {
            panic!("{name}: loaded without error (warnings {:?})", s.warnings)
        }
        (Expect::Warning(_), Err(e)) => {
            panic!("{name}: expected to load with a warning, failed: {e}")
        }
    }
}

#[test]
fn every_broken_file_gives_a_clear_error_or_warning() {
    let dir = broken_dir();
    let cases = cases();
    if std::env::var_os("SHINE_UPDATE_BROKEN").is_some() {
        if dir.exists() {
            std::fs::remove_dir_all(&dir).unwrap();
        }
        std::fs::create_dir_all(&dir).unwrap();
        for (name, bytes, _) in &cases {
            std::fs::write(dir.join(name), bytes).unwrap();
        }
    }
    let expected: BTreeMap<&str, &Expect> = cases.iter().map(|(n, _, e)| (*n, e)).collect();
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let Some(expect) = expected.get(name.as_str()) else {
            panic!("{name} in {} has no case; add it to cases()", dir.display())
        };
        check(&name, shine_scene::load(&path), expect);
        seen += 1;
    }
    assert_eq!(
        seen,
        cases.len(),
        "tests/broken is out of date; run SHINE_UPDATE_BROKEN=1 cargo test -p shine-scene --test broken_files"
    );
    for (name, bytes, _) in &cases {
        assert_eq!(
            &std::fs::read(dir.join(name)).unwrap(),
            bytes,
            "{name} differs from its generator; refresh tests/broken"
        );
    }
}

/// Deterministic corruptions: truncations at many lengths and random byte changes of valid
/// files. The loader may fail, but it must return. `SHINE_CORRUPTIONS=<n>` raises the number
/// of corruptions per input (default 400) for a longer soak.
#[test]
fn corrupted_builtins_never_panic() {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let rounds: usize = std::env::var("SHINE_CORRUPTIONS")
        .ok()
        .and_then(|n| n.parse().ok())
        .unwrap_or(400);
    let mut inputs = vec![
        shine_scene::builtin::build("cornell-box").unwrap(),
        common::triangle().to_glb(),
    ];
    inputs.push(common::triangle().to_gltf(None).0.into_bytes());
    inputs.push(common::animated_boxes(None).to_gltf(None).0.into_bytes());
    inputs.push(common::skinned_bar(|_| {}).to_gltf(None).0.into_bytes());
    if std::env::var_os("SHINE_CORRUPTIONS").is_some() {
        // Slow in debug builds (every surviving copy is fully processed): soak runs only.
        inputs.push(shine_scene::builtin::build("spheres").unwrap());
    }
    for input in &inputs {
        for k in 0..64 {
            let cut = input.len() * k / 64;
            let _ = shine_scene::load_slice(&input[..cut], None, "truncated");
        }
        for _ in 0..rounds {
            let mut bytes = input.clone();
            for _ in 0..1 + next() % 4 {
                let at = (next() as usize) % bytes.len();
                bytes[at] = next() as u8;
            }
            let _ = shine_scene::load_slice(&bytes, None, "mutated");
        }
        // Digit swaps keep the JSON well-formed but change indices, counts, offsets and
        // values, which reaches the checks behind the parser.
        let digits: Vec<usize> = input
            .iter()
            .enumerate()
            .filter(|(_, b)| b.is_ascii_digit())
            .map(|(i, _)| i)
            .collect();
        if digits.is_empty() {
            continue;
        }
        for _ in 0..rounds {
            let mut bytes = input.clone();
            for _ in 0..1 + next() % 3 {
                let at = digits[(next() as usize) % digits.len()];
                bytes[at] = b'0' + (next() % 10) as u8;
            }
            let _ = shine_scene::load_slice(&bytes, None, "mutated");
        }
    }
}
