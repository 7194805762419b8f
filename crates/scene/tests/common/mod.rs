//! Small glTF files for the loader tests, built with the crate's own writer.

use glam::{Vec2, Vec3};
use serde_json::{Value, json};
use shine_scene::builtin::shapes::{self, MeshData};
use shine_scene::glb_writer::GlbWriter;

/// One triangle with a material, in a scene, nothing else.
pub fn triangle() -> GlbWriter {
    let mut w = GlbWriter::new();
    let mut m = MeshData::default();
    m.quad(
        [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        Vec2::ONE,
    );
    let mat = w.push(
        "materials",
        json!({"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0]}}),
    );
    let mesh = w.mesh("quad", &[(&m, mat)]);
    let node = w.push("nodes", json!({"name": "quad", "mesh": mesh}));
    w.scene("test", &[node]);
    w
}

/// An animated box with explicit proxies (when `proxies` is given) and a static box.
pub fn animated_boxes(proxies: Option<Value>) -> GlbWriter {
    let mut w = GlbWriter::new();
    let cube = shapes::cuboid(Vec3::new(2.0, 0.5, 0.5));
    let mat = w.push("materials", json!({"name": "white"}));
    let mesh = w.mesh("bar", &[(&cube, mat)]);
    let mut moving = json!({"name": "moving", "mesh": mesh});
    if let Some(p) = proxies {
        moving["extras"] = json!({"shine_proxies": p});
    }
    let moving = w.push("nodes", moving);
    let fixed = w.push(
        "nodes",
        json!({"name": "fixed", "mesh": mesh, "translation": [0.0, 0.0, -3.0]}),
    );
    let (input, output) = w.keys(&[0.0, 1.0], &[0.0, 0.0, 0.0, 4.0, 0.0, 0.0], "VEC3");
    w.push(
        "animations",
        json!({"name": "slide", "samplers": [{"input": input, "output": output}],
               "channels": [{"sampler": 0, "target": {"node": moving, "path": "translation"}}]}),
    );
    w.scene("boxes", &[moving, fixed]);
    w
}

/// Parses a writer's `.gltf` JSON (buffer embedded as a data URI) for editing.
pub fn gltf_json(w: &GlbWriter) -> Value {
    serde_json::from_str(&w.to_gltf(None).0).expect("writer output is JSON")
}
