//! Paper 001's tiny environment cubes (issue 18, item 3; src/passes/cubes.rs) against the path
//! tracer: a grey ball floating above a grey floor under a uniform sky, no punctual light, the
//! ball's proxy its own sphere. The ball's receivers take their light from its 6×6×6 cube
//! (`gi = none`, `cubes.enabled`): its top sees the sky, its bottom the sky-lit floor. On the
//! ball's pixels the frame must match the path tracer's energy and shading, for both lookups.
//! Amortised (`cubes.slices`), a still scene gives the per-frame image, and a light that
//! changes, or an object that moves, refreshes at once the cubes it shows in.

mod common;

use common::scenes::luminance;
use glam::{Mat4, Vec3};
use shine::Renderer;
use shine::capture::image_io::HdrImage;
use shine::reference::render_reference;
use shine_scene::Scene;
use shine_scene::environment::Environment;
use shine_scene::proxies::{NodeProxies, ProxySource, ProxySphere};

const SIZE: u32 = 32;
const BALL: Vec3 = Vec3::new(0.0, 1.0, 0.0);
const RADIUS: f32 = 0.6;

fn scene() -> Scene {
    let sky = Environment {
        zenith: Vec3::splat(1.0),
        horizon: Vec3::splat(1.0),
        ground: Vec3::splat(1.0),
        intensity: 1.0,
        map: None,
    };
    let camera = Mat4::look_at_rh(Vec3::new(0.0, 1.2, 2.2), BALL, Vec3::Y).inverse();
    let mut scene = common::scenes::mesh_scene(
        &[
            (common::scenes::floor(8.0, 0.0), common::scenes::matte(0.6)),
            (
                common::scenes::sphere(BALL, RADIUS, true),
                common::scenes::matte(0.5),
            ),
        ],
        camera,
        vec![],
        Some(sky),
    );
    scene.proxies.push(NodeProxies {
        node: 0,
        spheres: vec![ProxySphere {
            center: BALL.to_array(),
            radius: RADIUS,
        }],
        source: ProxySource::Explicit,
    });
    scene
}

fn frame(device: &shine::gpu::Device, scene: &Scene, settings: &[(&str, &str)]) -> HdrImage {
    let mut s = common::scenes::settings(SIZE, &[("gi", "none")]);
    for (key, value) in settings {
        s.set(key, value).expect("setting");
    }
    common::scenes::render_once(device, scene, &s)
}

/// The pixels whose centre ray meets a sphere 10% smaller than the ball (away from its rim).
fn ball_pixels(device: &shine::gpu::Device, scene: &Scene) -> Vec<usize> {
    let r = 0.9 * RADIUS;
    common::scenes::pixel_rays(device, scene, SIZE)
        .iter()
        .enumerate()
        .filter(|(_, (o, d))| common::scenes::ray_meets_sphere(*o, *d, BALL, r))
        .map(|(p, _)| p)
        .collect()
}

/// On the ball: energy within 6% of the path tracer's (the cube leaves out the ball's glossy
/// reflection, a few percent) and relative RMSE below 0.1, for the paper's texel lookup with
/// its plain smoothing and for the default (the sum at the normal, solid-angle weights). The
/// mask view lights exactly the ball's pixels.
#[test]
fn the_cube_lights_the_ball_as_the_path_tracer_does() {
    let device = common::device();
    let scene = scene();
    let pixels = ball_pixels(&device, &scene);
    assert!(pixels.len() > 100, "{} ball pixels", pixels.len());
    let params = common::scenes::pixel_centre_reference(SIZE, 3);
    let truth = render_reference(&device, &scene, 0.0, &params, 1024).expect("reference");
    let truth = luminance(&truth.full, &pixels);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    for (label, settings) in [
        (
            "paper (texel lookup, plain sum)",
            &[
                ("cubes.enabled", "true"),
                ("cubes.lookup", "texel"),
                ("cubes.solid_angle", "false"),
            ][..],
        ),
        (
            "default (sum at the normal)",
            &[("cubes.enabled", "true")][..],
        ),
    ] {
        let lit = luminance(&frame(&device, &scene, settings), &pixels);
        let energy = mean(&lit) / mean(&truth);
        let error = (truth
            .iter()
            .zip(&lit)
            .map(|(t, l)| (l - t).powi(2))
            .sum::<f64>()
            / truth.len() as f64)
            .sqrt()
            / mean(&truth);
        println!("{label}: energy {energy:.4}, relative RMSE {error:.4}");
        assert!((energy - 1.0).abs() < 0.06, "{label}: energy {energy}");
        assert!(error < 0.1, "{label}: relative RMSE {error}");
    }
    let mask = frame(
        &device,
        &scene,
        &[
            ("cubes.enabled", "true"),
            ("cubes.mask", "true"),
            ("output.component", "indirect"),
        ],
    );
    assert!(pixels.iter().all(|&p| mask.texels[p][1] == 1.0));
    let lit = mask.texels.iter().filter(|t| t[1] > 0.0).count();
    assert!(lit < pixels.len() * 3 / 2, "{lit} mask pixels");
    common::assert_clean(&device);
}

