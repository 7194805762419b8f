//! CPU twin of the traced signals' denoiser (issue 47): `shaders/include/denoise.glsl` (same
//! names without the `denoise_` prefix), `shaders/denoise_prep.comp` ([`prep`]) and
//! `shaders/denoise_atrous.comp` ([`atrous`]), both variants ([`Signal`]). `tests/denoise.rs`
//! compares the passes with it; [`crate::passes::denoise`] explains the filter.

use glam::{Vec3, Vec4};

use crate::capture::tonemap::luminance;
use crate::passes::brdf_tables::{alpha, indirect_weights};
use crate::passes::specular::trace_weight;

/// `DENOISE_LOBE_FRACTION`: share f of the GGX half vectors inside the spanned lobe.
pub const LOBE_FRACTION: f32 = 0.5;
/// `DENOISE_MAX_LOBE_ANGLE`: widest reflected half-angle spanned, radians.
pub const MAX_LOBE_ANGLE: f32 = 1.0;
/// `DENOISE_MIN_PARALLAX`: least parallax the footprint takes.
pub const MIN_PARALLAX: f32 = 0.5;
/// `DENOISE_MAX_RADIUS`: largest footprint radius, pixels.
pub const MAX_RADIUS: f32 = 16.0;
/// `DENOISE_SHARP_RADIUS`: a footprint under this radius (pixels) is sharp, its pixel kept as
/// traced (neither filtered nor clamped: a mirror's rays agree).
pub const SHARP_RADIUS: f32 = 0.5;
/// `DENOISE_PLANE_SIGMA`: distance off the tangent plane, relative to the view distance.
pub const PLANE_SIGMA: f32 = 0.02;
/// `DENOISE_MIN_NORMAL_TOLERANCE`: least normal tolerance 1 − cos φ.
pub const MIN_NORMAL_TOLERANCE: f32 = 1e-4;
/// `DENOISE_ROUGHNESS_SIGMA`: roughness difference over which lobes stop mixing.
pub const ROUGHNESS_SIGMA: f32 = 0.05;
/// `DENOISE_LUMINANCE_SIGMA`: SVGF's σ_l, in standard deviations of the centre.
pub const LUMINANCE_SIGMA: f32 = 8.0;
/// `DENOISE_FIREFLY_RATIO`: a pixel's luminance at most this many times its largest neighbour's
/// on the same surface (roughness taken at [`clamp_roughness`]).
pub const FIREFLY_RATIO: f32 = 2.0;
/// `DENOISE_LUMINANCE_EPSILON`: ε of the luminance weight.
pub const LUMINANCE_EPSILON: f32 = 1e-6;
/// `HALF_MAX` (shaders/include/color.glsl): the largest finite half float, what the filter's
/// images (and the history's state) hold at most.
pub const HALF_MAX: f32 = 65504.0;
/// `DENOISE_MATCH`: least geometry weight of a neighbour in the clamp and the variance.
pub const MATCH: f32 = 0.25;
/// `DENOISE_MIN_WEIGHT`: smallest demodulation weight share · ks.
pub const MIN_WEIGHT: f32 = 1e-3;
/// `DENOISE_DIFFUSE_NORMAL_TOLERANCE`: the diffuse signal's normal tolerance 1 − cos φ.
pub const DIFFUSE_NORMAL_TOLERANCE: f32 = 0.03125;
/// `DENOISE_DIFFUSE_MIN_RADIUS`: least radius of a hit-distance footprint, pixels.
pub const DIFFUSE_MIN_RADIUS: f32 = 1.0;

/// `denoise_world_radius`: `world` units at `dist` from the eye in pixels of `pixel_angle`,
/// within [`DIFFUSE_MIN_RADIUS`]..=[`MAX_RADIUS`].
pub fn world_radius(world: f32, dist: f32, pixel_angle: f32) -> f32 {
    (world / (dist * pixel_angle)).clamp(DIFFUSE_MIN_RADIUS, MAX_RADIUS)
}

