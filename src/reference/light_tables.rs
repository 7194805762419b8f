//! The tables the path tracer samples its area lights from (next-event estimation for emissive
//! triangles and the environment, combined with BRDF sampling by multiple importance sampling:
//! `shaders/include/light_sampling.glsl`, docs/frame.md "Path-traced reference").
//!
//! - **Emissive triangles** are picked in proportion to area × luminance of their emissive
//!   factor (the texture only scales it down), by a binary search of a CDF; the point is
//!   uniform on the triangle. The shader divides the pick's probability by the triangle's
//!   area *as it is on the GPU*, so a table built from the instance matrices alone (skinning
//!   and morphs left out, or a frame behind) costs variance, never bias.
//! - **The environment**, when it has peaks (a texel [`ENVIRONMENT_PEAK_RATIO`] times the
//!   mean or more: a sun, a window), is sampled from the baked equirectangular texture
//!   ([`crate::gpu_scene::environment`]): a row by its marginal CDF, then a texel of the row,
//!   then a uniform point of the texel. A texel's weight is the largest luminance of its 3×3
//!   neighbourhood (bilinear filtering spreads every texel into its neighbours' cells) times
//!   sin θ at its centre; the solid-angle density is `p(texel) · W · H / (2π² sin θ)`
//!   ([`environment_pdf`]).
//!
//! Everything goes to the GPU as one buffer of 32-bit words ([`LightTables::words`]): a header
//! of [`HEADER_WORDS`], the triangles' CDF, their indices, every triangle's pick probability (0
//! for the others: BRDF-sampled hits look theirs up), and the environment's marginal and
//! conditional CDFs.

use glam::{Mat4, Vec3};

use crate::capture::tonemap::luminance;
use crate::gpu_scene::Vertex;

/// The environment is sampled only when its largest texel weight is at least this many times
/// the mean one. A smooth sky is found about as well by the BRDF's cosine-weighted rays, and
/// its extra shadow ray then costs more than it saves: the built-in skies (ratios 2.4–2.8)
/// lost 13% (marbles) and 31% (spheres) of their efficiency (1 / (error² × time)) with it.
pub const ENVIRONMENT_PEAK_RATIO: f32 = 8.0;

/// Words of the header: emitter count, triangle count, environment width and height, then the
/// offsets (in words) of the emitter CDF, the emitter triangles, the per-triangle
/// probabilities and the environment's marginal CDF (its conditional CDFs follow it).
pub const HEADER_WORDS: usize = 8;

/// The light-sampling tables of one scene, as the GPU reads them.
#[derive(Clone, Debug, PartialEq)]
pub struct LightTables {
    /// Emissive triangles that can be picked.
    pub emitters: u32,
    /// Whether the environment is sampled (it has peaks: [`ENVIRONMENT_PEAK_RATIO`]).
    pub environment: bool,
    words: Vec<u32>,
}

