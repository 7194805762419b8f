//! CPU twin of the AAF filter-width and filter passes (paper 004, `src/passes/aaf/`):
//! [`beta_cpu`] is `aaf_beta.comp` through shine-sh's formulas, [`filter_cpu`] the two passes
//! of `aaf_filter.comp` before the receivers' weights ([`weights`]). `tests/aaf.rs` ties them to the GPU.

use glam::{Vec3, Vec4};
use shine_sh::ShError;
use shine_sh::aaf::{
    LocalFit, PixelFootprint, TANGENT_SCALE, filter_bandwidth, filter_width, receiver_bandlimit,
    samples_per_pixel,
};

use crate::passes::aaf::{AafParams, MAX_RADIUS, PLANE_TOLERANCE, ROUGHNESS_TOLERANCE};
use crate::passes::brdf_tables::indirect_weights;
use crate::passes::specular::trace_weight;

/// What `aaf_beta` writes for one pixel: `(β, samples)` from its linear depth (0 on
/// background), its first-pass `(z_min, z_max)` (0, 0 without a hit: the scene's size is taken
/// for both), its roughness and metallic, the [`footprint`] and the scene's size
/// ([`scene_size`](crate::passes::aaf::scene_size)).
///
/// [`footprint`]: crate::passes::aaf::footprint
pub fn beta_cpu(
    depth: f32,
    z: [f32; 2],
    roughness_metallic: [f32; 2],
    footprint: [f32; 2],
    scene_size: f32,
    params: &AafParams,
) -> Result<[f32; 2], ShError> {
    if depth == 0.0 {
        return Ok([0.0, 0.0]);
    }
    let z = if z[1] == 0.0 { [scene_size; 2] } else { z };
    let z_min = z[0].max(params.z_min_fraction * scene_size);
    let px = PixelFootprint {
        z_min,
        z_max: z[1].max(z_min),
        pixel_size: depth * footprint[0] + footprint[1],
    };
    let [roughness, metallic] = roughness_metallic;
    let omega_h = receiver_bandlimit(params.omega_h, roughness, metallic);
    let omega_r = filter_bandwidth(omega_h, px, params.alpha, params.mu)?;
    let n = samples_per_pixel(omega_h, px, params.alpha, params.mu, params.gamma)?;
    Ok([
        filter_width(omega_r)?,
        n.ceil().clamp(params.spp_min as f32, params.spp_upper()),
    ])
}

/// The least diffuse weight the samples are divided by (`AAF_WEIGHT_MIN` of
/// `shaders/include/aaf.glsl`): a pixel whose `kd` sums to less over its channels (a metal)
/// carries no diffuse light, and the filter leaves its diffuse mean out.
pub const WEIGHT_MIN: f32 = 1e-3;

/// The receiver's weights of the filtered diffuse and specular means (the second pass of
/// `aaf_filter.comp`): `kd` and `ks (1 − trace_weight)`, `kd` and `ks` from
/// [`indirect_weights`] at `n_dot_v` and the traced specular pass of roughness limit
/// `specular_limit` taking the rest of the glossy lobe. The indirect light is the sum of the
/// products.
pub fn weights(
    albedo: Vec3,
    roughness: f32,
    metallic: f32,
    n_dot_v: f32,
    specular_limit: f32,
) -> [Vec3; 2] {
    let (kd, ks) = indirect_weights(albedo, metallic, n_dot_v);
    [kd, ks * (1.0 - trace_weight(roughness, specular_limit))]
}

/// One pixel of the G-buffer as the filter sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterTexel {
    /// xyz world position, w linear depth (0 on background).
    pub position: Vec4,
    /// Shading normal (normalised here): the normal threshold of the specular part (and of the
    /// diffuse part without the irradiance vector), and where the result is evaluated.
    pub normal: Vec3,
    /// Geometric normal (normalised here): the tangent-plane test, and the diffuse part's normal
    /// threshold with the irradiance vector.
    pub geometric_normal: Vec3,
    /// Perceptual roughness: the specular means' test ([`ROUGHNESS_TOLERANCE`]).
    pub roughness: f32,
    /// β of the pixel (world units; 0: no filter).
    pub beta: f32,
    /// The means to filter.
    pub means: Means,
}

/// A pixel's mean incident light as the sampling passes leave it, demodulated, in the diffuse
/// and specular parts the filter smooths apart.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Means {
    /// The diffuse mean `M₀` (the samples' `π f_d L / kd`).
    pub diffuse: Vec3,
    /// The mean of the diffuse samples times the x, y and z of their direction's part tangent
    /// to the shading normal (`M₁ₜ`, rgb per axis).
    pub tangent: [Vec3; 3],
    /// The specular mean (the samples' `π f_s L / ks`).
    pub specular: Vec3,
    /// Whether the diffuse mean holds light (`kd` summing to at least [`WEIGHT_MIN`]).
    pub lit: bool,
}

/// A pixel's light as the filter passes hand it on: the diffuse part as an irradiance vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Filtered {
    /// The irradiance vector over π, as its x, y and z columns (rgb each): the diffuse mean at
    /// normal `n` is `Σ_k vector[k] n_k`.
    pub vector: [Vec3; 3],
    /// The specular mean.
    pub specular: Vec3,
    /// Whether the diffuse part holds light.
    pub lit: bool,
    /// The precisions of the diffuse and specular parts ([`LocalFit::precision`]): 1 for a
    /// pixel's sampled means, the fit's after a pass (else unchanged). Above degree 0 the
    /// columns' pass weights each row by them.
    pub precision: [f32; 2],
}

