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

/// A skinned, morphing bar: a 1 m square tube from y = 0 to y = 2 with vertex
/// rings at y = 0, 1, 2, bound to two joints (`bone0` at the origin, `bone1` at y = 1) with
/// weights 1/0, ½/½ and 0/1 per ring, passed through `edit_weights` before writing. Two
/// morph targets: the top ring moves +X by 0.5 m (target 0) or +Z (target 1). The bar node
/// overrides the mesh weights with [0.25, 0]; the animation bends `bone1` 90° about Z over
/// 1 s (linear) and drives the weights (cubic spline).
pub fn skinned_bar(edit_weights: impl Fn(&mut Vec<glam::Vec4>)) -> GlbWriter {
    use glam::{Mat4, Quat, Vec4};
    use shine_scene::MorphTarget;
    use shine_scene::glb_writer::DeformingPrimitive;
    let mut w = GlbWriter::new();
    let mut bar = MeshData::default();
    let corners = [(-0.5, 0.5), (0.5, 0.5), (0.5, -0.5), (-0.5, -0.5)];
    for ring in 0..3 {
        for (x, z) in corners {
            let p = Vec3::new(x, ring as f32, z);
            bar.positions.push(p);
            bar.normals.push(Vec3::new(x, 0.0, z).normalize());
            bar.uvs.push(Vec2::new(x + 0.5, ring as f32 * 0.5));
        }
    }
    for ring in 0..2u32 {
        for side in 0..4u32 {
            let (a, b) = (ring * 4 + side, ring * 4 + (side + 1) % 4);
            bar.indices.extend([a, b, b + 4, a, b + 4, a + 4]);
        }
    }
    let joints: Vec<[u32; 4]> = (0..12).map(|_| [0, 1, 0, 0]).collect();
    let mut weights: Vec<Vec4> = (0..12)
        .map(|i| match i / 4 {
            0 => Vec4::new(1.0, 0.0, 0.0, 0.0),
            1 => Vec4::new(0.5, 0.5, 0.0, 0.0),
            _ => Vec4::new(0.0, 1.0, 0.0, 0.0),
        })
        .collect();
    edit_weights(&mut weights);
    let top = |d: Vec3| -> Vec<Vec3> {
        (0..12)
            .map(|i| if i >= 8 { d } else { Vec3::ZERO })
            .collect()
    };
    let targets = [
        MorphTarget {
            positions: top(Vec3::new(0.5, 0.0, 0.0)),
            normals: vec![Vec3::ZERO; 12],
        },
        MorphTarget {
            positions: top(Vec3::new(0.0, 0.0, 0.5)),
            normals: Vec::new(),
        },
    ];
    let mat = w.push("materials", json!({"name": "rubber"}));
    let mesh = w
        .deforming_mesh(
            "bar",
            &[DeformingPrimitive {
                geometry: &bar,
                material: mat,
                joints: &joints,
                weights: &weights,
                targets: &targets,
            }],
            &[0.0, 0.0],
        )
        .expect("joint indices fit");
    let bone1 = w.push(
        "nodes",
        json!({"name": "bone1", "translation": [0.0, 1.0, 0.0]}),
    );
    let bone0 = w.push("nodes", json!({"name": "bone0", "children": [bone1]}));
    let skin = w.skin(
        "bar skin",
        &[bone0, bone1],
        &[
            Mat4::IDENTITY,
            Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0)),
        ],
        Some(bone0),
    );
    let node = w.push(
        "nodes",
        json!({"name": "bar", "mesh": mesh, "skin": skin, "weights": [0.25, 0.0]}),
    );
    let bend = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    let (t_in, t_out) = w.keys(
        &[0.0, 1.0],
        &[0.0, 0.0, 0.0, 1.0, bend.x, bend.y, bend.z, bend.w],
        "VEC4",
    );
    // Cubic spline weights: (in, value, out) per key, two targets each.
    let (w_in, w_out) = w.keys(
        &[0.0, 1.0],
        &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.0],
        "SCALAR",
    );
    w.push(
        "animations",
        json!({"name": "bend", "samplers": [
                   {"input": t_in, "output": t_out},
                   {"input": w_in, "output": w_out, "interpolation": "CUBICSPLINE"}],
               "channels": [
                   {"sampler": 0, "target": {"node": bone1, "path": "rotation"}},
                   {"sampler": 1, "target": {"node": node, "path": "weights"}}]}),
    );
    w.scene("bar", &[bone0, node]);
    w
}