/// Which traced signal the filter takes: the shaders' variants.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    /// The specular pass's radiance (variant `specular`): demodulated by share · ks, the
    /// lobe's footprint and normal tolerance, the roughness test.
    Specular,
    /// The sky's or near field's demodulated light (variant `diffuse`): remodulated by kd,
    /// a stated footprint radius, [`DIFFUSE_NORMAL_TOLERANCE`], no roughness test, the
    /// luminance weight over the larger variance.
    Diffuse,
}

/// `denoise_lobe_angle`: the reflected lobe's half-angle for GGX `alpha`.
pub fn lobe_angle(alpha: f32) -> f32 {
    let t = alpha * (LOBE_FRACTION / (1.0 - LOBE_FRACTION)).sqrt();
    (2.0 * t.atan()).min(MAX_LOBE_ANGLE)
}

/// `DENOISE_RAY_FLOOR`: least claim of a traced pixel on the frame's specular rays.
pub const RAY_FLOOR: f32 = 0.02;
/// `DENOISE_RAY_MAX_FACTOR`: most rays of a pixel, in multiples of `specular.samples`.
pub const RAY_MAX_FACTOR: f32 = 4.0;
/// `DENOISE_RAY_KEEP_TAN`: a lobe narrower than this tan θ keeps its `specular.samples` rays
/// when they are shared ([`rays`]).
pub const RAY_KEEP_TAN: f32 = 0.01;

/// `denoise_rays`: the rays of a traced pixel of GGX `alpha` and trace share `share`:
/// [`ray_count`] of its [`ray_weight`], at least `samples` for a lobe narrower than
/// [`RAY_KEEP_TAN`].
pub fn rays(alpha: f32, share: f32, samples: u32, traced: f32, total: f32, u: f32) -> u32 {
    let n = ray_count(ray_weight(alpha, share), samples, traced, total, u);
    if lobe_tan(alpha) < RAY_KEEP_TAN {
        n.max(samples.max(1))
    } else {
        n
    }
}

/// `denoise_clamp_roughness`: the roughness neighbour `q` is compared at in the firefly clamp's
/// geometry test (a smoother neighbour counts as the centre's own).
pub fn clamp_roughness(p: f32, q: f32) -> f32 {
    p.max(q)
}

/// `denoise_variance_kernel`: the 3-tap gaussian (offset `i` in −1..=1) of SVGF's variance
/// prefilter.
pub fn variance_kernel(i: i32) -> f32 {
    if i == 0 { 0.5 } else { 0.25 }
}

/// `denoise_ray_weight`: a traced pixel's claim on the specular rays (0 when `share` is 0).
pub fn ray_weight(alpha: f32, share: f32) -> f32 {
    if share > 0.0 {
        share * (RAY_FLOOR + lobe_tan(alpha))
    } else {
        0.0
    }
}

/// `denoise_ray_count`: the rays of a pixel claiming `weight` of `total` among `traced`
/// pixels at `samples` each: one, plus its claim's share of the other `samples − 1` each,
/// rounded up with probability its fraction (`u` in [0, 1)).
pub fn ray_count(weight: f32, samples: u32, traced: f32, total: f32, u: f32) -> u32 {
    let spare = (samples.max(1) - 1) as f32;
    let n = if total > 0.0 {
        1.0 + spare * traced * weight / total
    } else {
        samples as f32
    };
    (n.min(RAY_MAX_FACTOR * samples as f32) + u).floor() as u32
}

/// `denoise_lobe_tan`: tan of [`lobe_angle`].
pub fn lobe_tan(alpha: f32) -> f32 {
    lobe_angle(alpha).tan()
}

/// `denoise_normal_tolerance`: 1 − cos of [`lobe_angle`], at least [`MIN_NORMAL_TOLERANCE`].
pub fn normal_tolerance(alpha: f32) -> f32 {
    (1.0 - lobe_angle(alpha).cos()).max(MIN_NORMAL_TOLERANCE)
}

/// `denoise_radius`: footprint radius in pixels at `parallax` d / (z + d).
pub fn radius(alpha: f32, parallax: f32, pixel_angle: f32) -> f32 {
    (lobe_tan(alpha) * parallax.max(MIN_PARALLAX) / pixel_angle).min(MAX_RADIUS)
}

