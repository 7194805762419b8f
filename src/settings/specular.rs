//! `[specular]`: the traced specular reflections (`src/passes/specular.rs`).

use serde::{Deserialize, Serialize};

use crate::passes::specular::SpecularParams;

/// `[specular]`: reflection rays for the sharp part of every glossy lobe (issue 21, item 3).
/// Runs in every frame with a GI technique; the techniques keep the lobes rougher than `limit`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpecularSettings {
    /// Trace the reflections (off: the techniques' SH glossy term takes every lobe, and the
    /// proxies none). Default true.
    pub enabled: bool,
    /// Reflection rays per pixel and frame. Range 1..=256, default 2.
    pub samples: u32,
    /// Roughness above which a lobe is left to the SH techniques (faded over the 0.1 below
    /// it). Range 0.0..=1.0, default 0.5.
    pub limit: f32,
}

impl Default for SpecularSettings {
    /// The defaults of the specular pass ([`SpecularParams::default`]).
    fn default() -> Self {
        let p = SpecularParams::default();
        Self {
            enabled: true,
            samples: p.samples,
            limit: p.limit,
        }
    }
}

impl SpecularSettings {
    /// The roughness limit of the traced pass in a frame with indirect light: `limit` when the
    /// pass is enabled, 0 (no pass) otherwise. The GI techniques leave the lobes below it out.
    pub fn traced_limit(&self) -> f32 {
        if self.enabled {
            self.limit.max(0.0)
        } else {
            0.0
        }
    }
}
