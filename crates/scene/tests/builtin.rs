//! Built-in scenes: they load back through the loader (round trip), hold what they promise,
//! and the committed `assets/<name>.glb` equal what the generator produces now.
//!
//! To refresh the assets after changing a generator:
//! `SHINE_UPDATE_ASSETS=1 cargo test -p shine-scene --test builtin`.

use std::path::PathBuf;

use shine_scene::proxies::ProxySource;
use shine_scene::{LightKind, NO_TEXTURE, Projection, Scene, builtin};

fn assets_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

#[test]
fn committed_assets_match_the_generators() {
    let update = std::env::var_os("SHINE_UPDATE_ASSETS").is_some();
    for name in builtin::names() {
        let path = assets_dir().join(format!("{name}.glb"));
        if update {
            builtin::export(name, &path).unwrap();
        }
        let glb = builtin::build(name).unwrap();
        let committed = std::fs::read(&path).unwrap_or_else(|e| {
            panic!(
                "{}: {e}; run SHINE_UPDATE_ASSETS=1 cargo test -p shine-scene --test builtin",
                path.display()
            )
        });
        assert!(
            committed == glb,
            "{} differs from what the generator produces now; run SHINE_UPDATE_ASSETS=1 cargo test -p shine-scene --test builtin",
            path.display()
        );
        assert!(
            glb.len() < 1024 * 1024,
            "{name}.glb is {} bytes; keep built-ins under 1 MiB",
            glb.len()
        );
    }
}