/// `denoise_kernel`: the B3-spline tap of offset `i` in −2..=2.
pub fn kernel(i: i32) -> f32 {
    match i.abs() {
        0 => 0.375,
        1 => 0.25,
        _ => 0.0625,
    }
}

/// One side of a geometry test: position, unit normal, distance from the eye, roughness
/// (the normal tolerance is the centre's, from its roughness).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Surface {
    /// World position.
    pub position: Vec3,
    /// Unit shading normal.
    pub normal: Vec3,
    /// Distance from the eye.
    pub dist: f32,
    /// Perceptual roughness.
    pub roughness: f32,
}

/// `denoise_geometry_weight` with the normal tolerance of `p`'s lobe: how much `q` stands for
/// `p`.
pub fn geometry_weight(p: &Surface, q: &Surface) -> f32 {
    geometry_weight_within(p, q, normal_tolerance(alpha(p.roughness)))
}

/// `denoise_geometry_weight` with the normal tolerance `tolerance` (1 − cos φ).
pub fn geometry_weight_within(p: &Surface, q: &Surface, tolerance: f32) -> f32 {
    let plane = p.normal.dot(q.position - p.position).abs() / (PLANE_SIGMA * p.dist);
    let normal = (1.0 - p.normal.dot(q.normal)) / tolerance;
    (-plane - normal - (p.roughness - q.roughness).abs() / ROUGHNESS_SIGMA).exp()
}

/// `denoise_luminance_weight`: SVGF's exp(−|l_p − l_q| / (σ_l √var_p + ε)).
pub fn luminance_weight(l_p: f32, l_q: f32, variance: f32) -> f32 {
    (-(l_p - l_q).abs() / (LUMINANCE_SIGMA * variance.max(0.0).sqrt() + LUMINANCE_EPSILON)).exp()
}

/// `denoise_storable`: each channel at most [`HALF_MAX`].
pub fn storable(v: Vec4) -> Vec4 {
    v.min(Vec4::splat(HALF_MAX))
}

/// `denoise_lobe_weight`: the footprint's gaussian at squared offset `offset2`.
pub fn lobe_weight(offset2: f32, radius: f32) -> f32 {
    if radius < SHARP_RADIUS {
        return if offset2 == 0.0 { 1.0 } else { 0.0 };
    }
    (-offset2 / (2.0 * radius * radius)).exp()
}

/// The G-buffer the denoiser reads, row-major texels as the images hold them (normals not
/// normalised; albedo and material in 0..1).
#[derive(Debug, Clone, Copy)]
pub struct Guide<'a> {
    /// Width and height.
    pub extent: [u32; 2],
    /// `gb_position` (w = view depth, 0 on the background).
    pub position: &'a [Vec4],
    /// `gb_normal`.
    pub normal: &'a [Vec4],
    /// `gb_albedo`.
    pub albedo: &'a [Vec4],
    /// `gb_material` (r roughness, g metallic).
    pub material: &'a [Vec4],
    /// Eye position.
    pub camera: Vec3,
    /// The specular pass's roughness limit (unused by [`Signal::Diffuse`]).
    pub limit: f32,
    /// The signal filtered.
    pub signal: Signal,
}

