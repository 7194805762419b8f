//! The loader on good input: the three container forms agree, defaults and warnings,
//! explicit proxies override the fit, generated attributes.

mod common;

use glam::Vec3;
use serde_json::json;
use shine_scene::proxies::{ProxySource, ProxySphere};
use shine_scene::{LightKind, Projection, Scene, load, load_slice};

fn temp_dir(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("shine-scene-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn same_geometry(a: &Scene, b: &Scene) {
    assert_eq!(a.meshes, b.meshes);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.nodes, b.nodes);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.textures, b.textures);
    assert_eq!(a.animations, b.animations);
}

#[test]
fn glb_gltf_with_bin_and_data_uri_load_the_same_scene() {
    let w = common::triangle();
    let dir = temp_dir("forms");
    let glb = dir.join("t.glb");
    std::fs::write(&glb, w.to_glb()).unwrap();
    let (json, bin) = w.to_gltf(Some("t data.bin"));
    std::fs::write(dir.join("t.gltf"), json).unwrap();
    std::fs::write(dir.join("t data.bin"), bin).unwrap();
    let (embedded, _) = w.to_gltf(None);
    std::fs::write(dir.join("embedded.gltf"), embedded).unwrap();

    let a = load(&glb).unwrap();
    let b = load(dir.join("t.gltf")).unwrap();
    let c = load(dir.join("embedded.gltf")).unwrap();
    same_geometry(&a, &b);
    same_geometry(&a, &c);
    assert!(
        std::fs::read_to_string(dir.join("embedded.gltf"))
            .unwrap()
            .contains("data:application/octet-stream;base64,")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn missing_camera_and_light_get_documented_defaults_with_warnings() {
    let s = load_slice(&common::triangle().to_glb(), None, "tri.glb").unwrap();
    assert_eq!(s.warnings.len(), 2, "{:?}", s.warnings);
    assert!(s.warnings.iter().all(|w| w.starts_with("tri.glb: ")));
    assert!(s.warnings.iter().any(|w| w.contains("no camera")));
    assert!(s.warnings.iter().any(|w| w.contains("no light")));
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].light_kind(), Some(LightKind::Directional));
    assert_eq!(s.lights[0].intensity, shine_scene::DEFAULT_SUN_LUX);
    // The default camera sees the whole quad: every corner projects inside the frustum.
    let cam = &s.cameras[0];
    let Projection::Perspective {
        yfov, znear, zfar, ..
    } = cam.projection
    else {
        panic!()
    };
    let view = cam.world.inverse();
    for corner in [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y] {
        let p = view.transform_point3(corner);
        assert!(-p.z > znear && -p.z < zfar.unwrap());
        assert!((p.y / -p.z).abs() <= (yfov * 0.5).tan() + 1e-6);
        assert!((p.x / -p.z).abs() <= (yfov * 0.5).tan() + 1e-6);
    }
}

#[test]
fn generated_normals_and_tangents_when_missing() {
    // A 2×2 flat normal map makes the material normal-mapped, so tangents follow MikkTSpace.
    let mut png = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut png),
        &[128, 128, 255].repeat(4),
        2,
        2,
        image::ExtendedColorType::Rgb8,
    )
    .unwrap();
    let mut w = common::triangle();
    let tex = w.png_texture("flat normal", &png);
    let mut j = common::gltf_json(&w);
    j["materials"][0]["normalTexture"] = json!({"index": tex});
    let attrs = j["meshes"][0]["primitives"][0]["attributes"]
        .as_object_mut()
        .unwrap();
    attrs.remove("NORMAL");
    let s = load_slice(j.to_string().as_bytes(), None, "no-normals.gltf").unwrap();
    assert!(
        s.warnings.iter().all(|w| !w.contains("images")),
        "{:?}",
        s.warnings
    );
    let p = &s.meshes[0].primitives[0];
    for (n, t) in p.normals.iter().zip(&p.tangents) {
        assert!((*n - Vec3::Z).length() < 1e-6, "{n:?}");
        assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t:?}");
        // u runs along +X and v down the image along -Y: bitangent = N × T · w = +Y.
        assert_eq!(t.w, 1.0);
    }
    // Without the normal map the tangents are only well-formed perpendiculars.
    j["materials"][0]
        .as_object_mut()
        .unwrap()
        .remove("normalTexture");
    let s = load_slice(j.to_string().as_bytes(), None, "no-normals.gltf").unwrap();
    let p = &s.meshes[0].primitives[0];
    for (n, t) in p.normals.iter().zip(&p.tangents) {
        assert!(n.dot(t.truncate()).abs() < 1e-6 && (t.truncate().length() - 1.0).abs() < 1e-6);
    }
}