impl LightTables {
    /// The tables of a flattened scene: mesh-space `vertices` (each naming its instance and
    /// material), triangle `indices`, every instance's mesh-to-world `matrices`, the
    /// `emissive` factor of every material, and the baked environment (`width × height` RGBA
    /// texels, rows from the zenith down).
    pub fn new(
        vertices: &[Vertex],
        indices: &[u32],
        matrices: &[Mat4],
        emissive: &[[f32; 3]],
        environment: &[[f32; 4]],
        [width, height]: [u32; 2],
    ) -> Self {
        let weights = triangle_weights(vertices, indices, matrices, emissive);
        let triangles = weights.len();
        let picked: Vec<(u32, f32)> = weights
            .iter()
            .enumerate()
            .filter(|(_, w)| **w > 0.0)
            .map(|(i, w)| (i as u32, *w))
            .collect();
        let emitter_cdf = cdf(picked.iter().map(|(_, w)| *w));
        // Each triangle's probability is its bin of the f32 CDF the shader searches, not w /
        // total: the two differ by the CDF's rounding, and the MIS weights need the first.
        let mut probability = vec![0.0f32; triangles];
        for (k, (i, _)) in picked.iter().enumerate() {
            let below = if k > 0 { emitter_cdf[k - 1] } else { 0.0 };
            probability[*i as usize] = emitter_cdf[k] - below;
        }
        let texel_weights = environment_weights(environment, width, height);
        let env_total: f64 = texel_weights.iter().map(|w| f64::from(*w)).sum();
        let peak = texel_weights.iter().fold(0.0f32, |a, b| a.max(*b));
        let mean = env_total / texel_weights.len().max(1) as f64;
        let environment_on =
            env_total > 0.0 && f64::from(peak) >= f64::from(ENVIRONMENT_PEAK_RATIO) * mean;
        let (marginal, conditional) = if environment_on {
            let rows: Vec<f32> = texel_weights
                .chunks(width as usize)
                .map(|row| row.iter().sum())
                .collect();
            let conditional: Vec<f32> = texel_weights
                .chunks(width as usize)
                .flat_map(|row| {
                    if row.iter().any(|w| *w > 0.0) {
                        cdf(row.iter().copied())
                    } else {
                        vec![1.0; row.len()]
                    }
                })
                .collect();
            (cdf(rows.into_iter()), conditional)
        } else {
            (Vec::new(), Vec::new())
        };
        let emitters = picked.len();
        let offsets = [
            HEADER_WORDS,
            HEADER_WORDS + emitters,
            HEADER_WORDS + 2 * emitters,
            HEADER_WORDS + 2 * emitters + triangles,
        ];
        let [env_w, env_h] = if environment_on {
            [width, height]
        } else {
            [0, 0]
        };
        let mut words = vec![emitters as u32, triangles as u32, env_w, env_h];
        words.extend(offsets.iter().map(|o| *o as u32));
        words.extend(emitter_cdf.iter().map(|c| c.to_bits()));
        words.extend(picked.iter().map(|(i, _)| *i));
        words.extend(probability.iter().map(|p| p.to_bits()));
        words.extend(marginal.iter().map(|c| c.to_bits()));
        words.extend(conditional.iter().map(|c| c.to_bits()));
        Self {
            emitters: emitters as u32,
            environment: environment_on,
            words,
        }
    }

    /// The buffer's words (never empty: the header is always there).
    pub fn words(&self) -> &[u32] {
        &self.words
    }
}

/// Area × luminance of the emissive factor of every triangle in world space (0 where it
/// emits nothing or its material or instance is unknown).
fn triangle_weights(
    vertices: &[Vertex],
    indices: &[u32],
    matrices: &[Mat4],
    emissive: &[[f32; 3]],
) -> Vec<f32> {
    let emitted = |e: &[f32; 3]| luminance(Vec3::from(*e).max(Vec3::ZERO));
    indices
        .chunks_exact(3)
        .map(|t| {
            let Some(v) = t
                .iter()
                .map(|i| vertices.get(*i as usize))
                .collect::<Option<Vec<_>>>()
            else {
                return 0.0;
            };
            let e = emissive.get(v[0].material as usize).map_or(0.0, emitted);
            let Some(m) = matrices.get(v[0].instance as usize) else {
                return 0.0;
            };
            if e <= 0.0 {
                return 0.0;
            }
            let p: Vec<Vec3> = v
                .iter()
                .map(|v| m.transform_point3(Vec3::from(v.position)))
                .collect();
            let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            if area.is_finite() { area * e } else { 0.0 }
        })
        .collect()
}

