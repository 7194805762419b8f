//! `[cubes]`: paper 001's tiny environment cubes for the dynamic objects
//! (`src/passes/cubes.rs`).

use serde::{Deserialize, Serialize};

use crate::passes::cubes::{CubeLookup, CubeParams};

/// `[cubes]`: one 6×6×6 cube of incoming light per dynamic object (a node with proxies),
/// filled by rays and smoothed as paper 001 does; the object's receivers take their indirect
/// light from it instead of from the frame's technique (issue 18, item 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CubeSettings {
    /// Light the dynamic objects from their cubes. Default false.
    pub enabled: bool,
    /// How a receiver reads its cube: "normal" (the smoothing sum at the normal, default) or
    /// "texel" (the smoothed texel holding the normal, the paper's).
    pub lookup: CubeLookup,
    /// Weight the smoothing by each texel's solid angle (false: the paper's plain sum).
    /// Default true.
    pub solid_angle: bool,
    /// Write 1 at the receivers the cubes light and 0 elsewhere, instead of light (see with
    /// `output.component = indirect`). Default false.
    pub mask: bool,
    /// Refresh one cube in `slices` per frame, in turn, plus at once those of objects that move
    /// (and their neighbours) and all of them when a light changes (paper 001: "update one
    /// object at the time"). Range 1..=16, default 1 (every cube every frame).
    pub slices: u32,
}

impl Default for CubeSettings {
    /// Off, with the passes' defaults ([`CubeParams::default`]).
    fn default() -> Self {
        let p = CubeParams::default();
        Self {
            enabled: false,
            lookup: p.lookup,
            solid_angle: p.solid_angle,
            mask: p.mask,
            slices: p.slices,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::settings::Settings;

    #[test]
    fn cubes_are_refused_with_full_resolution_techniques() {
        for gi in ["igi", "aaf", "igi,proxy"] {
            let message =
                Settings::from_toml_str(&format!("gi = \"{gi}\"\n[cubes]\nenabled = true"))
                    .unwrap_err()
                    .to_string();
            assert!(message.contains("cubes.enabled"), "{gi}: {message}");
        }
        for gi in ["hvl", "proxy", "hvl,proxy", "none"] {
            let toml = format!("gi = \"{gi}\"\n[cubes]\nenabled = true\nlookup = \"texel\"");
            let settings = Settings::from_toml_str(&toml).unwrap();
            assert!(settings.cubes.enabled, "{gi}");
        }
    }
}