#[test]
fn explicit_proxies_override_the_fit() {
    let explicit = vec![ProxySphere {
        center: [0.25, 0.0, 0.0],
        radius: 0.75,
    }];
    let with = common::animated_boxes(Some(shine_scene::proxies::to_json(&explicit)));
    let s = load_slice(&with.to_glb(), None, "boxes.glb").unwrap();
    assert_eq!(s.proxies.len(), 1, "only the animated node gets proxies");
    assert_eq!(s.proxies[0].source, ProxySource::Explicit);
    assert_eq!(s.proxies[0].spheres, explicit);

    let without = load_slice(&common::animated_boxes(None).to_glb(), None, "boxes.glb").unwrap();
    assert_eq!(without.proxies.len(), 1);
    let ProxySource::Fitted(cov) = without.proxies[0].source else {
        panic!("expected a fit")
    };
    assert_eq!(
        without.proxies[0].spheres.len(),
        shine_scene::proxies::DEFAULT_PROXY_COUNT
    );
    assert!(cov.uncovered < 0.01, "{cov:?}");
    assert_ne!(without.proxies[0].spheres, explicit);

    // Proxies follow the node: at t = 0.5 s the bar has slid 2 m along +X.
    let world = s.world_transforms_at(0.5);
    let p = s.proxies_at(&world);
    assert!(
        (Vec3::from(p[0].center) - Vec3::new(2.25, 0.0, 0.0)).length() < 1e-5,
        "{p:?}"
    );
    assert_eq!(p[0].radius, 0.75);
}

#[test]
fn lights_cameras_and_emissive_strength_are_read_in_their_units() {
    let mut j = common::gltf_json(&common::triangle());
    j["extensionsUsed"] = json!(["KHR_lights_punctual", "KHR_materials_emissive_strength"]);
    j["extensions"] = json!({"KHR_lights_punctual": {"lights": [
        {"type": "spot", "intensity": 250.0, "color": [1.0, 0.5, 0.25], "range": 12.0,
         "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.4}},
        {"type": "directional", "intensity": 3.5}]}});
    j["materials"][0]["emissiveFactor"] = json!([1.0, 0.5, 0.0]);
    j["materials"][0]["extensions"] =
        json!({"KHR_materials_emissive_strength": {"emissiveStrength": 8.0}});
    j["cameras"] = json!([{"type": "perspective", "perspective": {"yfov": 0.7, "znear": 0.1, "zfar": 30.0, "aspectRatio": 1.5}}]);
    let nodes = j["nodes"].as_array_mut().unwrap();
    nodes.push(json!({"name": "spot", "translation": [0.0, 3.0, 0.0], "rotation": [-std::f32::consts::FRAC_1_SQRT_2, 0.0, 0.0, std::f32::consts::FRAC_1_SQRT_2],
                      "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    nodes.push(json!({"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 1}}}));
    nodes.push(json!({"name": "cam", "camera": 0, "translation": [0.0, 1.0, 5.0]}));
    // A light on a node outside the displayed scene is not loaded.
    nodes.push(json!({"name": "stray", "extensions": {"KHR_lights_punctual": {"light": 0}}}));
    j["scenes"][0]["nodes"] = json!([0, 1, 2, 3]);
    let s = load_slice(j.to_string().as_bytes(), None, "lights.gltf").unwrap();
    assert!(s.warnings.is_empty(), "{:?}", s.warnings);
    assert_eq!(s.lights.len(), 2);
    let spot = s.lights[0];
    assert_eq!(spot.light_kind(), Some(LightKind::Spot));
    assert_eq!(
        (
            spot.intensity,
            spot.range,
            spot.inner_cone_angle,
            spot.outer_cone_angle
        ),
        (250.0, 12.0, 0.2, 0.4)
    );
    assert!((Vec3::from(spot.direction) - Vec3::NEG_Y).length() < 1e-5);
    assert_eq!(spot.position, [0.0, 3.0, 0.0]);
    assert_eq!(s.lights[1].light_kind(), Some(LightKind::Directional));
    assert_eq!(s.lights[1].direction, [0.0, 0.0, -1.0]);
    assert_eq!(s.materials[0].emissive, [8.0, 4.0, 0.0]);
    assert_eq!(s.cameras.len(), 1);
    assert_eq!(
        s.cameras[0].world.w_axis.truncate(),
        Vec3::new(0.0, 1.0, 5.0)
    );
}

fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for k in 0..4 {
            out.push(if k <= c.len() {
                A[((n >> (18 - 6 * k)) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    out
}

#[test]
fn sparse_accessors_substitute_their_values() {
    let mut j = common::gltf_json(&common::triangle());
    // Replace vertex 2 of POSITION with (5, 6, 7) through a sparse accessor.
    let mut data = vec![2u8, 0, 0, 0];
    for v in [5.0f32, 6.0, 7.0] {
        data.extend(v.to_le_bytes());
    }
    j["buffers"].as_array_mut().unwrap().push(
        json!({"byteLength": data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&data))}),
    );
    let views = j["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 1, "byteOffset": 0, "byteLength": 1}));
    views.push(json!({"buffer": 1, "byteOffset": 4, "byteLength": 12}));
    let (iv, vv) = (views.len() - 2, views.len() - 1);
    j["accessors"][0]["sparse"] = json!({"count": 1, "indices": {"bufferView": iv, "componentType": 5121},
                                         "values": {"bufferView": vv}});
    j["accessors"][0]["max"] = json!([5.0, 6.0, 7.0]);
    let s = load_slice(j.to_string().as_bytes(), None, "sparse.gltf").unwrap();
    let p = &s.meshes[0].primitives[0].positions;
    assert_eq!(p[2], Vec3::new(5.0, 6.0, 7.0));
    assert_eq!(p[1], Vec3::X);
}

#[test]
fn skins_morph_targets_and_weight_channels_round_trip() {
    use shine_scene::animation::{Interpolation, Property};
    let s = load_slice(&common::skinned_bar(|_| {}).to_glb(), None, "bar.glb").unwrap();
    assert!(
        s.warnings
            .iter()
            .all(|w| w.contains("no camera") || w.contains("no light")),
        "{:?}",
        s.warnings
    );
    let (bone1, bone0, bar) = (0, 1, 2);
    assert_eq!(s.skins.len(), 1);
    assert_eq!(s.skins[0].name, "bar skin");
    assert_eq!(s.skins[0].joints, vec![bone0, bone1]);
    assert_eq!(
        s.skins[0].inverse_bind,
        vec![
            glam::Mat4::IDENTITY,
            glam::Mat4::from_translation(Vec3::new(0.0, -1.0, 0.0))
        ]
    );
    assert_eq!(s.nodes[bar].skin, Some(0));
    assert_eq!(s.nodes[bar].weights, Some(vec![0.25, 0.0]));
    let mesh = &s.meshes[0];
    assert_eq!(mesh.weights, vec![0.0, 0.0]);
    let p = &mesh.primitives[0];
    assert_eq!(p.joints, vec![[0, 1, 0, 0]; 12]);
    assert_eq!(p.weights[4], glam::Vec4::new(0.5, 0.5, 0.0, 0.0));
    assert_eq!(p.targets.len(), 2);
    assert_eq!(p.targets[0].positions[8], Vec3::new(0.5, 0.0, 0.0));
    assert_eq!(p.targets[0].normals, vec![Vec3::ZERO; 12]);
    assert!(p.targets[1].normals.is_empty());
    let c = &s.animations[0].channels[1];
    assert_eq!(
        (c.node, c.property, c.interpolation, c.width),
        (bar, Property::Weights, Interpolation::CubicSpline, 2)
    );
    assert_eq!(c.values.len(), 12);
    assert_eq!(&c.values[9..10], &[0.5]);
    // The skinned instance ignores its node transform and is deforming; triangles count.
    let inst = s.instances(&s.rest_world_transforms())[0];
    assert_eq!(inst.skin, 0);
    assert_eq!(inst.world, glam::Mat4::IDENTITY.to_cols_array_2d());
    assert!(s.is_deforming(&inst));
    assert_eq!(s.triangle_count(), 16);

    // The .gltf form (data URI) loads the same data.
    let (text, _) = common::skinned_bar(|_| {}).to_gltf(None);
    let again = load_slice(text.as_bytes(), None, "bar.gltf").unwrap();
    assert_eq!(s.meshes, again.meshes);
    assert_eq!(s.skins, again.skins);
    assert_eq!(s.animations, again.animations);
}

#[test]
fn deformation_morphs_then_skins() {
    // Moving the skinned node must not move the mesh (glTF 2.0 §3.7.3).
    let mut j = common::gltf_json(&common::skinned_bar(|_| {}));
    j["nodes"][2]["translation"] = json!([10.0, 0.0, 0.0]);
    let s = load_slice(j.to_string().as_bytes(), None, "bar.gltf").unwrap();
    let base = s.meshes[0].primitives[0].positions.clone();
    let close = |a: Vec3, b: Vec3| (a - b).length() < 1e-5;

    // Rest: no bend, node weights [0.25, 0]: the top ring moves 0.125 m along +X.
    let rest = s.rest_pose();
    let inst = s.instances(&rest.world)[0];
    let v = s.instance_vertices(&rest, &inst, 0).unwrap();
    assert_eq!(v.positions.len(), 12);
    assert!(
        close(v.positions[8], Vec3::new(-0.5 + 0.125, 2.0, 0.5)),
        "{:?}",
        v.positions[8]
    );
    assert!(close(v.positions[0], Vec3::new(-0.5, 0.0, 0.5)));

    // t = 1: bone1 bent 90° about +Z at y = 1, weights (1, 0.5).
    let pose = s.pose_at(1.0);
    assert_eq!(pose.weights[2], vec![1.0, 0.5]);
    let v = s.instance_vertices(&pose, &inst, 0).unwrap();
    for (i, p) in v.positions.iter().enumerate() {
        let (x, z) = (base[i].x, base[i].z);
        let expect = match i / 4 {
            0 => Vec3::new(x, 0.0, z),
            // Half bone0 (unmoved), half bone1 ((x, 1, z) → (0, 1 + x, z)).
            1 => Vec3::new(x * 0.5, 1.0 + x * 0.5, z),
            // Morphed (x + 0.5, 2, z + 0.25), then rotated about (0, 1, 0).
            _ => Vec3::new(-1.0, 1.5 + x, z + 0.25),
        };
        assert!(close(*p, expect), "vertex {i}: {p} != {expect}");
    }
    for (n, t) in v.normals.iter().zip(&v.tangents) {
        assert!((n.length() - 1.0).abs() < 1e-5 && (t.truncate().length() - 1.0).abs() < 1e-5);
    }
    // Top ring normals turn with the bone: (x, 0, z) → (0, x, z) normalised.
    assert!(
        close(v.normals[8], Vec3::new(0.0, -0.5, 0.5).normalize()),
        "{}",
        v.normals[8]
    );
    let b = s.pose_bounds(&pose);
    assert!(close(b.min, Vec3::new(-1.0, 0.0, -0.5)), "{b:?}");
    assert!(close(b.max, Vec3::new(0.5, 2.0, 0.75)), "{b:?}");
    // bounds() at rest uses the deformed vertices too, not the node at x = 10.
    assert!(s.bounds(&rest.world).max.x < 1.0);
    // A host posing nodes itself gets the same result from the same inputs.
    let own = s.pose(s.world_transforms_at(1.0), s.weights_at(1.0));
    assert_eq!(own, pose);
}

#[test]
fn short_joints_and_normalized_byte_weights_are_read_and_renormalised() {
    let mut j = common::gltf_json(&common::skinned_bar(|_| {}));
    // JOINTS_0 as unsigned shorts, WEIGHTS_0 as normalized bytes that do not sum to 255.
    let mut data = Vec::new();
    for _ in 0..12 {
        for v in [0u16, 1, 0, 0] {
            data.extend(v.to_le_bytes());
        }
    }
    for ring in 0..3 {
        for _ in 0..4 {
            data.extend(match ring {
                0 => [200u8, 0, 0, 0],
                1 => [100, 100, 0, 0],
                _ => [0, 51, 0, 0],
            });
        }
    }
    j["buffers"].as_array_mut().unwrap().push(
        json!({"byteLength": data.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&data))}),
    );
    let views = j["bufferViews"].as_array_mut().unwrap();
    views.push(json!({"buffer": 1, "byteOffset": 0, "byteLength": 96}));
    views.push(json!({"buffer": 1, "byteOffset": 96, "byteLength": 48}));
    let (jv, wv) = (views.len() - 2, views.len() - 1);
    let accessors = j["accessors"].as_array_mut().unwrap();
    accessors.push(json!({"bufferView": jv, "componentType": 5123, "count": 12, "type": "VEC4"}));
    accessors.push(json!({"bufferView": wv, "componentType": 5121, "normalized": true, "count": 12, "type": "VEC4"}));
    let n = accessors.len();
    j["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = json!(n - 2);
    j["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = json!(n - 1);
    let s = load_slice(j.to_string().as_bytes(), None, "short.gltf").unwrap();
    let p = &s.meshes[0].primitives[0];
    assert_eq!(p.joints, vec![[0, 1, 0, 0]; 12]);
    assert_eq!(p.weights[0], glam::Vec4::new(1.0, 0.0, 0.0, 0.0));
    assert_eq!(p.weights[4], glam::Vec4::new(0.5, 0.5, 0.0, 0.0));
    assert_eq!(p.weights[8], glam::Vec4::new(0.0, 1.0, 0.0, 0.0));
}
