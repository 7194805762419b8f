//! Node animations (glTF translation / rotation / scale channels) evaluated at any time.
//!
//! Sampling follows glTF 2.0 §3.11: before the first key the first value holds, after the last
//! key the last value holds (no looping: wrap `t` yourself with [`Animation::duration`]);
//! `STEP` holds the previous key, `LINEAR` lerps (rotations slerp along the shortest arc) and
//! `CUBICSPLINE` evaluates the Hermite spline from the in/out tangents. Rotations are
//! renormalised. Morph-target weights are not animated (the loader warns about them).

use glam::{Quat, Vec4};

use crate::types::Transform;

/// Which part of a node's transform a channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    /// Translation (xyz).
    Translation,
    /// Rotation (unit quaternion xyzw).
    Rotation,
    /// Scale (xyz).
    Scale,
}

/// How values between keys are computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// Hold the previous key's value.
    Step,
    /// Linear (rotations: spherical linear).
    Linear,
    /// Cubic Hermite spline with per-key in and out tangents.
    CubicSpline,
}

/// One animated property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Target node index.
    pub node: usize,
    /// Target property.
    pub property: Property,
    /// Interpolation between keys.
    pub interpolation: Interpolation,
    /// Key times in seconds, strictly increasing, at least one.
    pub times: Vec<f32>,
    /// Key values (xyz in `xyz` for translation and scale, xyzw for rotation). For
    /// `CubicSpline`, three per key: in-tangent, value, out-tangent.
    pub values: Vec<Vec4>,
}

impl Channel {
    /// The channel's value at time `t` (seconds).
    pub fn sample(&self, t: f32) -> Vec4 {
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let value = |k: usize| -> Vec4 {
            let i = if cubic { 3 * k + 1 } else { k };
            self.values.get(i).copied().unwrap_or(Vec4::ZERO)
        };
        let n = self.times.len();
        let (Some(&first), Some(&last)) = (self.times.first(), self.times.last()) else {
            return Vec4::ZERO;
        };
        if n == 1 || t.is_nan() || t <= first {
            return value(0);
        }
        if t >= last {
            return value(n - 1);
        }
        // times[k] <= t < times[k + 1]
        let k = self
            .times
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .min(n - 2);
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let dt = t1 - t0;
        let s = if dt > 0.0 {
            ((t - t0) / dt).clamp(0.0, 1.0)
        } else {
            0.0
        };
        match self.interpolation {
            Interpolation::Step => value(k),
            Interpolation::Linear => {
                let (a, b) = (value(k), value(k + 1));
                if self.property == Property::Rotation {
                    Vec4::from(
                        Quat::from_vec4(a)
                            .normalize()
                            .slerp(Quat::from_vec4(b).normalize(), s),
                    )
                } else {
                    a.lerp(b, s)
                }
            }
            Interpolation::CubicSpline => {
                let get = |i: usize| self.values.get(i).copied().unwrap_or(Vec4::ZERO);
                let (p0, m0) = (get(3 * k + 1), get(3 * k + 2) * dt);
                let (p1, m1) = (get(3 * (k + 1) + 1), get(3 * (k + 1)) * dt);
                let (s2, s3) = (s * s, s * s * s);
                p0 * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + m0 * (s3 - 2.0 * s2 + s)
                    + p1 * (-2.0 * s3 + 3.0 * s2)
                    + m1 * (s3 - s2)
            }
        }
    }
}

/// A named set of channels played together.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// The glTF name, or `animation<i>`.
    pub name: String,
    /// The channels.
    pub channels: Vec<Channel>,
}

impl Animation {
    /// Time of the last key over all channels, in seconds.
    pub fn duration(&self) -> f32 {
        self.channels
            .iter()
            .filter_map(|c| c.times.last().copied())
            .fold(0.0, f32::max)
    }

    /// Overwrites the animated properties of `locals` with their values at time `t`.
    pub fn apply(&self, t: f32, locals: &mut [Transform]) {
        for c in &self.channels {
            let Some(local) = locals.get_mut(c.node) else {
                continue;
            };
            let v = c.sample(t);
            match c.property {
                Property::Translation => local.translation = v.truncate(),
                Property::Scale => local.scale = v.truncate(),
                Property::Rotation => {
                    let q = Quat::from_vec4(v);
                    local.rotation = if q.length_squared() > 0.0 {
                        q.normalize()
                    } else {
                        Quat::IDENTITY
                    };
                }
            }
        }
    }

    /// Whether a channel of this animation drives `node`.
    pub fn targets(&self, node: usize) -> bool {
        self.channels.iter().any(|c| c.node == node)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(
        interpolation: Interpolation,
        property: Property,
        times: Vec<f32>,
        values: Vec<Vec4>,
    ) -> Channel {
        Channel {
            node: 0,
            property,
            interpolation,
            times,
            values,
        }
    }

    #[test]
    fn linear_step_and_clamping() {
        let c = channel(
            Interpolation::Linear,
            Property::Translation,
            vec![1.0, 3.0],
            vec![Vec4::ZERO, Vec4::new(2.0, 4.0, 6.0, 0.0)],
        );
        assert_eq!(c.sample(0.0), Vec4::ZERO);
        assert_eq!(c.sample(2.0), Vec4::new(1.0, 2.0, 3.0, 0.0));
        assert_eq!(c.sample(9.0), Vec4::new(2.0, 4.0, 6.0, 0.0));
        let s = Channel {
            interpolation: Interpolation::Step,
            ..c
        };
        assert_eq!(s.sample(2.9), Vec4::ZERO);
        assert_eq!(s.sample(3.0), Vec4::new(2.0, 4.0, 6.0, 0.0));
    }

    #[test]
    fn slerp_keeps_unit_length_and_halves_the_angle() {
        let q0 = Quat::IDENTITY;
        let q1 = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let c = channel(
            Interpolation::Linear,
            Property::Rotation,
            vec![0.0, 1.0],
            vec![q0.into(), q1.into()],
        );
        let q = Quat::from_vec4(c.sample(0.5));
        assert!((q.length() - 1.0).abs() < 1e-5);
        assert!(q.angle_between(Quat::from_rotation_y(std::f32::consts::FRAC_PI_4)) < 1e-4);
    }

    #[test]
    fn cubic_spline_hits_keys_and_matches_hermite_midpoint() {
        // in, value, out per key; p0 = 0, m0 = 1 (out tangent), p1 = 1, m1 = 1 (in tangent)
        let v = |x: f32| Vec4::new(x, 0.0, 0.0, 0.0);
        let c = channel(
            Interpolation::CubicSpline,
            Property::Translation,
            vec![0.0, 2.0],
            vec![v(0.0), v(0.0), v(1.0), v(1.0), v(1.0), v(0.0)],
        );
        assert_eq!(c.sample(0.0).x, 0.0);
        assert_eq!(c.sample(2.0).x, 1.0);
        // Hermite at s = 0.5 with dt = 2: 0.5 * p1 + 0.125 * m0 * dt - 0.125 * m1 * dt = 0.5
        assert!((c.sample(1.0).x - 0.5).abs() < 1e-6);
        // s = 0.25: h00 = .84375 h10 = .140625 h01 = .15625 h11 = -.046875
        let expect = 0.140625 * 2.0 + 0.15625 - 0.046875 * 2.0;
        assert!((c.sample(0.5).x - expect).abs() < 1e-6);
    }
}
