//! Loading a scene of about one million triangles, and building its BVH.
//!
//! `cargo bench -p shine-scene --bench load`. The scene is 16 meshes of 65 536 triangles
//! (wavy 256×128-quad grids) with positions, normals, UVs and indices. Variants: tangents in
//! the file; no tangents and no normal map (cheap perpendicular tangents); no tangents under
//! a normal map (the loader runs MikkTSpace).

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use glam::{Vec2, Vec3};
use serde_json::json;
use shine_scene::builtin::shapes::MeshData;
use shine_scene::bvh::Bvh;
use shine_scene::glb_writer::GlbWriter;

fn grid(nx: u32, nz: u32, phase: f32) -> MeshData {
    let mut m = MeshData::default();
    for z in 0..=nz {
        for x in 0..=nx {
            let (u, v) = (x as f32 / nx as f32, z as f32 / nz as f32);
            let y = 0.1 * ((u * 20.0 + phase).sin() + (v * 13.0).cos());
            m.positions.push(Vec3::new(u * 4.0, y, v * 2.0));
            m.normals.push(
                Vec3::new(
                    -(u * 20.0 + phase).cos() * 0.5,
                    1.0,
                    (v * 13.0).sin() * 0.65,
                )
                .normalize(),
            );
            m.uvs.push(Vec2::new(u * 8.0, v * 4.0));
        }
    }
    for z in 0..nz {
        for x in 0..nx {
            let a = z * (nx + 1) + x;
            let b = a + nx + 1;
            m.indices.extend([a, b, a + 1, a + 1, b, b + 1]);
        }
    }
    m
}

/// The million-triangle scene; `normal_mapped` gives its material a (tiny) normal map, so
/// missing tangents are generated with MikkTSpace.
fn million_triangles(with_tangents: bool, normal_mapped: bool) -> Vec<u8> {
    let mut w = GlbWriter::new();
    let mut material = json!({"name": "grey"});
    if normal_mapped {
        let mut png = Vec::new();
        let encoder = image::codecs::png::PngEncoder::new(&mut png);
        image::ImageEncoder::write_image(
            encoder,
            &[128, 128, 255],
            1,
            1,
            image::ExtendedColorType::Rgb8,
        )
        .expect("1×1 PNG encodes");
        let tex = w.png_texture("flat", &png);
        material["normalTexture"] = json!({"index": tex});
    }
    let mat = w.push("materials", material);
    let mut roots = Vec::new();
    for i in 0..16 {
        let g = grid(256, 128, i as f32);
        let mesh = w.mesh_parts(&format!("grid{i}"), &[(&g, mat, with_tangents)]);
        let at = [(i % 4) as f32 * 4.5, 0.0, (i / 4) as f32 * 2.5];
        roots.push(w.push(
            "nodes",
            json!({"name": format!("grid{i}"), "mesh": mesh, "translation": at}),
        ));
    }
    w.scene("million", &roots);
    w.to_glb()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("1M triangles");
    group
        .sample_size(10)
        .measurement_time(Duration::from_secs(10))
        .warm_up_time(Duration::from_secs(1));
    for (name, tangents, normal_mapped) in [
        ("load, tangents in file", true, true),
        ("load, no normal map, no tangents", false, false),
        (
            "load, normal-mapped, MikkTSpace tangents generated",
            false,
            true,
        ),
    ] {
        let glb = million_triangles(tangents, normal_mapped);
        let scene =
            shine_scene::load_slice(&glb, None, "million.glb").expect("benchmark scene loads");
        assert_eq!(scene.triangle_count(), 16 * 256 * 128 * 2);
        group.bench_function(name, |b| {
            b.iter(|| shine_scene::load_slice(black_box(&glb), None, "million.glb"))
        });
    }
    let scene = shine_scene::load_slice(&million_triangles(true, false), None, "million.glb")
        .expect("loads");
    let world = scene.rest_world_transforms();
    group.bench_function("BVH build", |b| {
        b.iter(|| Bvh::from_scene(black_box(&scene), &world))
    });
    let mut bvh = Bvh::from_scene(&scene, &world);
    let moved: Vec<_> = world
        .iter()
        .map(|m| glam::Mat4::from_translation(Vec3::Y * 0.1) * *m)
        .collect();
    let poses = [moved, world.clone()];
    let mut k = 0;
    group.bench_function("BVH refit (all instances moved)", |b| {
        b.iter(|| {
            k ^= 1;
            bvh.refit(&scene, &poses[k]);
        })
    });
    let start = std::time::Instant::now();
    bvh.refit(&scene, &poses[k ^ 1]);
    println!(
        "one refit of {} triangles: {:?}",
        bvh.triangles.len(),
        start.elapsed()
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