/// Renders `frames` frames of `scene` on one renderer with `settings` (gi = none, sky pass
/// off: its rays would differ from frame to frame), the update of frame k from `update(k)`;
/// returns the last frame.
fn sequence(
    device: &shine::gpu::Device,
    scene: &Scene,
    settings: &[(&str, &str)],
    frames: u32,
    update: impl Fn(u32) -> shine::gpu_scene::FrameUpdate,
) -> HdrImage {
    let mut s = common::scenes::settings(
        SIZE,
        &[
            ("gi", "none"),
            ("sky.enabled", "false"),
            ("cubes.enabled", "true"),
        ],
    );
    for (key, value) in settings {
        s.set(key, value).expect("setting");
    }
    let mut renderer = Renderer::new(device).expect("renderer");
    renderer.set_scene(scene, 0.0).expect("scene");
    let mut last = None;
    for k in 0..frames {
        renderer.update(&update(k)).expect("update");
        last = Some(renderer.render(&s).expect("render").hdr);
    }
    last.expect("a frame")
}

/// A cube's slice comes round every 16 frames, no history blends the frames, and the frame
/// shows the indirect light alone (on the balls: the cubes').
const RARE_SLICES: [(&str, &str); 3] = [
    ("cubes.slices", "16"),
    ("history.frames", "1"),
    ("output.component", "indirect"),
];

/// The largest difference on the ball's pixels relative to the mean there.
fn difference(a: &HdrImage, b: &HdrImage, pixels: &[usize]) -> f64 {
    let (la, lb) = (luminance(a, pixels), luminance(b, pixels));
    let mean = lb.iter().sum::<f64>() / lb.len() as f64;
    la.iter()
        .zip(&lb)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
        / mean
}

/// A still scene amortised over 4 slices gives, after 6 frames, the image every cube refreshed
/// every frame gives (to float rounding); with a sun that turns at frame 3, slices = 16 (the one
/// cube's slice comes round every 16 frames) still shows the turned sun's floor at once, as a
/// fresh render at that sun does, because a light that changes refreshes every cube. The
/// ball's indirect light under the old sun differs from the new one's by far more.
#[test]
fn amortised_cubes_converge_and_refresh_when_a_light_moves() {
    let device = common::device();
    let mut scene = scene();
    let pixels = ball_pixels(&device, &scene);
    let still = |_| shine::gpu_scene::FrameUpdate::at(0.0);
    let every = sequence(&device, &scene, &[], 1, still);
    let sliced = sequence(&device, &scene, &[("cubes.slices", "4")], 6, still);
    let converged = difference(&sliced, &every, &pixels);
    assert!(converged < 1e-3, "amortised differs by {converged}");

    let sun = |direction: Vec3| shine_scene::Light {
        position: [0.0; 3],
        kind: 0,
        direction: direction.normalize().to_array(),
        range: 0.0,
        color: [1.0; 3],
        intensity: 3.0,
        inner_cone_angle: 0.0,
        outer_cone_angle: 0.0,
        node: u32::MAX,
        _pad: 0,
    };
    let (before, after) = (
        sun(Vec3::new(0.3, -1.0, -0.4)),
        sun(Vec3::new(-0.8, -0.5, 0.6)),
    );
    scene.lights.push(before);
    let turning = |k: u32| shine::gpu_scene::FrameUpdate {
        lights: vec![(0, if k < 3 { before } else { after })],
        ..shine::gpu_scene::FrameUpdate::at(0.0)
    };
    let turned = sequence(&device, &scene, &RARE_SLICES, 4, turning);
    let fresh = sequence(&device, &scene, &RARE_SLICES, 1, |_| turning(3));
    let stale = sequence(&device, &scene, &RARE_SLICES, 1, |_| turning(0));
    let refreshed = difference(&turned, &fresh, &pixels);
    let changed = difference(&stale, &fresh, &pixels);
    println!(
        "after the sun turned: {refreshed:.2e} from a fresh render (the old sun: {changed:.3})"
    );
    assert!(refreshed < 1e-3, "{refreshed}");
    assert!(
        changed > 0.05,
        "the sun's turn changes the ball by {changed} only"
    );
    common::assert_clean(&device);
}

