//! Geometry and lights from the host's own buffers: the Cornell box registered from the
//! host's vertex and index buffers (one mesh per draw) with the scene's light list gives what
//! `set_scene` with the built-in gives, the instances and lights move per frame, and bad
//! input is refused with a clear error.

use super::gi_context::{Bench, EXTENT, error_of, exact_desc};
use shine::embed::{
    DispatchShape, GiContext, HostBuffer, HostInstance, HostMaterial, HostMesh, IndexFormat,
    MeshId, PositionFormat,
};

/// The identity as a 3×4 instance transform.
const IDENTITY: [[f32; 4]; 3] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
];

/// Bytes of one of the host's vertices: world position and normal, 6 floats.
const VERTEX_BYTES: u32 = 24;

/// The bench's whole flattened scene as one mesh of the host's buffers: every vertex (normals
/// at byte 12), every index, a default material.
fn whole_mesh(bench: &Bench) -> HostMesh {
    let flat = bench.scene.flatten_at(0.0);
    let host = bench.host_scene();
    HostMesh {
        vertices: HostBuffer {
            buffer: host.vertices.buffer,
            size: flat.vertices.len() as u64 * u64::from(VERTEX_BYTES),
            offset: 0,
        },
        vertex_stride: VERTEX_BYTES,
        vertex_count: flat.vertices.len() as u32,
        position_format: PositionFormat::Float3,
        normal_offset: Some(12),
        indices: HostBuffer {
            buffer: host.indices.buffer,
            size: flat.indices.len() as u64 * 4,
            offset: 0,
        },
        index_format: IndexFormat::U32,
        index_count: flat.indices.len() as u32,
        material: HostMaterial::default(),
        deformable: false,
    }
}

/// Every mesh of `ids` placed at `transform`.
fn placed(ids: &[MeshId], transform: [[f32; 4]; 3]) -> Vec<HostInstance> {
    ids.iter()
        .map(|&mesh| HostInstance { mesh, transform })
        .collect()
}

/// A context for the bench with the host's meshes registered (one per draw of its
/// flattened scene) and placed at the identity, lit by the scene's lights.
fn registered(bench: &Bench, desc: &shine::embed::GiContextDesc) -> (GiContext, Vec<MeshId>) {
    registered_with(bench, desc, None, IDENTITY)
}

/// As [`registered`], with draw `deformable` (if any) registered deformable and the first
/// instance placed at `first`.
fn registered_with(
    bench: &Bench,
    desc: &shine::embed::GiContextDesc,
    deformable: Option<usize>,
    first: [[f32; 4]; 3],
) -> (GiContext, Vec<MeshId>) {
    let flat = bench.scene.flatten_at(0.0);
    let mut gi = GiContext::new(bench.device(), desc).expect("context");
    let whole = whole_mesh(bench);
    let ids: Vec<MeshId> = flat
        .draws
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let material = d.material.map(|m| bench.scene.materials[m]);
            gi.register_mesh(&HostMesh {
                indices: HostBuffer {
                    offset: u64::from(d.first_index) * 4,
                    ..whole.indices
                },
                index_count: d.index_count,
                material: HostMaterial {
                    base_color: d.base_color,
                    roughness: d.roughness,
                    metallic: d.metallic,
                    emissive: material.map_or([0.0; 3], |m| m.emissive),
                    double_sided: material.is_some_and(|m| m.double_sided != 0),
                },
                deformable: deformable == Some(i),
                ..whole
            })
            .expect("register")
        })
        .collect();
    let mut instances = placed(&ids, IDENTITY);
    instances[0].transform = first;
    let lights = bench.scene.lights_at(&bench.scene.world_transforms_at(0.0));
    gi.set_instances(&instances, &lights).expect("instances");
    (gi, ids)
}

