//! The environment light projected to SH (paper 002 §3: `L` and `L̃ = L ⋆ g_cos`).
//!
//! The environment is evaluated only through [`shine_scene::environment::Environment::radiance`], whatever
//! it holds (procedural sky or equirectangular map), and projected per colour channel by the
//! Gauss–Legendre × uniform-φ quadrature of shine-sh ([`SphereQuadrature::project`]) with
//! [`PROJECTION_NODES_Z`] × [`PROJECTION_NODES_PHI`] nodes: exact for band-limited functions up
//! to degree 127 in φ, far beyond order 6; a map's higher frequencies are integrated, not
//! aliased into the 36 coefficients, as long as they are smoother than the node spacing
//! (≈ 1.4°).

use shine_scene::environment::Environment;
use shine_sh::ShError;
use shine_sh::kernels::{clamped_cosine_zh, convolve};
use shine_sh::quadrature::SphereQuadrature;

/// Gauss–Legendre nodes in `z = cos θ` of the projection.
pub const PROJECTION_NODES_Z: usize = 128;
/// Uniform nodes in φ of the projection.
pub const PROJECTION_NODES_PHI: usize = 256;
/// SH orders (bands) the projection accepts: paper 002 uses 3 and 4; shine goes to 6.
pub const ORDERS: std::ops::RangeInclusive<u32> = 3..=6;

/// The environment's radiance `L` and diffuse irradiance `L̃` as SH vectors, per channel.
#[derive(Debug, Clone, PartialEq)]
pub struct EnvironmentSh {
    bands: usize,
    /// `L` per channel (r, g, b), plain projections (`bands²` coefficients each).
    pub radiance: [Vec<f32>; 3],
    /// `L̃ = L ⋆ max(0, cos)` per channel: evaluated at a normal it is the unshadowed
    /// irradiance (paper 002 §3 "Shading in SH").
    pub irradiance: [Vec<f32>; 3],
}

impl EnvironmentSh {
    /// Projects `environment` to `bands` bands (3..=6).
    pub fn project(environment: &Environment, bands: usize) -> Result<Self, ShError> {
        if !u32::try_from(bands).is_ok_and(|b| ORDERS.contains(&b)) {
            return Err(ShError::InvalidBands { bands });
        }
        let quadrature = SphereQuadrature::new(PROJECTION_NODES_Z, PROJECTION_NODES_PHI);
        let channel = |c: usize| {
            quadrature.project(bands, |d| {
                f64::from(environment.radiance(d.as_vec3()).to_array()[c])
            })
        };
        let radiance = [channel(0)?, channel(1)?, channel(2)?];
        let cosine = clamped_cosine_zh(bands)?;
        let irradiance = [
            convolve(&radiance[0], &cosine)?,
            convolve(&radiance[1], &cosine)?,
            convolve(&radiance[2], &cosine)?,
        ];
        Ok(Self {
            bands,
            radiance,
            irradiance,
        })
    }

    /// Band count.
    pub fn bands(&self) -> usize {
        self.bands
    }

    /// The GPU buffer `environment` of the proxy passes: `L` r, g, b then `L̃` r, g, b,
    /// `bands²` floats each.
    pub fn gpu_data(&self) -> Vec<f32> {
        self.radiance
            .iter()
            .chain(&self.irradiance)
            .flat_map(|c| c.iter().copied())
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn constant(l: f32) -> Environment {
        Environment {
            zenith: Vec3::splat(l),
            horizon: Vec3::splat(l),
            ground: Vec3::splat(l),
            intensity: 1.0,
            map: None,
        }
    }

    /// A constant environment projects to its DC term only: `L √(4π)`; its irradiance is `π L`
    /// at every normal.
    #[test]
    fn constant_environment_is_dc_only() {
        let l = 0.7;
        let sh = EnvironmentSh::project(&constant(l), 4).unwrap();
        let sqrt_4pi = (4.0 * std::f32::consts::PI).sqrt();
        for c in 0..3 {
            assert!((sh.radiance[c][0] - l * sqrt_4pi).abs() < 1e-5);
            assert!(sh.radiance[c][1..].iter().all(|x| x.abs() < 1e-5));
            let e =
                shine_sh::basis::evaluate(&sh.irradiance[c], Vec3::new(0.3, 0.8, -0.2)).unwrap();
            assert!((e - std::f32::consts::PI * l).abs() < 1e-4, "{e}");
        }
        assert!(EnvironmentSh::project(&constant(l), 7).is_err());
        assert_eq!(sh.gpu_data().len(), 6 * 16);
    }

    /// The projection of the sky reconstructs it within 10% away from the horizon (the sky's
    /// `sqrt(|y|)` kink at the horizon rings at order 6: 14% low there).
    #[test]
    fn sky_reconstructs() {
        let scene = shine_scene::Scene::builtin("spheres").unwrap();
        let sky = scene.environment.unwrap();
        let sh = EnvironmentSh::project(&sky, 6).unwrap();
        for d in [Vec3::Y, -Vec3::Y, Vec3::new(0.3, 0.8, -0.5).normalize()] {
            let want = sky.radiance(d);
            let got = shine_sh::basis::evaluate(&sh.radiance[2], d).unwrap();
            assert!(
                (got - want.z).abs() < 0.1 * want.z.max(0.1),
                "{d}: {got} vs {want}"
            );
        }
    }
}