impl Guide<'_> {
    fn index(&self, x: i32, y: i32) -> Option<usize> {
        let [w, h] = self.extent.map(|e| e as i32);
        (x >= 0 && y >= 0 && x < w && y < h).then(|| (y * w + x) as usize)
    }

    /// The normal tolerance of centre `p`.
    fn tolerance(&self, p: &Surface) -> f32 {
        match self.signal {
            Signal::Specular => normal_tolerance(alpha(p.roughness)),
            Signal::Diffuse => DIFFUSE_NORMAL_TOLERANCE,
        }
    }

    /// The variance the luminance weight of centre and neighbour takes: the centre's (SVGF), or
    /// for the diffuse signals the larger of the two.
    fn variance(&self, p: f32, q: f32) -> f32 {
        match self.signal {
            Signal::Specular => p,
            Signal::Diffuse => p.max(q),
        }
    }

    /// The roughness the geometry test compares (0 for the diffuse signal: no test).
    fn roughness(&self, i: usize) -> f32 {
        match self.signal {
            Signal::Specular => self.material[i].x,
            Signal::Diffuse => 0.0,
        }
    }

    /// The pixel's surface, what the input is divided by (share · ks floored at
    /// [`MIN_WEIGHT`]; 1 for the diffuse light, demodulated already) and what the output is
    /// multiplied by (share · ks again, or kd); `None` where nothing is traced.
    fn surface(&self, i: usize) -> Option<(Surface, Vec3, Vec3)> {
        if self.signal == Signal::Diffuse {
            return self.diffuse_surface(i);
        }
        let position = self.position[i];
        let n = self.normal[i].truncate();
        let material = self.material[i];
        let dist = (self.camera - position.truncate()).length();
        let share = trace_weight(material.x, self.limit);
        if position.w == 0.0 || share <= 0.0 || n.dot(n) <= 0.0 || dist <= 0.0 {
            return None;
        }
        let normal = n.normalize();
        let nv = normal.dot((self.camera - position.truncate()) / dist);
        if nv <= 0.0 {
            return None;
        }
        let (_, ks) = indirect_weights(self.albedo[i].truncate(), material.y, nv);
        let surface = Surface {
            position: position.truncate(),
            normal,
            dist,
            roughness: material.x,
        };
        let weight = (share * ks).max(Vec3::splat(MIN_WEIGHT));
        Some((surface, weight, weight))
    }

    /// [`Self::surface`] of a receiver for the diffuse light.
    fn diffuse_surface(&self, i: usize) -> Option<(Surface, Vec3, Vec3)> {
        let position = self.position[i];
        let n = self.normal[i].truncate();
        let dist = (self.camera - position.truncate()).length();
        if position.w <= 0.0 || n.dot(n) <= 0.0 || dist <= 0.0 {
            return None;
        }
        let normal = n.normalize();
        let nv = normal.dot((self.camera - position.truncate()) / dist);
        let (kd, _) = indirect_weights(self.albedo[i].truncate(), self.material[i].y, nv);
        let surface = Surface {
            position: position.truncate(),
            normal,
            dist,
            roughness: 0.0,
        };
        Some((surface, Vec3::ONE, kd))
    }
}