/// The Cornell box from the host's buffers and light list against `set_scene` with the
/// built-in: the same indirect light within 1e-3 relative RMSE (HVL, 3 frames).
#[test]
fn a_host_registered_cornell_box_matches_set_scene() {
    let bench = Bench::new(false);
    let desc = exact_desc(EXTENT, "hvl");
    let mut builtin = bench.context("hvl");
    builtin.warm_up(DispatchShape::default()).expect("warm up");
    let truth = (0..3)
        .map(|k| bench.run_still(&mut builtin, k))
        .last()
        .expect("frames");
    let (mut gi, _) = registered(&bench, &desc);
    gi.warm_up(DispatchShape::default()).expect("warm up");
    let output = (0..3)
        .map(|k| bench.run_still(&mut gi, k))
        .last()
        .expect("frames");
    let (relative_rmse, energy) = error_of(&output, &truth);
    println!("registered against built-in: relative RMSE {relative_rmse:.2e}, energy {energy:.6}");
    assert!(relative_rmse <= 1e-3, "relative RMSE {relative_rmse}");
    bench.assert_clean();
}

/// Moving the lamp by `move_instances` changes the light as the same move through the
/// built-in's light list does; a different instance list is refused there.
#[test]
fn registered_lights_move_per_frame_and_lists_are_checked() {
    let bench = Bench::new(false);
    let (mut gi, ids) = registered(&bench, &exact_desc(EXTENT, "hvl"));
    let mut lights = bench.scene.lights_at(&bench.scene.world_transforms_at(0.0));
    let still = bench.run_still(&mut gi, 0);
    lights[0].position[0] -= 0.1;
    let instances = placed(&ids, IDENTITY);
    gi.move_instances(&instances, &lights).expect("move");
    let moved = bench.run_still(&mut gi, 1);
    let (change, _) = error_of(&moved, &still);
    assert!(change > 0.01, "the light did not move: {change}");
    let error = gi
        .move_instances(&instances[1..], &lights)
        .expect_err("fewer instances")
        .to_string();
    assert!(error.contains("move_instances takes"), "{error}");
    bench.assert_clean();
}

/// A mesh whose stated vertex count overruns its buffer is refused before anything is read.
#[test]
fn a_buffer_too_small_for_its_count_is_refused() {
    let bench = Bench::new(false);
    let mut gi = GiContext::new(bench.device(), &exact_desc(EXTENT, "hvl")).expect("context");
    let error = gi
        .register_mesh(&HostMesh {
            vertex_count: whole_mesh(&bench).vertex_count + 1,
            normal_offset: None,
            index_count: 3,
            ..whole_mesh(&bench)
        })
        .expect_err("overrun")
        .to_string();
    println!("{error}");
    assert!(error.contains("vertex buffer holds"), "{error}");
    bench.assert_clean();
}

/// Indices past the stated vertex count are refused (read back, then checked).
#[test]
fn an_index_out_of_range_is_refused() {
    let bench = Bench::new(false);
    let mut gi = GiContext::new(bench.device(), &exact_desc(EXTENT, "hvl")).expect("context");
    let error = gi
        .register_mesh(&HostMesh {
            // Fewer vertices than the indices reach.
            vertex_count: 3,
            ..whole_mesh(&bench)
        })
        .expect_err("index out of range")
        .to_string();
    println!("{error}");
    assert!(error.contains("past the mesh's 3 vertices"), "{error}");
    bench.assert_clean();
}

/// NaN and sheared instance transforms are refused, at `set_instances` and per frame, and
/// the world set before stays.
#[test]
fn nan_and_sheared_transforms_are_refused() {
    let bench = Bench::new(false);
    let (mut gi, ids) = registered(&bench, &exact_desc(EXTENT, "hvl"));
    let lights = bench.scene.lights_at(&bench.scene.world_transforms_at(0.0));
    let mut nan = IDENTITY;
    nan[1][3] = f32::NAN;
    let mut shear = IDENTITY;
    shear[0][1] = 0.5;
    for (transform, expected) in [(nan, "not finite"), (shear, "shears")] {
        let instances = placed(&ids, transform);
        let error = gi
            .set_instances(&instances, &lights)
            .expect_err("refused")
            .to_string();
        assert!(error.contains(expected), "{error}");
        let error = gi
            .move_instances(&instances, &lights)
            .expect_err("refused")
            .to_string();
        assert!(error.contains(expected), "{error}");
    }
    // The world set before is still there and renders.
    let output = bench.run_still(&mut gi, 0);
    assert!(output.iter().flatten().any(|&v| v > 0.0));
    bench.assert_clean();
}