/// A second ball (its own node and cube) beside the first, 0.4 m across from it: `r/d` = 0.29
/// in the first ball's cube.
const SECOND: Vec3 = Vec3::new(1.4, 1.0, 0.0);
const SECOND_RADIUS: f32 = 0.4;

/// The ball scene with a second ball on a node of its own, with its proxy.
fn two_balls() -> Scene {
    let mut scene = scene();
    let second = common::scenes::mesh_scene(
        &[(
            common::scenes::sphere(Vec3::ZERO, SECOND_RADIUS, true),
            common::scenes::matte(0.5),
        )],
        Mat4::IDENTITY,
        vec![],
        None,
    );
    scene.meshes.push(second.meshes[0].clone());
    let mut node = second.nodes[0].clone();
    node.mesh = Some(1);
    node.transform.translation = SECOND;
    scene.nodes.push(node);
    scene.roots.push(1);
    scene.proxies.push(NodeProxies {
        node: 1,
        spheres: vec![ProxySphere {
            center: [0.0; 3],
            radius: SECOND_RADIUS,
        }],
        source: ProxySource::Explicit,
    });
    scene
}

/// Two cubes, `cubes.slices = 16`, the second ball lifted by 0.5 m at frame 3 (neither cube's
/// slice comes round then): the lifted ball's cube refreshes because its object moved, the
/// first ball's because the mover shows in it, and frame 3 equals a fresh render of the
/// lifted scene on both balls (indirect light only). A cube left stale would show the floor
/// from where the ball was.
#[test]
fn a_moving_object_refreshes_its_cube_and_its_neighbours() {
    let device = common::device();
    let scene = two_balls();
    let lift = |k: u32| shine::gpu_scene::FrameUpdate {
        nodes: if k >= 3 {
            vec![(
                1,
                shine_scene::Transform {
                    translation: SECOND + Vec3::new(0.0, 0.5, 0.0),
                    ..shine_scene::Transform::default()
                },
            )]
        } else {
            vec![]
        },
        ..shine::gpu_scene::FrameUpdate::at(0.0)
    };
    let moved = sequence(&device, &scene, &RARE_SLICES, 4, lift);
    let fresh = sequence(&device, &scene, &RARE_SLICES, 1, |_| lift(3));
    let still = sequence(&device, &scene, &RARE_SLICES, 1, |_| lift(0));
    // the first ball's pixels, and the pixels the cubes light in the lifted frame
    let first = ball_pixels(&device, &scene);
    let lit: Vec<usize> = (0..fresh.texels.len())
        .filter(|&p| fresh.texels[p][1] > 0.0 && !first.contains(&p))
        .collect();
    let mask = sequence(
        &device,
        &scene,
        &[("cubes.mask", "true"), ("output.component", "indirect")],
        1,
        |_| lift(3),
    );
    let second: Vec<usize> = lit
        .into_iter()
        .filter(|&p| mask.texels[p][1] == 1.0)
        .collect();
    assert!(
        second.len() > 20,
        "{} pixels of the second ball",
        second.len()
    );
    for (name, pixels) in [("first", &first), ("second", &second)] {
        let refreshed = difference(&moved, &fresh, pixels);
        println!("{name} ball: {refreshed:.2e} from a fresh render");
        assert!(refreshed < 1e-3, "{name}: {refreshed}");
    }
    let changed = difference(&still, &fresh, &first);
    println!("the first ball's light, before and after the lift: {changed:.4}");
    assert!(
        changed > 1e-3,
        "the lift changes the first ball by {changed} only"
    );
    common::assert_clean(&device);
}