impl Filtered {
    /// The diffuse mean at the unit normal `n`, clamped at 0.
    pub fn diffuse_at(&self, n: Vec3) -> Vec3 {
        (self.vector[0] * n.x + self.vector[1] * n.y + self.vector[2] * n.z).max(Vec3::ZERO)
    }

    /// The sampled means of a pixel of shading normal `n` as the first pass takes them: `V =
    /// M₀ n + (8/3) M₁ₜ` ([`TANGENT_SCALE`]) with `irradiance_vector`, else `M₀ n`.
    pub fn from_means(means: &Means, n: Vec3, irradiance_vector: bool) -> Self {
        let tangent = if irradiance_vector {
            TANGENT_SCALE
        } else {
            0.0
        };
        Self {
            vector: std::array::from_fn(|k| means.diffuse * n[k] + means.tangent[k] * tangent),
            specular: means.specular,
            lit: means.lit,
            precision: [1.0; 2],
        }
    }
}

/// The two passes of `aaf_filter.comp` (rows, then columns) over a `width`-wide image, before
/// the receivers' weights: per pixel, the filtered irradiance vector (to evaluate at the
/// pixel's shading normal) and specular mean. Above degree 0, the columns' pass weights each
/// row by the precision of its row fit ([`LocalFit`]'s precision).
pub fn filter_cpu(
    texels: &[FilterTexel],
    width: usize,
    footprint: [f32; 2],
    params: &AafParams,
) -> Vec<Filtered> {
    let sampled: Vec<Filtered> = texels
        .iter()
        .map(|t| Filtered::from_means(&t.means, t.normal.normalize(), params.irradiance_vector))
        .collect();
    let rows = filter_axis(texels, &sampled, width, footprint, params, [1, 0]);
    filter_axis(texels, &rows, width, footprint, params, [0, 1])
}

/// One separable pass along `axis` ([1, 0]: rows, [0, 1]: columns) of `values`.
fn filter_axis(
    texels: &[FilterTexel],
    values: &[Filtered],
    width: usize,
    footprint: [f32; 2],
    params: &AafParams,
    axis: [i64; 2],
) -> Vec<Filtered> {
    let height = texels.len() / width.max(1);
    let cos_threshold = params.normal_threshold_degrees.to_radians().cos();
    // The columns' pass above degree 0 weights each row by its precision; the rows' pass, and
    // the paper's gaussian, weight every value alike.
    let weighted = axis[1] == 1 && params.filter_degree > 0;
    // Neighbour q's irradiance vector as the centre of normal n takes it: without the
    // irradiance vector, q's scalar mean along n.
    let vector = |q: &Filtered, nq: Vec3, n: Vec3| -> [f32; 9] {
        let v = if params.irradiance_vector {
            q.vector
        } else {
            let mean = q.vector[0] * nq.x + q.vector[1] * nq.y + q.vector[2] * nq.z;
            std::array::from_fn(|k| mean * n[k])
        };
        std::array::from_fn(|i| v[i / 3][i % 3])
    };
    (0..texels.len())
        .map(|p| {
            let centre = &texels[p];
            let (x, y) = ((p % width) as i64, (p / width) as i64);
            if !params.filter || centre.position.w == 0.0 || centre.beta <= 0.0 {
                return values[p];
            }
            let n = centre.normal.normalize();
            let ng = centre.geometric_normal.normalize();
            let d = centre.position.w * footprint[0] + footprint[1];
            let radius = MAX_RADIUS.min((2.0 * centre.beta / d).ceil() as u32) as i64;
            let (mut diffuse, mut specular) = (LocalFit::<9>::default(), LocalFit::<3>::default());
            for k in -radius..=radius {
                let (qx, qy) = (x + axis[0] * k, y + axis[1] * k);
                if qx < 0 || qy < 0 || qx >= width as i64 || qy >= height as i64 {
                    continue;
                }
                let qi = qy as usize * width + qx as usize;
                let q = &texels[qi];
                if q.position.w == 0.0 {
                    continue;
                }
                let offset = q.position.truncate() - centre.position.truncate();
                if ng.dot(offset).abs() > PLANE_TOLERANCE * d {
                    continue;
                }
                let nq = q.normal.normalize();
                let shading_close = n.dot(nq) >= cos_threshold;
                let diffuse_close = if params.irradiance_vector {
                    ng.dot(q.geometric_normal.normalize()) >= cos_threshold
                } else {
                    shading_close
                };
                let specular_close =
                    shading_close && (q.roughness - centre.roughness).abs() <= ROUGHNESS_TOLERANCE;
                let u = (k as f32).signum() * offset.length() / centre.beta;
                let [diffuse_precision, specular_precision] = if weighted {
                    values[qi].precision
                } else {
                    [1.0; 2]
                };
                if diffuse_close && values[qi].lit {
                    diffuse.add(u, vector(&values[qi], nq, n), diffuse_precision);
                }
                if specular_close {
                    specular.add(u, values[qi].specular.to_array(), specular_precision);
                }
            }
            let own = vector(&values[p], n, n);
            let degree = params.filter_degree;
            let v = diffuse.value(degree).unwrap_or(own);
            Filtered {
                vector: std::array::from_fn(|k| Vec3::new(v[3 * k], v[3 * k + 1], v[3 * k + 2])),
                specular: specular
                    .value(degree)
                    .map_or(values[p].specular, Vec3::from_array),
                lit: values[p].lit || diffuse.has_neighbours(),
                precision: [
                    diffuse.precision(degree).unwrap_or(values[p].precision[0]),
                    specular.precision(degree).unwrap_or(values[p].precision[1]),
                ],
            }
        })
        .collect()
}
