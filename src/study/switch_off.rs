//! A light switched off in the middle of a temporal study (issue 43): the frames' updates
//! that turn it off, and how many frames a mode's sequence keeps its light.

use serde::Serialize;
use shine_scene::Scene;

use crate::capture::image_io::HdrImage;
use crate::gpu_scene::FrameUpdate;
use crate::gpu_scene::frame_update::FrameState;

/// What a sequence keeps of a light's indirect light after the light goes off, as a share of
/// what the light gave: "gone" below this (the 5%).
pub const GONE_BELOW: f64 = 0.05;

/// The light switched off and when.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct SwitchOff {
    /// Index of the light in the scene.
    pub light: usize,
    /// The first measured frame (0-based) without it: the middle one.
    pub frame: usize,
}

impl SwitchOff {
    /// Light `light` of `scene` off from the middle of `frames` measured frames; an error
    /// names the lights there are when the scene has no light `light`.
    pub fn new(scene: &Scene, light: usize, frames: usize) -> Result<Self, String> {
        if light >= scene.lights.len() {
            return Err(format!(
                "--switch-off {light}: the scene has {} light(s), numbered from 0",
                scene.lights.len()
            ));
        }
        Ok(Self {
            light,
            frame: frames / 2,
        })
    }

    /// The update of measured frame `k` at scene time `t`: the scene as animated, the light
    /// at zero intensity from [`SwitchOff::frame`] on.
    pub fn update(&self, scene: &Scene, k: usize, t: f32) -> FrameUpdate {
        let mut update = FrameUpdate::at(t);
        if k >= self.frame {
            let state = FrameState::evaluate(scene, &update);
            if let Some(light) = state.lights.get(self.light) {
                let mut off = *light;
                off.intensity = 0.0;
                update.lights.push((self.light, off));
            }
        }
        update
    }

    /// What a sequence keeps of the light at each frame from [`SwitchOff::frame`] on: the
    /// sequence's mean minus the cold frame's (which has no history) over what the light gave
    /// the cold frames (the fall of their mean across the switch). Signed means, so noise
    /// averages out.
    pub fn residual(&self, sequence: &[HdrImage], cold: &[HdrImage]) -> Vec<f64> {
        let mean = |f: &HdrImage| {
            f.texels
                .iter()
                .map(|t| f64::from(t[0] + t[1] + t[2]))
                .sum::<f64>()
                / f.texels.len().max(1) as f64
        };
        let (Some(before), Some(after)) = (
            self.frame.checked_sub(1).and_then(|k| cold.get(k)),
            cold.get(self.frame),
        ) else {
            return Vec::new();
        };
        let gave = (mean(before) - mean(after)).max(1e-12);
        sequence
            .iter()
            .zip(cold)
            .skip(self.frame)
            .map(|(s, c)| (mean(s) - mean(c)) / gave)
            .collect()
    }

    /// Frames until the light is gone (residual below [`GONE_BELOW`] from then on), counting
    /// the first frame without it as 1; `None` when it never goes.
    pub fn frames_until_gone(residual: &[f64]) -> Option<u32> {
        if residual.is_empty() {
            return None;
        }
        let last_kept = residual.iter().rposition(|r| *r >= GONE_BELOW);
        match last_kept {
            None => Some(1),
            Some(k) if k + 1 < residual.len() => Some(k as u32 + 2),
            Some(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_light_is_gone_once_its_residual_stays_below_five_percent() {
        assert_eq!(SwitchOff::frames_until_gone(&[0.01, 0.0, 0.02]), Some(1));
        assert_eq!(SwitchOff::frames_until_gone(&[0.5, 0.04, 0.01]), Some(2));
        assert_eq!(
            SwitchOff::frames_until_gone(&[0.5, 0.2, 0.06, 0.01]),
            Some(4)
        );
        assert_eq!(SwitchOff::frames_until_gone(&[0.5, 0.2, 0.06]), None);
        assert_eq!(SwitchOff::frames_until_gone(&[]), None);
    }
}