/// `denoise_prep`: per pixel the demodulated, firefly-clamped (`clamp`, where the footprint is
/// at least [`SHARP_RADIUS`]) signal with its 3×3
/// luminance variance in w, and the footprint radius in pixels (−1 where nothing is traced),
/// from `input`: the specular pass's output (rgb radiance, a parallax) or the diffuse light
/// (rgb light / π, a the rays' mean hit distance where `hit_scale` > 0). `footprint` and
/// `hit_scale` are the push constants': the angle of a pixel (specular, or diffuse with
/// `hit_scale` > 0: the radius `hit_scale` times the mean hit distance) or the radius in pixels.
pub fn prep(
    g: &Guide<'_>,
    input: &[Vec4],
    footprint: f32,
    hit_scale: f32,
    clamp: bool,
) -> (Vec<Vec4>, Vec<f32>) {
    let count = (g.extent[0] * g.extent[1]) as usize;
    let mut signal = vec![Vec4::ZERO; count];
    let mut radii = vec![-1.0; count];
    for y in 0..g.extent[1] as i32 {
        for x in 0..g.extent[0] as i32 {
            let Some(i) = g.index(x, y) else { continue };
            let Some((centre, weight, _)) = g.surface(i) else {
                continue;
            };
            let tolerance = g.tolerance(&centre);
            let mut bound = -1.0f32;
            let (mut sum, mut sum2) = (0.0f32, 0.0f32);
            let mut parallax = input[i].w;
            let mut n = 1.0f32;
            for (dx, dy) in (-1..=1).flat_map(|dy| (-1..=1).map(move |dx| (dx, dy))) {
                let Some(j) = g.index(x + dx, y + dy).filter(|_| (dx, dy) != (0, 0)) else {
                    continue;
                };
                let Some((q, q_weight, _)) = g.surface(j) else {
                    continue;
                };
                let l = luminance(input[j].truncate() / q_weight);
                let same_surface = Surface {
                    roughness: clamp_roughness(centre.roughness, q.roughness),
                    ..q
                };
                if geometry_weight_within(&centre, &same_surface, tolerance) >= MATCH {
                    bound = bound.max(l);
                }
                if geometry_weight_within(&centre, &q, tolerance) < MATCH {
                    continue;
                }
                sum += l;
                sum2 += l * l;
                parallax += input[j].w;
                n += 1.0;
            }
            let r = match g.signal {
                Signal::Specular => radius(alpha(centre.roughness), parallax / n, footprint),
                Signal::Diffuse if hit_scale > 0.0 => {
                    world_radius(hit_scale * parallax / n, centre.dist, footprint)
                }
                Signal::Diffuse => footprint,
            };
            bound *= FIREFLY_RATIO;
            let mut value = input[i].truncate() / weight;
            let mut l_p = luminance(value);
            if clamp && r >= SHARP_RADIUS && bound >= 0.0 && l_p > bound {
                value *= bound / l_p;
                l_p = bound;
            }
            sum += l_p;
            sum2 += l_p * l_p;
            let mean = sum / n;
            let variance = (sum2 / n - mean * mean).max(0.0);
            signal[i] = storable(value.extend(variance));
            radii[i] = r;
        }
    }
    (signal, radii)
}

/// The specular's luminance-weight variance at (x, y): the [`variance_kernel`] gaussian of the
/// traced 3×3 neighbours' variances (SVGF's prefilter).
fn prefiltered_variance(g: &Guide<'_>, signal: &[Vec4], radii: &[f32], x: i32, y: i32) -> f32 {
    let (mut sum, mut weight) = (0.0f32, 0.0f32);
    for j in -1..=1 {
        for k in -1..=1 {
            let Some(c) = g.index(x + k, y + j).filter(|&c| radii[c] >= 0.0) else {
                continue;
            };
            let w = variance_kernel(k) * variance_kernel(j);
            sum += w * signal[c].w;
            weight += w;
        }
    }
    sum / weight
}

