//! Environment lighting stored in a glTF file's root `extras`.
//!
//! glTF has no environment light, so shine reads one from the root object's extras:
//!
//! ```json
//! "extras": { "shine_environment": {
//!     "type": "sky",
//!     "zenith": [0.25, 0.45, 0.9], "horizon": [0.9, 0.9, 1.0], "ground": [0.3, 0.27, 0.22],
//!     "intensity": 1.0 } }
//! ```
//!
//! The sky is a distant radiance field over directions `d` (world space, +Y up), linear
//! Rec.709 RGB radiance in the same relative units as light intensities:
//! for `d.y >= 0`, `L(d) = intensity * mix(horizon, zenith, d.y^0.5)`;
//! for `d.y < 0`, `L(d) = intensity * mix(horizon, ground, (-d.y)^0.5)`.
//! It is smooth and low-frequency, which is what paper 002 lights with (projected to SH).

use glam::Vec3;
use serde_json::{Value, json};

/// The key in the root `extras` holding the environment.
pub const EXTRAS_KEY: &str = "shine_environment";

/// A procedural gradient sky (see the module documentation for the formula).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Environment {
    /// Radiance straight up.
    pub zenith: Vec3,
    /// Radiance at the horizon.
    pub horizon: Vec3,
    /// Radiance straight down.
    pub ground: Vec3,
    /// Multiplier on all three colours.
    pub intensity: f32,
}

impl Environment {
    /// Radiance arriving from direction `dir` (need not be normalised).
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        let d = dir.normalize_or(Vec3::Y);
        let c = if d.y >= 0.0 {
            self.horizon.lerp(self.zenith, d.y.sqrt())
        } else {
            self.horizon.lerp(self.ground, (-d.y).sqrt())
        };
        c * self.intensity
    }

    /// The JSON stored under [`EXTRAS_KEY`].
    pub fn to_json(&self) -> Value {
        json!({
            "type": "sky",
            "zenith": self.zenith.to_array(),
            "horizon": self.horizon.to_array(),
            "ground": self.ground.to_array(),
            "intensity": self.intensity,
        })
    }

    /// Parses the value stored under [`EXTRAS_KEY`]; the error says which field is wrong.
    pub fn from_json(v: &Value) -> Result<Environment, String> {
        match v.get("type").and_then(Value::as_str) {
            Some("sky") => {}
            Some(other) => {
                return Err(format!(
                    "unknown environment type {other:?} (expected \"sky\")"
                ));
            }
            None => return Err("missing \"type\": \"sky\"".to_string()),
        }
        let colour = |key: &str| -> Result<Vec3, String> {
            let a = v
                .get(key)
                .and_then(Value::as_array)
                .ok_or(format!("missing colour {key:?}"))?;
            let f: Vec<f32> = a
                .iter()
                .filter_map(Value::as_f64)
                .map(|x| x as f32)
                .collect();
            match f.as_slice() {
                [r, g, b] if f.iter().all(|x| x.is_finite() && *x >= 0.0) => {
                    Ok(Vec3::new(*r, *g, *b))
                }
                _ => Err(format!("{key:?} must be three finite non-negative numbers")),
            }
        };
        let intensity = match v.get("intensity") {
            None => 1.0,
            Some(x) => match x.as_f64() {
                Some(i) if i.is_finite() && i >= 0.0 => i as f32,
                _ => return Err("\"intensity\" must be a finite non-negative number".to_string()),
            },
        };
        Ok(Environment {
            zenith: colour("zenith")?,
            horizon: colour("horizon")?,
            ground: colour("ground")?,
            intensity,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_round_trip_and_gradient_ends() {
        let e = Environment {
            zenith: Vec3::new(0.1, 0.2, 0.9),
            horizon: Vec3::ONE,
            ground: Vec3::splat(0.3),
            intensity: 2.0,
        };
        assert_eq!(Environment::from_json(&e.to_json()), Ok(e));
        assert!((e.radiance(Vec3::Y) - e.zenith * 2.0).length() < 1e-6);
        assert!((e.radiance(Vec3::X) - e.horizon * 2.0).length() < 1e-6);
        assert!((e.radiance(-Vec3::Y) - e.ground * 2.0).length() < 1e-6);
        assert!(Environment::from_json(&json!({"type": "sky", "zenith": [1, 2]})).is_err());
    }
}
