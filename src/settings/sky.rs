//! `[sky]`: the sky light of frames without proxies (`src/passes/sky.rs`).

use serde::{Deserialize, Serialize};

use crate::passes::sky::{CAVITY_RANGE, CAVITY_RAYS, SkyParams};

/// `[sky]`: the environment's diffuse light times each receiver's sky visibility and bent
/// normal (issue 16, item 7), in every frame without the proxies (which shadow the
/// environment themselves; `gi = none` included), when the scene has an environment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkySettings {
    /// Light the receivers by the sky. Default true.
    pub enabled: bool,
    /// Rays per receiver. Range 1..=1024, default 16.
    pub rays: u32,
    /// How far a ray looks for an occluder, in world units (0: unbounded, the sky's
    /// visibility; a short range gives cavity occlusion). Range 0.0..=1e6, default 0.
    pub range: f32,
    /// Look the irradiance up at the bent normal (the mean open direction); false: at the
    /// shading normal. Default true.
    pub bent_normal: bool,
    /// Radius in receivers of the joint bilateral filter of the sky's light (0: none).
    /// Range 0..=8, default 3.
    pub filter_radius: u32,
}

impl Default for SkySettings {
    /// The defaults of the sky pass ([`SkyParams::default`]).
    fn default() -> Self {
        let p = SkyParams::default();
        Self {
            enabled: true,
            rays: p.rays,
            range: p.range,
            bent_normal: p.bent_normal,
            filter_radius: p.filter_radius,
        }
    }
}

/// `[cavity]`: paper 001's cavity shading of HVL's unshadowed indirect light (issue 18): the
/// light times the share of short cosine-weighted rays that meet nothing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CavitySettings {
    /// Darken HVL's light by its receivers' cavity occlusion. Default false. Meant for HVLs
    /// without shadows (`hvl.visibility = false`): shadowed HVLs already lose that light.
    pub enabled: bool,
    /// Rays per receiver. Range 1..=1024, default 8.
    pub rays: u32,
    /// Reach of the rays as a fraction of the scene's largest side. Range 1e-4..=1.0,
    /// default 0.02.
    pub range: f32,
}

impl Default for CavitySettings {
    /// Off, with the cavity pass's default rays and reach.
    fn default() -> Self {
        Self {
            enabled: false,
            rays: CAVITY_RAYS,
            range: CAVITY_RANGE,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::settings::Settings;

    #[test]
    fn the_sky_filter_radius_is_checked() {
        let message = Settings::from_toml_str("[sky]\nfilter_radius = 9")
            .unwrap_err()
            .to_string();
        assert!(message.contains("sky.filter_radius"), "{message}");
    }
}
