//! What changes between frames, as a host engine drives it ([`FrameUpdate`]), and the scene
//! it gives at one instant, evaluated on the CPU ([`FrameState`]): node world matrices,
//! lights, camera, bounds. The GPU side of an update (instance records, the top-level BVH,
//! deformed vertices) is made from a `FrameState` by [`crate::gpu_scene::GpuScene`].

use glam::{Mat4, Vec3};
use shine_scene::{Light, Pose, Projection, Scene, Transform};

/// The camera of a frame when the host places it itself.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraPose {
    /// Camera-to-world matrix (the camera looks along its local -Z, +Y up).
    pub world: Mat4,
    /// The projection.
    pub projection: Projection,
}

/// Everything a frame may change. Static data (meshes, materials, textures) is uploaded once
/// by [`crate::Renderer::set_scene`]; an update sends only this.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrameUpdate {
    /// Scene clock in seconds: every animation is evaluated at it (glTF clamping: before the
    /// first key the first value, after the last the last).
    pub time: f32,
    /// The camera; `None`: the scene's first camera (following its node's animation).
    pub camera: Option<CameraPose>,
    /// Local transforms the host sets, by node index, replacing the animated ones.
    pub nodes: Vec<(usize, Transform)>,
    /// Lights the host sets, by index into the scene's lights, in world space, replacing
    /// the animated ones.
    pub lights: Vec<(usize, Light)>,
    /// Morph weights the host sets, by node (one per target of its mesh), replacing the
    /// animated ones.
    pub weights: Vec<(usize, Vec<f32>)>,
    /// Sub-pixel offset of the camera's projection, in pixels (temporal anti-aliasing).
    pub jitter: [f32; 2],
}

impl FrameUpdate {
    /// The scene as animated at `time` seconds, with its own camera and lights.
    pub fn at(time: f32) -> Self {
        Self {
            time,
            ..Self::default()
        }
    }

    /// Refuses an update that names nodes or lights the scene does not have, or holds
    /// non-finite numbers.
    pub fn validate(&self, scene: &Scene) -> Result<(), String> {
        if !self.time.is_finite() {
            return Err(format!("frame time {} is not finite", self.time));
        }
        for (node, t) in &self.nodes {
            if *node >= scene.nodes.len() {
                return Err(format!(
                    "node {node} does not exist (the scene has {})",
                    scene.nodes.len()
                ));
            }
            let finite = t.translation.is_finite() && t.rotation.is_finite() && t.scale.is_finite();
            if !finite {
                return Err(format!("node {node}: the transform is not finite"));
            }
            if t.scale.x * t.scale.y * t.scale.z == 0.0 || t.rotation.length_squared() == 0.0 {
                return Err(format!(
                    "node {node}: a zero scale or rotation cannot be inverted (rays need it)"
                ));
            }
        }
        for (index, light) in &self.lights {
            if *index >= scene.lights.len() {
                return Err(format!(
                    "light {index} does not exist (the scene has {})",
                    scene.lights.len()
                ));
            }
            let values = light
                .position
                .iter()
                .chain(&light.direction)
                .chain(&light.color)
                .chain([&light.intensity, &light.range]);
            if values.into_iter().any(|v| !v.is_finite()) || light.light_kind().is_none() {
                return Err(format!("light {index}: not a finite light of a known kind"));
            }
            // The shadow atlas is laid out per light kind when the scene is set.
            if scene.lights[*index].kind != light.kind {
                return Err(format!(
                    "light {index}: its kind cannot change between frames (set a new scene)"
                ));
            }
            let directed = light.light_kind() != Some(shine_scene::LightKind::Point);
            if directed && glam::Vec3::from(light.direction).length_squared() == 0.0 {
                return Err(format!("light {index}: the direction is zero"));
            }
        }
        for (node, weights) in &self.weights {
            let targets = scene
                .nodes
                .get(*node)
                .and_then(|n| n.mesh)
                .and_then(|m| scene.meshes.get(m))
                .map(|m| m.target_count());
            match targets {
                None => return Err(format!("node {node} has no mesh to morph")),
                Some(n) if n != weights.len() => {
                    return Err(format!(
                        "node {node}: {} morph weights for {n} targets",
                        weights.len()
                    ));
                }
                Some(_) if weights.iter().any(|w| !w.is_finite()) => {
                    return Err(format!("node {node}: a morph weight is not finite"));
                }
                Some(_) => {}
            }
        }
        if let Some(camera) = &self.camera {
            if !camera.world.is_finite() || camera.world.determinant() == 0.0 {
                return Err("the camera matrix is not finite and invertible".into());
            }
            if !camera.projection.is_valid() {
                return Err(format!(
                    "the camera projection {:?} cannot be rendered (fov in (0, π), 0 < near < far)",
                    camera.projection
                ));
            }
        }
        if !self.jitter.iter().all(|j| j.is_finite()) {
            return Err("the jitter is not finite".into());
        }
        Ok(())
    }
}

/// The projection used when a scene has no camera (shine-scene adds one, so only for
/// hand-built scenes).
const FALLBACK_PROJECTION: Projection = Projection::Perspective {
    yfov: 0.8,
    aspect_ratio: None,
    znear: 0.05,
    zfar: None,
};

/// The scene at one instant, on the CPU.
#[derive(Clone, Debug, PartialEq)]
pub struct FrameState {
    /// The scene clock.
    pub time: f32,
    /// World matrix of every node, morph weights and joint matrices.
    pub pose: Pose,
    /// Lights in world space.
    pub lights: Vec<Light>,
    /// Camera-to-world matrix.
    pub camera_world: Mat4,
    /// Camera projection.
    pub projection: Projection,
    /// Sub-pixel jitter in pixels.
    pub jitter: [f32; 2],
    /// World bounds of the geometry (rigid instances' mesh boxes moved to the world,
    /// deforming ones' deformed vertices).
    pub bounds: (Vec3, Vec3),
}

impl FrameState {
    /// Evaluates `update` on `scene` (which it must have passed [`FrameUpdate::validate`]
    /// for).
    pub fn evaluate(scene: &Scene, update: &FrameUpdate) -> Self {
        let mut locals = scene.local_transforms_at(update.time);
        for (node, transform) in &update.nodes {
            if let Some(local) = locals.get_mut(*node) {
                *local = *transform;
            }
        }
        let matrices: Vec<Mat4> = locals.iter().map(Transform::matrix).collect();
        let world = scene.world_from_locals(&matrices);
        let mut lights = scene.lights_at(&world);
        for (index, light) in &update.lights {
            if let Some(slot) = lights.get_mut(*index) {
                *slot = *light;
            }
        }
        let (camera_world, projection) = match &update.camera {
            Some(c) => (c.world, c.projection),
            None => (
                scene.camera_world(0, &world).unwrap_or(Mat4::IDENTITY),
                scene
                    .cameras
                    .first()
                    .map_or(FALLBACK_PROJECTION, |c| c.projection),
            ),
        };
        let mut weights = scene.weights_at(update.time);
        for (node, w) in &update.weights {
            if let Some(slot) = weights.get_mut(*node) {
                slot.clone_from(w);
            }
        }
        let pose = scene.pose(world, weights);
        let bounds = scene.pose_bounds(&pose);
        Self {
            time: update.time,
            pose,
            lights,
            camera_world,
            projection,
            jitter: update.jitter,
            bounds: (bounds.min, bounds.max),
        }
    }
}
