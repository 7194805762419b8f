//! Animation channels of a built-in scene, gathered into one glTF animation.

use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};

use crate::glb_writer::GlbWriter;

/// The samplers and channels of one animation, appended in call order.
#[derive(Default)]
pub(super) struct Tracks {
    samplers: Vec<Value>,
    channels: Vec<Value>,
}

impl Tracks {
    /// Adds a channel driving `path` of `node` with keys at `times` and flat `values`
    /// (VEC4 rotations, SCALAR weights with one float per morph target, VEC3 otherwise).
    pub(super) fn add(
        &mut self,
        w: &mut GlbWriter,
        node: usize,
        path: &str,
        interpolation: &str,
        times: &[f32],
        values: &[f32],
    ) {
        let kind = match path {
            "rotation" => "VEC4",
            "weights" => "SCALAR",
            _ => "VEC3",
        };
        let (input, output) = w.keys(times, values, kind);
        self.samplers
            .push(json!({"input": input, "output": output, "interpolation": interpolation}));
        self.channels.push(
            json!({"sampler": self.samplers.len() - 1, "target": {"node": node, "path": path}}),
        );
    }

    /// Writes the channels as the animation `name`.
    pub(super) fn write(self, w: &mut GlbWriter, name: &str) {
        w.push(
            "animations",
            json!({"name": name, "samplers": self.samplers, "channels": self.channels}),
        );
    }
}

/// A node rotation that points its -Z from `from` towards `to` (a camera's or a light's aim).
pub(super) fn aim(from: Vec3, to: Vec3) -> Quat {
    let look = Mat4::look_at_rh(from, to, Vec3::Y).inverse();
    let (_, rotation, _) = look.to_scale_rotation_translation();
    rotation.normalize()
}