/// A deformable mesh given a new shape by `deform_mesh` (every vertex moved 0.1 along x)
/// lights the room as the same mesh registered rigid and placed 0.1 along x does: the
/// traced shadows of HVL and AAF's paths see the refitted hierarchy. Within 1e-3 relative
/// RMSE, and the shape changes the light.
#[test]
fn a_deformed_mesh_matches_the_same_shape_placed_rigidly() {
    const SHIFT: f32 = 0.1;
    let bench = Bench::new(false);
    let mut moved = IDENTITY;
    moved[0][3] = SHIFT;
    let vertices = bench.scene.flatten_at(0.0).vertices;
    let positions: Vec<[f32; 3]> = vertices
        .iter()
        .map(|v| [v[0] + SHIFT, v[1], v[2]])
        .collect();
    // A translation keeps the normals (what a skinning host would hand over with them).
    let normals: Vec<[f32; 3]> = vertices.iter().map(|v| [v[3], v[4], v[5]]).collect();
    for technique in ["hvl", "aaf"] {
        let desc = shine::embed::GiContextDesc::new(EXTENT, technique).expect("desc");
        let (mut rigid, _) = registered_with(&bench, &desc, None, moved);
        let (mut deformed, ids) = registered_with(&bench, &desc, Some(0), IDENTITY);
        let rest = bench.run_still(&mut deformed, 0);
        deformed
            .deform_mesh(ids[0], &positions, Some(&normals))
            .expect("deform");
        let truth = bench.run_still(&mut rigid, 1);
        deformed.reset_history();
        let output = bench.run_still(&mut deformed, 1);
        let (relative_rmse, energy) = error_of(&output, &truth);
        let (change, _) = error_of(&rest, &truth);
        println!(
            "{technique}: deformed against rigid {relative_rmse:.2e} (energy {energy:.5}); the \
             move changes {change:.4}"
        );
        assert!(relative_rmse <= 1e-3, "{technique}: {relative_rmse}");
        assert!(
            change >= 0.01,
            "{technique}: the shape changed nothing ({change})"
        );
    }
    bench.assert_clean();
}

/// A rigid mesh, a wrong vertex count, an infinite normal and a NaN position are refused by
/// `deform_mesh`.
#[test]
fn bad_deformations_are_refused() {
    let bench = Bench::new(false);
    let desc = exact_desc(EXTENT, "hvl");
    let (mut gi, ids) = registered_with(&bench, &desc, Some(0), IDENTITY);
    let count = whole_mesh(&bench).vertex_count as usize;
    let mut positions = vec![[0.0f32; 3]; count];
    let rigid = gi.deform_mesh(ids[1], &positions, None).expect_err("rigid");
    assert!(rigid.to_string().contains("registered rigid"), "{rigid}");
    let short = gi
        .deform_mesh(ids[0], &positions[1..], None)
        .expect_err("count");
    assert!(short.to_string().contains("vertices;"), "{short}");
    let mut normals = vec![[0.0f32, 1.0, 0.0]; count];
    normals[5][2] = f32::INFINITY;
    let bad_normal = gi
        .deform_mesh(ids[0], &positions, Some(&normals))
        .expect_err("infinite normal");
    assert!(
        bad_normal.to_string().contains("vertex 5 is not finite"),
        "{bad_normal}"
    );
    positions[7][1] = f32::NAN;
    let nan = gi.deform_mesh(ids[0], &positions, None).expect_err("NaN");
    assert!(nan.to_string().contains("vertex 7 is not finite"), "{nan}");
    bench.assert_clean();
}