#[test]
fn builtins_load_without_warnings_and_are_deterministic() {
    for name in builtin::names() {
        let scene = Scene::builtin(name).unwrap();
        assert!(scene.warnings.is_empty(), "{name}: {:?}", scene.warnings);
        assert!(scene.triangle_count() > 0);
        assert_eq!(
            builtin::build(name).unwrap(),
            builtin::build(name).unwrap(),
            "{name} is not deterministic"
        );
        for m in &scene.meshes {
            for p in &m.primitives {
                assert!(p.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
                assert!(
                    p.tangents
                        .iter()
                        .all(|t| (t.truncate().length() - 1.0).abs() < 1e-3 && t.w.abs() == 1.0)
                );
            }
        }
    }
    assert!(
        builtin::build("no-such-scene")
            .unwrap_err()
            .to_string()
            .contains("cornell-box")
    );
}

#[test]
fn cornell_box_has_the_classic_layout() {
    let s = Scene::builtin("cornell-box").unwrap();
    let b = s.bounds(&s.rest_world_transforms());
    assert!(
        (b.extent().x - 0.556).abs() < 1e-3
            && (b.extent().y - 0.5488).abs() < 1e-3
            && (b.extent().z - 0.5592).abs() < 1e-3,
        "{b:?}"
    );
    assert_eq!(s.lights.len(), 1);
    let l = s.lights[0];
    assert_eq!(l.light_kind(), Some(LightKind::Spot));
    assert!(
        (glam::Vec3::from(l.direction) - glam::Vec3::NEG_Y).length() < 1e-5,
        "{l:?}"
    );
    assert!(l.position[1] > 0.54);
    // Red on the camera's left: the red wall is at -X, and the camera looks down -Z.
    let red = s.material_names.iter().position(|n| n == "red").unwrap() as u32;
    let walls = s.meshes.iter().find(|m| m.name == "walls").unwrap();
    let red_wall = walls.primitives.iter().find(|p| p.material == red).unwrap();
    assert!(red_wall.bounds.max.x < -0.27, "{:?}", red_wall.bounds);
    assert!(s.materials[red as usize].base_color[0] > 0.6);
    let lamp = s.material_names.iter().position(|n| n == "lamp").unwrap();
    assert_eq!(s.materials[lamp].emissive[0], 17.0);
    let Projection::Perspective { yfov, .. } = s.cameras[0].projection else {
        panic!("perspective camera expected")
    };
    assert!((yfov.to_degrees() - 39.3).abs() < 0.1);
}

#[test]
fn spheres_has_environment_animation_and_explicit_proxies() {
    let s = Scene::builtin("spheres").unwrap();
    assert!(s.environment.is_some());
    assert!(s.lights.is_empty(), "lit by the environment only");
    assert_eq!(s.animations.len(), 1);
    assert_eq!(s.animations[0].channels.len(), 4);
    assert_eq!(s.proxies.len(), 4);
    assert!(
        s.proxies
            .iter()
            .all(|p| p.source == ProxySource::Explicit && !p.spheres.is_empty())
    );
    // Proxies follow the animation: the ball's proxy is at the ball's centre at any time.
    let ball = s
        .nodes
        .iter()
        .position(|n| n.name == "bouncing ball")
        .unwrap();
    for t in [0.0, 0.25, 0.5, 1.3] {
        let world = s.world_transforms_at(t);
        let centre = world[ball].transform_point3(glam::Vec3::ZERO);
        let proxies = s.proxies_at(&world);
        assert!(
            proxies
                .iter()
                .any(|p| (glam::Vec3::from(p.center) - centre).length() < 1e-5
                    && (p.radius - 0.5).abs() < 1e-6)
        );
    }
    // Apex of the bounce at t = 0.5 s.
    assert!((s.world_transforms_at(0.5)[ball].w_axis.y - 1.8).abs() < 1e-5);
}

#[test]
fn marbles_has_many_proxies_a_sun_and_a_sky() {
    let s = Scene::builtin("marbles").unwrap();
    assert!(s.environment.is_some());
    assert_eq!(s.lights.len(), 1);
    assert_eq!(s.lights[0].light_kind(), Some(LightKind::Directional));
    let spheres: usize = s.proxies.iter().map(|p| p.spheres.len()).sum();
    assert!(spheres >= 64, "{spheres} proxies");
    assert!(s.proxies.iter().all(|p| p.source == ProxySource::Explicit));
    // every proxy bounds its ball at rest: centre on the ball's centre, radius its height
    for p in s.proxies_at(&s.world_transforms_at(0.0)) {
        assert!((p.center[1] - p.radius).abs() < 1e-5, "{p:?}");
    }
    assert!(
        s.materials
            .iter()
            .any(|m| m.metallic == 1.0 && m.roughness < 0.1)
    );
    assert_eq!(s.animations.len(), 1);
}

#[test]
fn room_has_textures_lights_and_glossy_materials() {
    let s = Scene::builtin("room").unwrap();
    assert_eq!(s.lights.len(), 2);
    let kinds: Vec<_> = s.lights.iter().map(|l| l.light_kind()).collect();
    assert!(kinds.contains(&Some(LightKind::Point)) && kinds.contains(&Some(LightKind::Spot)));
    let tiles = &s.materials[s.material_names.iter().position(|n| n == "tiles").unwrap()];
    assert_ne!(tiles.normal_texture, NO_TEXTURE);
    assert_ne!(tiles.metallic_roughness_texture, NO_TEXTURE);
    assert!(s.textures[tiles.base_color_texture as usize].srgb);
    assert!(!s.textures[tiles.normal_texture as usize].srgb);
    for t in &s.textures {
        assert_eq!(t.rgba8.len(), (t.width * t.height * 4) as usize);
    }
    assert!(
        s.materials
            .iter()
            .any(|m| m.metallic == 1.0 && m.roughness < 0.2)
    );
    assert!(s.material_names.len() >= 6);
}

#[test]
fn export_is_atomic_and_reports_bad_paths() {
    let dir = std::env::temp_dir().join(format!("shine-scene-export-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("box.glb");
    std::fs::write(&path, b"old contents").unwrap();
    builtin::export("cornell-box", &path).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        builtin::build("cornell-box").unwrap()
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.path() != path)
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    let err = builtin::export("cornell-box", dir.join("missing-dir/x.glb"))
        .unwrap_err()
        .to_string();
    assert!(err.contains("missing-dir"), "{err}");
    assert!(!dir.join("missing-dir").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn animated_walks_morphs_and_sweeps_for_300_frames() {
    let s = Scene::builtin("animated").unwrap();
    assert!(s.environment.is_some());
    assert!(s.triangle_count() <= 6000, "{}", s.triangle_count());
    assert_eq!(s.skins.len(), 1);
    assert_eq!(s.skins[0].joints.len(), 11);
    let duration = s.animations[0].duration();
    assert!(duration >= 300.0 / 24.0, "{duration}");
    let rest = s.rest_pose();
    let instances = s.instances(&rest.world);
    let walker = *instances.iter().find(|i| i.skin == 0).unwrap();
    let curtain = *instances
        .iter()
        .find(|i| s.nodes[i.node as usize].name == "curtain")
        .unwrap();
    assert!(s.is_deforming(&walker) && s.is_deforming(&curtain));
    assert_eq!(
        s.proxies
            .iter()
            .filter(|p| p.source == ProxySource::Explicit)
            .count(),
        11
    );
    let hips = s.skins[0].joints[0];
    let mut last: Option<shine_scene::Pose> = None;
    for frame in 0..300 {
        let t = frame as f32 / 24.0;
        let pose = s.pose_at(t);
        let body = s.instance_vertices(&pose, &walker, 0).unwrap();
        let (lo, hi) = body.positions.iter().fold(
            (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        // On the floor, about 1.7 m tall, inside the 5 m × 4 m room.
        assert!(lo.y > -0.06 && lo.y < 0.12, "t = {t}: feet at {}", lo.y);
        assert!(hi.y > 1.6 && hi.y < 1.8, "t = {t}: head at {}", hi.y);
        assert!(
            lo.x > -2.4 && hi.x < 2.2 && lo.z > -1.9 && hi.z < 1.9,
            "t = {t}: {lo} {hi}"
        );
        if let Some(prev) = &last {
            assert_ne!(
                prev.world[hips], pose.world[hips],
                "frame {frame} does not move"
            );
        }
        last = Some(pose);
    }
    // The curtain billows, the spot sweeps, proxies follow the bones.
    let (a, b) = (s.pose_at(0.0), s.pose_at(3.0));
    let c = s.nodes.iter().position(|n| n.name == "curtain").unwrap();
    assert_eq!(a.weights[c], vec![0.0, 0.0]);
    assert!(
        b.weights[c][0] > 0.1 && b.weights[c][1] > 0.1,
        "{:?}",
        b.weights[c]
    );
    let moved = |p: &[glam::Vec3], q: &[glam::Vec3]| {
        p.iter().zip(q).any(|(x, y)| (*x - *y).length() > 0.05)
    };
    let (ca, cb) = (
        s.instance_vertices(&a, &curtain, 0).unwrap(),
        s.instance_vertices(&b, &curtain, 0).unwrap(),
    );
    assert!(moved(&ca.positions, &cb.positions));
    let spot = |p: &shine_scene::Pose| {
        s.lights_at(&p.world)
            .into_iter()
            .find(|l| l.light_kind() == Some(LightKind::Spot))
            .unwrap()
            .direction
    };
    assert!((glam::Vec3::from(spot(&a)) - glam::Vec3::from(spot(&s.pose_at(4.0)))).length() > 0.3);
    let pa: Vec<_> = s
        .proxies_at(&a.world)
        .iter()
        .map(|p| glam::Vec3::from(p.center))
        .collect();
    let pb: Vec<_> = s
        .proxies_at(&b.world)
        .iter()
        .map(|p| glam::Vec3::from(p.center))
        .collect();
    assert!(moved(&pa, &pb));
    assert!(
        s.materials
            .iter()
            .any(|m| m.metallic == 1.0 && (m.roughness - 0.3).abs() < 1e-6)
    );
    assert!(
        s.materials
            .iter()
            .any(|m| m.metallic == 0.0 && m.roughness < 0.2)
    );
}

#[test]
fn metals_has_four_metal_spheres_two_lights_and_nothing_else() {
    let s = Scene::builtin("metals").unwrap();
    assert!(s.environment.is_none() && s.animations.is_empty());
    let kinds: Vec<_> = s.lights.iter().map(|l| l.light_kind()).collect();
    assert_eq!(kinds, [Some(LightKind::Spot), Some(LightKind::Point)]);
    assert!(s.materials.iter().all(|m| m.emissive == [0.0; 3]));
    for (name, roughness) in [
        ("chrome", 0.03),
        ("silver", 0.1),
        ("gold", 0.3),
        ("copper", 0.5),
    ] {
        let i = s.material_names.iter().position(|n| n == name).unwrap();
        let m = &s.materials[i];
        assert!(
            m.metallic == 1.0 && (m.roughness - roughness).abs() < 1e-6,
            "{name}"
        );
    }
    // The room is closed: 5 m × 2.8 m × 5 m.
    let b = s.bounds(&s.rest_world_transforms());
    assert!(
        (b.extent() - glam::Vec3::new(5.0, 2.8, 5.0)).length() < 1e-4,
        "{b:?}"
    );
    let Projection::Perspective { yfov, .. } = s.cameras[0].projection else {
        panic!("perspective camera expected")
    };
    assert!((0.85..=1.0).contains(&yfov), "{yfov}");
}
