//! The BVH over a whole scene: closest hits agree with brute force over the scene's
//! world-space triangles, before and after refitting to an animated pose.

use glam::{Mat4, Vec3};
use shine_scene::Scene;
use shine_scene::bvh::{Bvh, Ray, intersect_triangle};

/// World-space triangles computed independently of the BVH.
fn world_triangles(scene: &Scene, world: &[Mat4]) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for inst in scene.instances(world) {
        let m = Mat4::from_cols_array_2d(&inst.world);
        for p in &scene.meshes[inst.mesh as usize].primitives {
            for t in p.indices.chunks_exact(3) {
                out.push([0, 1, 2].map(|k| m.transform_point3(p.positions[t[k] as usize])));
            }
        }
    }
    out
}

fn check(bvh: &Bvh, tris: &[[Vec3; 3]], seed: u64) -> usize {
    let mut s = seed;
    let mut f = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 40) as f32 / (1u64 << 24) as f32
    };
    let mut hits = 0;
    for _ in 0..300 {
        let origin = Vec3::new(f() * 8.0 - 4.0, f() * 3.0, f() * 8.0 - 4.0);
        let target = Vec3::new(f() * 4.0 - 2.0, f() * 1.5, f() * 4.0 - 2.0);
        let ray = Ray {
            origin,
            dir: target - origin,
            t_min: 1e-4,
            t_max: f32::INFINITY,
        };
        let brute = tris
            .iter()
            .filter_map(|t| intersect_triangle(&ray, *t).map(|h| h.0))
            .fold(f32::INFINITY, f32::min);
        match bvh.intersect(&ray) {
            Some(h) => {
                hits += 1;
                assert!(
                    (h.t - brute).abs() <= 1e-4 * brute.max(1.0),
                    "bvh {} brute {brute}",
                    h.t
                );
            }
            None => assert!(brute.is_infinite(), "bvh missed a hit at {brute}"),
        }
    }
    hits
}

#[test]
fn scene_bvh_matches_brute_force_before_and_after_refit() {
    let scene = Scene::builtin("spheres").unwrap();
    let rest = scene.rest_world_transforms();
    let mut bvh = Bvh::from_scene(&scene, &rest);
    assert_eq!(bvh.triangles.len(), scene.triangle_count());
    assert!(check(&bvh, &world_triangles(&scene, &rest), 0x1111_2222_3333_4444) > 100);

    let later = scene.world_transforms_at(0.7);
    assert_ne!(later, rest);
    bvh.refit(&scene, &later);
    assert!(
        check(
            &bvh,
            &world_triangles(&scene, &later),
            0x5555_6666_7777_8888
        ) > 100
    );
    // The refitted tree holds exactly the triangles of a fresh build at that pose.
    let fresh = Bvh::from_scene(&scene, &later);
    let key = |t: &shine_scene::bvh::BvhTriangle| (t.instance, t.primitive, t.triangle);
    let mut a: Vec<_> = bvh
        .triangles
        .iter()
        .map(|t| (key(t), t.v0, t.v1, t.v2))
        .collect();
    let mut b: Vec<_> = fresh
        .triangles
        .iter()
        .map(|t| (key(t), t.v0, t.v1, t.v2))
        .collect();
    a.sort_by_key(|x| x.0);
    b.sort_by_key(|x| x.0);
    assert_eq!(a, b);
}
