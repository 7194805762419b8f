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
        }
    }
}
