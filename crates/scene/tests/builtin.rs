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
