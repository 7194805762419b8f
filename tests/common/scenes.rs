//! Small scenes built in code for the GPU tests: flat-shaded meshes, one material per part.

use glam::{Mat4, Vec3};
use shine_scene::environment::Environment;
use shine_scene::{Camera, Light, Material, Mesh, Node, Primitive, Projection, Scene, Transform};

/// A scene of one mesh whose primitives are `parts` (flat-shaded triangles, each part with its
/// material), a perspective camera (vertical field of view 1 rad) at `camera`, and `lights`.
pub fn mesh_scene(
    parts: &[(Vec<[Vec3; 3]>, Material)],
    camera: Mat4,
    lights: Vec<Light>,
    environment: Option<Environment>,
) -> Scene {
    let primitives = parts
        .iter()
        .enumerate()
        .map(|(k, (triangles, _))| {
            let mut primitive = Primitive {
                material: k as u32,
                ..Primitive::default()
            };
            for (i, t) in triangles.iter().enumerate() {
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                for v in t {
                    primitive.positions.push(*v);
                    primitive.normals.push(n);
                    primitive.bounds.grow(*v);
                }
                primitive
                    .indices
                    .extend([3 * i as u32, 3 * i as u32 + 1, 3 * i as u32 + 2]);
            }
            primitive
        })
        .collect();
    Scene {
        source: "test".into(),
        nodes: vec![Node {
            name: "mesh".into(),
            parent: None,
            children: vec![],
            transform: Transform::default(),
            mesh: Some(0),
            camera: None,
            lights: vec![],
            skin: None,
            weights: None,
        }],
        roots: vec![0],
        meshes: vec![Mesh {
            name: "mesh".into(),
            primitives,
            weights: vec![],
        }],
        materials: parts.iter().map(|(_, m)| *m).collect(),
        material_names: (0..parts.len()).map(|k| format!("material {k}")).collect(),
        lights,
        cameras: vec![Camera {
            name: "camera".into(),
            projection: Projection::Perspective {
                yfov: 1.0,
                aspect_ratio: None,
                znear: 0.01,
                zfar: None,
            },
            world: camera,
            node: None,
        }],
        environment,
        ..Scene::default()
    }
}

/// A UV sphere of radius `r` about `centre`: outward-facing (counter-clockwise seen from
/// outside) or inward-facing.
pub fn sphere(centre: Vec3, r: f32, outward: bool) -> Vec<[Vec3; 3]> {
    let (rings, segments) = (24, 48);
    let point = |i: u32, j: u32| {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * j as f32 / segments as f32;
        centre
            + r * Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            )
    };
    let mut out = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            let (a, b, c, d) = (
                point(i, j),
                point(i + 1, j),
                point(i + 1, j + 1),
                point(i, j + 1),
            );
            // (a, d, c) and (a, c, b) wind counter-clockwise seen from outside.
            let mut tris = vec![];
            if i > 0 {
                tris.push([a, d, c]);
            }
            if i + 1 < rings {
                tris.push([a, c, b]);
            }
            for t in tris {
                out.push(if outward { t } else { [t[0], t[2], t[1]] });
            }
        }
    }
    out
}

/// A square of side `2 s` in the plane y = `height`, facing +y.
pub fn floor(s: f32, height: f32) -> Vec<[Vec3; 3]> {
    let c = [
        Vec3::new(-s, height, -s),
        Vec3::new(-s, height, s),
        Vec3::new(s, height, s),
        Vec3::new(s, height, -s),
    ];
    vec![[c[0], c[1], c[2]], [c[0], c[2], c[3]]]
}

/// The camera ray through the centre of every pixel of a `size`×`size` frame of `scene` (as
/// the raster and the path tracer place them), row by row: origin and unit direction.
pub fn pixel_rays(device: &shine::gpu::Device, scene: &Scene, size: u32) -> Vec<(Vec3, Vec3)> {
    let gpu = shine::gpu_scene::GpuScene::upload(device, scene, 0.0).expect("upload");
    let inverse = shine::passes::gbuffer::camera_view(&gpu.state, size, size)
        .view_proj()
        .inverse();
    let mut rays = Vec::with_capacity((size * size) as usize);
    for y in 0..size {
        for x in 0..size {
            let unproject = |z: f32| {
                let p = inverse
                    * glam::Vec4::new(
                        (x as f32 + 0.5) / size as f32 * 2.0 - 1.0,
                        (y as f32 + 0.5) / size as f32 * 2.0 - 1.0,
                        z,
                        1.0,
                    );
                p.truncate() / p.w
            };
            let origin = unproject(0.0);
            rays.push((origin, (unproject(0.5) - origin).normalize()));
        }
    }
    rays
}

/// A rough, double-sided dielectric of grey `albedo` (roughness 1).
pub fn matte(albedo: f32) -> shine_scene::Material {
    shine_scene::Material {
        base_color: [albedo, albedo, albedo, 1.0],
        metallic: 0.0,
        roughness: 1.0,
        double_sided: 1,
        ..shine_scene::Material::default()
    }
}

/// The path tracer's parameters for a one-bounce `size`×`size` reference through pixel
/// centres (as the raster samples), punctual lights and the environment only, seeded `seed`.
pub fn pixel_centre_reference(size: u32, seed: u32) -> shine::reference::ReferenceParams {
    shine::reference::ReferenceParams {
        width: size,
        height: size,
        bounces: 1,
        jitter: false,
        emissive_lighting: false,
        lambert_only: false,
        light_sampling: true,
        seed,
        primary_specular: None,
    }
}

/// Rec. 709 luminance of `image` at `pixels` (`shine::capture::tonemap::luminance`).
pub fn luminance(image: &shine::capture::image_io::HdrImage, pixels: &[usize]) -> Vec<f64> {
    pixels
        .iter()
        .map(|&p| {
            let t = image.texels[p];
            f64::from(shine::capture::tonemap::luminance(glam::Vec3::new(
                t[0], t[1], t[2],
            )))
        })
        .collect()
}

/// Whether the ray `origin + t dir` (t > 0 at the sphere's nearest point; `dir` unit) passes
/// within `r` of `centre`.
pub fn ray_meets_sphere(origin: Vec3, dir: Vec3, centre: Vec3, r: f32) -> bool {
    let to_centre = centre - origin;
    let b = to_centre.dot(dir);
    b > 0.0 && to_centre.length_squared() - b * b < r * r
}

/// Settings of a `size`×`size` frame with the receivers at full resolution, then `pairs` set by
/// their TOML keys.
pub fn settings(size: u32, pairs: &[(&str, &str)]) -> shine::Settings {
    let mut s = shine::Settings {
        width: size,
        height: size,
        receiver_scale: 1,
        ..shine::Settings::default()
    };
    for (key, value) in pairs {
        s.set(key, value).expect("setting");
    }
    s
}

/// One frame of `scene` at time 0 on a new renderer with `settings`.
pub fn render_once(
    device: &shine::gpu::Device,
    scene: &Scene,
    settings: &shine::Settings,
) -> shine::capture::image_io::HdrImage {
    let mut renderer = shine::Renderer::new(device).expect("renderer");
    renderer.set_scene(scene, 0.0).expect("scene");
    renderer.render(settings).expect("render").hdr
}