/// Every texel's sampling weight: the largest luminance of its 3×3 neighbourhood (u wraps, v
/// clamps, as the sampler does) times sin θ at its centre.
fn environment_weights(texels: &[[f32; 4]], width: u32, height: u32) -> Vec<f32> {
    let (w, h) = (width as usize, height as usize);
    if texels.len() != w * h {
        return Vec::new();
    }
    let texel_luminance: Vec<f32> = texels
        .iter()
        .map(|t| {
            let y = luminance(Vec3::from_slice(&t[..3]).max(Vec3::ZERO));
            if y.is_finite() { y } else { 0.0 }
        })
        .collect();
    (0..h)
        .flat_map(|j| (0..w).map(move |i| (i, j)))
        .map(|(i, j)| {
            let mut largest = 0.0f32;
            for dj in [-1i64, 0, 1] {
                let jj = (j as i64 + dj).clamp(0, h as i64 - 1) as usize;
                for di in [-1i64, 0, 1] {
                    let ii = (i as i64 + di).rem_euclid(w as i64) as usize;
                    largest = largest.max(texel_luminance[jj * w + ii]);
                }
            }
            let theta = (j as f32 + 0.5) / h as f32 * std::f32::consts::PI;
            largest * theta.sin()
        })
        .collect()
}

/// The inclusive CDF of `weights` normalised to end at exactly 1.
fn cdf(weights: impl Iterator<Item = f32>) -> Vec<f32> {
    let mut sum = 0.0f64;
    let mut out: Vec<f64> = weights
        .map(|w| {
            sum += f64::from(w.max(0.0));
            sum
        })
        .collect();
    for c in &mut out {
        *c /= sum;
    }
    let mut out: Vec<f32> = out.into_iter().map(|c| c as f32).collect();
    if let Some(last) = out.last_mut() {
        *last = 1.0;
    }
    out
}

