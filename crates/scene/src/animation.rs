//! Node animations (glTF translation / rotation / scale / morph weight channels) evaluated at
//! any time.
//!
//! Sampling follows glTF 2.0 §3.11: before the first key the first value holds, after the last
//! key the last value holds (no looping: wrap `t` yourself with [`Animation::duration`]);
//! `STEP` holds the previous key, `LINEAR` lerps (rotations slerp along the shortest arc) and
//! `CUBICSPLINE` evaluates the Hermite spline from the in/out tangents. Rotations are
//! renormalised. Morph weights are sampled component by component like translations.

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
    /// Morph target weights of the node's mesh (one per target).
    Weights,
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
    /// Components per value: 3 for translation and scale, 4 for rotation (xyzw), the number
    /// of morph targets for weights.
    pub width: usize,
    /// Key values, `width` floats each, flat. For `CubicSpline`, three values per key:
    /// in-tangent, value, out-tangent.
    pub values: Vec<f32>,
}

impl Channel {
    /// Value `i` (in units of `width` floats); zeros past the end.
    fn value(&self, i: usize, out: &mut [f32]) {
        let start = i * self.width;
        let src = self
            .values
            .get(start..start + self.width)
            .unwrap_or_default();
        out.fill(0.0);
        for (o, s) in out.iter_mut().zip(src) {
            *o = *s;
        }
    }

    /// Writes the channel's value at time `t` (seconds) into `out` (its first `width`
    /// components; the rest is zeroed).
    pub fn sample_into(&self, t: f32, out: &mut [f32]) {
        let cubic = self.interpolation == Interpolation::CubicSpline;
        let key = |k: usize| if cubic { 3 * k + 1 } else { k };
        let n = self.times.len();
        let (Some(&first), Some(&last)) = (self.times.first(), self.times.last()) else {
            out.fill(0.0);
            return;
        };
        if n == 1 || t.is_nan() || t <= first {
            return self.value(key(0), out);
        }
        if t >= last {
            return self.value(key(n - 1), out);
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
        let mut a = vec![0.0; out.len()];
        let mut b = vec![0.0; out.len()];
        match self.interpolation {
            Interpolation::Step => self.value(k, out),
            Interpolation::Linear => {
                self.value(k, &mut a);
                self.value(k + 1, &mut b);
                if self.property == Property::Rotation {
                    let q = |v: &[f32]| {
                        Quat::from_xyzw(
                            v.first().copied().unwrap_or(0.0),
                            v.get(1).copied().unwrap_or(0.0),
                            v.get(2).copied().unwrap_or(0.0),
                            v.get(3).copied().unwrap_or(0.0),
                        )
                        .normalize()
                    };
                    let r = q(&a).slerp(q(&b), s).to_array();
                    for (o, x) in out.iter_mut().zip(r) {
                        *o = x;
                    }
                } else {
                    for ((o, x), y) in out.iter_mut().zip(&a).zip(&b) {
                        *o = x + (y - x) * s;
                    }
                }
            }
            Interpolation::CubicSpline => {
                // glTF 2.0 Appendix C: p(s) = h00 p0 + h10 dt m0 + h01 p1 + h11 dt m1, with
                // m0 the out-tangent of key k and m1 the in-tangent of key k + 1.
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                let mut m0 = vec![0.0; out.len()];
                let mut m1 = vec![0.0; out.len()];
                self.value(3 * k + 1, &mut a);
                self.value(3 * k + 2, &mut m0);
                self.value(3 * (k + 1) + 1, &mut b);
                self.value(3 * (k + 1), &mut m1);
                for (i, o) in out.iter_mut().enumerate() {
                    *o = a[i] * h00 + m0[i] * dt * h10 + b[i] * h01 + m1[i] * dt * h11;
                }
            }
        }
    }

    /// The channel's value at time `t` (seconds) as a vector: its first four components,
    /// zeros past `width` (translation and scale in `xyz`, rotation in `xyzw`).
    pub fn sample(&self, t: f32) -> Vec4 {
        let mut v = [0.0; 4];
        self.sample_into(t, &mut v);
        Vec4::from_array(v)
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

    /// Overwrites the animated transform properties of `locals` with their values at time
    /// `t` (weight channels are left to [`Animation::apply_weights`]).
    pub fn apply(&self, t: f32, locals: &mut [Transform]) {
        for c in &self.channels {
            let Some(local) = locals.get_mut(c.node) else {
                continue;
            };
            match c.property {
                Property::Weights => {}
                Property::Translation => local.translation = c.sample(t).truncate(),
                Property::Scale => local.scale = c.sample(t).truncate(),
                Property::Rotation => {
                    let v = c.sample(t);
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

    /// Overwrites the animated morph weights in `weights` (one list per node) with their
    /// values at time `t`; a channel wider than its node's list writes only what fits.
    pub fn apply_weights(&self, t: f32, weights: &mut [Vec<f32>]) {
        for c in &self.channels {
            if c.property != Property::Weights {
                continue;
            }
            if let Some(w) = weights.get_mut(c.node) {
                c.sample_into(t, w);
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
        let width = if property == Property::Rotation { 4 } else { 3 };
        Channel {
            node: 0,
            property,
            interpolation,
            times,
            width,
            values: values
                .iter()
                .flat_map(|v| v.to_array().into_iter().take(width))
                .collect(),
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

    #[test]
    fn weights_channels_have_any_width_and_write_per_node_lists() {
        // Two targets, cubic spline: in, value, out per key, two floats each.
        let c = Channel {
            node: 1,
            property: Property::Weights,
            interpolation: Interpolation::CubicSpline,
            times: vec![0.0, 1.0],
            width: 2,
            values: vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        };
        let a = Animation {
            name: "w".into(),
            channels: vec![c.clone()],
        };
        let mut weights = vec![vec![], vec![0.5, 0.5]];
        a.apply_weights(0.5, &mut weights);
        // Zero tangents: smoothstep from (0, 1) to (1, 0).
        assert!((weights[1][0] - 0.5).abs() < 1e-6 && (weights[1][1] - 0.5).abs() < 1e-6);
        a.apply_weights(0.25, &mut weights);
        assert!((weights[1][0] - 0.15625).abs() < 1e-6, "{weights:?}");
        assert!((weights[1][0] + weights[1][1] - 1.0).abs() < 1e-6);
        assert!(weights[0].is_empty());
        // Transforms are untouched by weight channels.
        let mut locals = vec![Transform::default(); 2];
        a.apply(0.5, &mut locals);
        assert_eq!(locals[1], Transform::default());
        let linear = Channel {
            interpolation: Interpolation::Linear,
            values: vec![0.0, 1.0, 1.0, 0.0],
            ..c
        };
        let mut out = [9.0; 3];
        linear.sample_into(0.75, &mut out);
        assert_eq!(out, [0.75, 0.25, 0.0]);
    }
}