/// `denoise_atrous`: one iteration at tap spacing `step` over `signal` (rgb, variance in w);
/// with `remodulate = Some(source)` (the prep's input) the last one: the radiance times share ·
/// ks (or kd) with w = 0, and where the footprint is sharp ([`SHARP_RADIUS`]) `source` as
/// traced (times kd for the diffuse signal, whose source is demodulated).
pub fn atrous(
    g: &Guide<'_>,
    signal: &[Vec4],
    radii: &[f32],
    step: i32,
    remodulate: Option<&[Vec4]>,
) -> Vec<Vec4> {
    let mut out = vec![Vec4::ZERO; signal.len()];
    for y in 0..g.extent[1] as i32 {
        for x in 0..g.extent[0] as i32 {
            let Some(i) = g.index(x, y) else { continue };
            let r = radii[i];
            let Some((p, _, weight)) = g.surface(i).filter(|_| r >= 0.0) else {
                continue;
            };
            let tolerance = g.tolerance(&p);
            let centre = signal[i];
            let l_p = luminance(centre.truncate());
            let guide = match g.signal {
                Signal::Specular => prefiltered_variance(g, signal, radii, x, y),
                Signal::Diffuse => centre.w,
            };
            let (mut sum, mut variance, mut weight_sum) = (Vec3::ZERO, 0.0f32, 0.0f32);
            for j in -2..=2 {
                for k in -2..=2 {
                    let (ox, oy) = (step * k, step * j);
                    let Some(c) = g.index(x + ox, y + oy) else {
                        continue;
                    };
                    let lobe = lobe_weight((ox * ox + oy * oy) as f32, r);
                    if lobe == 0.0 || radii[c] < 0.0 {
                        continue;
                    }
                    let q = signal[c];
                    let surface = Surface {
                        position: g.position[c].truncate(),
                        normal: g.normal[c].truncate().normalize(),
                        dist: 0.0,
                        roughness: g.roughness(c),
                    };
                    let w = kernel(k)
                        * kernel(j)
                        * lobe
                        * geometry_weight_within(&p, &surface, tolerance)
                        * luminance_weight(l_p, luminance(q.truncate()), g.variance(guide, q.w));
                    if w > 0.0 {
                        sum += w * q.truncate();
                        variance += w * w * q.w;
                        weight_sum += w;
                    }
                }
            }
            let value = sum / weight_sum;
            out[i] = match remodulate {
                Some(source) if r < SHARP_RADIUS => match g.signal {
                    Signal::Specular => source[i].truncate().extend(0.0),
                    Signal::Diffuse => (source[i].truncate() * weight).extend(0.0),
                },
                Some(_) => (value * weight).extend(0.0),
                None => storable(value.extend(variance / (weight_sum * weight_sum))),
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rays_go_to_the_wide_lobes_within_the_budget() {
        // A frame of mirrors (roughness 0.05), a gold of 0.3 and a fading 0.45 (share ½).
        let pixels: Vec<(f32, f32)> = (0..3000)
            .map(|i| match i % 3 {
                0 => (alpha(0.05), 1.0),
                1 => (alpha(0.3), 1.0),
                _ => (alpha(0.45), 0.5),
            })
            .collect();
        let total: f32 = pixels.iter().map(|&(a, s)| ray_weight(a, s)).sum();
        let traced = pixels.len() as f32;
        let rays: Vec<u32> = pixels
            .iter()
            .enumerate()
            .map(|(i, &(a, s))| {
                ray_count(
                    ray_weight(a, s),
                    2,
                    traced,
                    total,
                    (i as f32 * 0.618_034).fract(),
                )
            })
            .collect();
        let mean = |k: usize| {
            let r: Vec<u32> = rays.iter().skip(k).step_by(3).copied().collect();
            r.iter().sum::<u32>() as f32 / r.len() as f32
        };
        let spent = rays.iter().sum::<u32>() as f32 / traced;
        // Mirrors about one ray; the gold more than the two it had; the whole within 2% of 2.
        assert!(mean(0) < 1.25, "mirrors {}", mean(0));
        assert!(mean(1) > 2.2, "gold {}", mean(1));
        assert!(
            (spent / 2.0 - 1.0).abs() < 0.02,
            "spent {spent} rays per pixel"
        );
        assert_eq!(ray_weight(alpha(0.3), 0.0), 0.0);
        assert_eq!(ray_count(1.0, 2, 10.0, 0.0, 0.0), 2);

        // With the mirrors' floor (`rays`): the mirrors keep their two rays, the gold still
        // gains, and the frame spends at most the mirrors' extra ray on top of the budget.
        let shared: Vec<u32> = pixels
            .iter()
            .enumerate()
            .map(|(i, &(a, s))| super::rays(a, s, 2, traced, total, (i as f32 * 0.618_034).fract()))
            .collect();
        assert!(
            shared.iter().step_by(3).all(|&n| n == 2),
            "a mirror lost rays"
        );
        let gold = shared.iter().skip(1).step_by(3).sum::<u32>() as f32 / 1000.0;
        assert!((gold - mean(1)).abs() < 1e-6, "gold {gold}");
        let spent = shared.iter().sum::<u32>() as f32 / traced;
        assert!(
            spent < 2.0 * 1.02 + 1.0 / 3.0,
            "spent {spent} rays per pixel"
        );
        // A lobe just wider than the floor's shares as before.
        let wide = alpha(0.1);
        assert!(lobe_tan(wide) > RAY_KEEP_TAN);
        assert_eq!(
            super::rays(wide, 1.0, 2, 10.0, 10.0, 0.0),
            ray_count(ray_weight(wide, 1.0), 2, 10.0, 10.0, 0.0)
        );
    }
}