/// Solid-angle density of sampling direction `dir` from the environment tables (`words` of
/// [`LightTables::words`]); the twin of `light_environment_pdf` in light_sampling.glsl.
pub fn environment_pdf(words: &[u32], dir: Vec3) -> f32 {
    let (w, h) = (words[2] as usize, words[3] as usize);
    if w == 0 {
        return 0.0;
    }
    let d = dir.normalize();
    let u = crate::gpu_scene::environment::texcoord(d);
    let i = ((u.x * w as f32) as usize).min(w - 1);
    let j = ((u.y * h as f32) as usize).min(h - 1);
    let at = |k: usize| f32::from_bits(words[k]);
    let marginal = words[7] as usize;
    let conditional = marginal + h;
    let row = at(marginal + j) - if j > 0 { at(marginal + j - 1) } else { 0.0 };
    let base = conditional + j * w;
    let texel = at(base + i) - if i > 0 { at(base + i - 1) } else { 0.0 };
    let sin_theta = (1.0 - d.y * d.y).max(0.0).sqrt();
    if sin_theta <= 0.0 {
        return 0.0;
    }
    row * texel * (w * h) as f32 / (2.0 * std::f32::consts::PI * std::f32::consts::PI * sin_theta)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vertex(p: [f32; 3], material: u32) -> Vertex {
        Vertex {
            position: p,
            material,
            ..Vertex::default()
        }
    }

    /// Two emitting triangles (areas 0.5 and 2: the second's instance is scaled by 2) and a
    /// dark one: picked with probabilities 1/5 and 4/5, the dark one never; the CDF ends at 1.
    #[test]
    fn triangles_are_picked_by_area_times_luminance() {
        let corners = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        let mut v: Vec<Vertex> = corners.iter().map(|p| vertex(*p, 0)).collect();
        v.extend(corners.iter().map(|p| vertex(*p, 1)));
        v.extend(corners.iter().map(|p| Vertex {
            instance: 1,
            ..vertex(*p, 0)
        }));
        let indices: Vec<u32> = (0..9).collect();
        let matrices = [Mat4::IDENTITY, Mat4::from_scale(Vec3::splat(2.0))];
        let t = LightTables::new(&v, &indices, &matrices, &[[1.0; 3], [0.0; 3]], &[], [0, 0]);
        assert_eq!(t.emitters, 2);
        assert!(!t.environment);
        let w = t.words();
        let f = |k: usize| f32::from_bits(w[k]);
        let (cdf, tris, prob) = (w[4] as usize, w[5] as usize, w[6] as usize);
        assert!((f(cdf) - 0.2).abs() < 1e-6 && f(cdf + 1) == 1.0);
        assert_eq!([w[tris], w[tris + 1]], [0, 2]);
        assert_eq!([f(prob), f(prob + 1)], [0.2, 0.0]);
        assert!((f(prob + 2) - 0.8).abs() < 1e-6);
    }

    /// The environment density integrates to 1 over the sphere and follows the radiance: a
    /// map bright in three texels and dim elsewhere gives their directions the larger density.
    #[test]
    fn environment_density_integrates_to_one() {
        let (w, h) = (32u32, 16u32);
        let texels: Vec<[f32; 4]> = (0..w * h)
            .map(|k| {
                let (i, j) = (k % w, k / w);
                if j == 5 && (3..6).contains(&i) {
                    [50.0, 40.0, 30.0, 1.0]
                } else {
                    [0.2, 0.3, 0.4, 1.0]
                }
            })
            .collect();
        let t = LightTables::new(&[], &[], &[], &[], &texels, [w, h]);
        assert!(t.environment);
        // Midpoint rule over (θ, φ) with dω = sin θ dθ dφ.
        let (n_theta, n_phi) = (400, 800);
        let mut integral = 0.0f64;
        for a in 0..n_theta {
            let theta = (a as f32 + 0.5) / n_theta as f32 * std::f32::consts::PI;
            for b in 0..n_phi {
                let phi = (b as f32 + 0.5) / n_phi as f32 * std::f32::consts::TAU;
                let d = Vec3::new(
                    theta.sin() * phi.cos(),
                    theta.cos(),
                    theta.sin() * phi.sin(),
                );
                integral += f64::from(environment_pdf(t.words(), d)) * f64::from(theta.sin());
            }
        }
        integral *= std::f64::consts::PI / n_theta as f64 * std::f64::consts::TAU / n_phi as f64;
        assert!((integral - 1.0).abs() < 0.01, "∫ pdf dω = {integral}");
        let bright = crate::gpu_scene::environment::direction(4.5 / w as f32, 5.5 / h as f32);
        let dim = crate::gpu_scene::environment::direction(0.7, 10.5 / h as f32);
        assert!(environment_pdf(t.words(), bright) > 20.0 * environment_pdf(t.words(), dim));
    }

    /// The built-in skies are smooth (peak ratios 2.4–2.8): the BRDF's rays find them, the
    /// environment is not sampled. A sun of 0.3% of the sphere is.
    #[test]
    fn only_an_environment_with_peaks_is_sampled() {
        for name in ["spheres", "marbles", "animated"] {
            let scene = shine_scene::Scene::builtin(name).expect("builtin");
            let env = crate::gpu_scene::environment::bake(scene.environment.as_ref());
            let t = LightTables::new(&[], &[], &[], &[], &env, [256, 128]);
            assert!(!t.environment, "{name}'s sky is sampled");
        }
        let (w, h) = (64u32, 32u32);
        let sun: Vec<[f32; 4]> = (0..w * h)
            .map(|k| {
                if k == 10 * w + 20 {
                    [500.0; 4]
                } else {
                    [0.5, 0.6, 0.8, 1.0]
                }
            })
            .collect();
        assert!(LightTables::new(&[], &[], &[], &[], &sun, [w, h]).environment);
    }

    /// No emitters and a black environment: only the header, nothing to sample.
    #[test]
    fn a_dark_scene_has_empty_tables() {
        let v = vec![
            vertex([0.0; 3], 0),
            vertex([1.0, 0.0, 0.0], 0),
            vertex([0.0, 1.0, 0.0], 0),
        ];
        let t = LightTables::new(
            &v,
            &[0, 1, 2],
            &[Mat4::IDENTITY],
            &[[0.0; 3]],
            &[[0.0; 4]; 8],
            [4, 2],
        );
        assert_eq!((t.emitters, t.environment), (0, false));
        assert_eq!(t.words()[2..4], [0, 0]);
    }
}
