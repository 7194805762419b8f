//! The `hvl_gather.comp` variants and the checks of [`HvlParams`] before the cache and the
//! gather run.

use super::{
    CACHE_COUNT, CONV_BANDS, Distribution, EMISSION_BANDS, GATHER_COUNT, GatherPath, HvlError,
    HvlGrid, HvlParams, RADIUS_SCALE, RadiusHeuristic, shadows,
};
use crate::gpu::ShaderDesc;
use crate::shaders;

/// The `hvl_gather.comp` variants: `(path, conv_bands, shadowing, shader)` for every path,
/// every band count of [`CONV_BANDS`] and every [`shadows::Shadowing`] (variants `full_cN`,
/// `zonal_cN`, then `_vis` and `_shadows` after them).
pub fn gather_variants() -> Vec<(GatherPath, u32, shadows::Shadowing, &'static ShaderDesc)> {
    use shadows::Shadowing;
    let mut variants = Vec::new();
    for (path, name) in [(GatherPath::Full, "full"), (GatherPath::Zonal, "zonal")] {
        for shadowing in [Shadowing::None, Shadowing::EveryHvl, Shadowing::Sampled] {
            for bands in CONV_BANDS {
                let suffix = shadowing.suffix();
                if let Some(shader) =
                    shaders::get(&format!("hvl_gather.comp:{name}_c{bands}{suffix}"))
                {
                    variants.push((path, bands, shadowing, shader));
                }
            }
        }
    }
    variants
}

/// The gather shader for `params` (its path, convolution bands and shadowing), or
/// [`HvlError::Variant`].
pub fn gather_shader(params: &HvlParams) -> Result<&'static ShaderDesc, HvlError> {
    let variants = gather_variants();
    let shadowing = shadows::Shadowing::of(params.visibility, &params.shadows());
    variants
        .iter()
        .find(|v| v.0 == params.path && v.1 == params.conv_bands && v.2 == shadowing)
        .map(|v| v.3)
        .ok_or_else(|| HvlError::Variant {
            conv_bands: params.conv_bands,
            path: params.path,
            available: variants
                .iter()
                .map(|v| format!("{:?} c{}{}", v.0, v.1, v.2.suffix()))
                .collect::<Vec<_>>()
                .join(", "),
        })
}

impl HvlParams {
    /// Checks the parameters for the cache built from an RSM of side `rsm_size`; returns the
    /// cells of the RSM, one per HVL.
    pub fn validate_cache(&self, rsm_size: u32) -> Result<HvlGrid, HvlError> {
        let grid = HvlGrid::new(self.count, rsm_size)
            .filter(|_| CACHE_COUNT.contains(&self.count))
            .ok_or(HvlError::Count {
                count: self.count,
                rsm_size,
            })?;
        if self.distribution == Distribution::Flux && self.radius == RadiusHeuristic::R1 {
            return Err(HvlError::R1NeedsGrid);
        }
        if !RADIUS_SCALE.contains(&self.radius_scale) {
            return Err(HvlError::OutOfRange {
                name: "radius_scale",
                value: f64::from(self.radius_scale),
                expected: format!("{RADIUS_SCALE:?} (paper 003 §5.3)"),
            });
        }
        Ok(grid)
    }

    /// Checks the band counts and the HVL count of the gather (`1..=10 000` records, bands as
    /// documented on the fields) and returns the matching shader variant.
    pub fn validate_gather(&self) -> Result<&'static ShaderDesc, HvlError> {
        if !GATHER_COUNT.contains(&self.count) {
            return Err(HvlError::OutOfRange {
                name: "count",
                value: f64::from(self.count),
                expected: format!("{GATHER_COUNT:?} HVLs"),
            });
        }
        if !CONV_BANDS.contains(&self.conv_bands) {
            return Err(HvlError::OutOfRange {
                name: "conv_bands",
                value: f64::from(self.conv_bands),
                expected: format!("{CONV_BANDS:?}"),
            });
        }
        if self.visibility {
            self.validate_shadows()?;
        }
        if !(self.near_radius.is_finite() && self.near_radius >= 0.0) {
            return Err(HvlError::OutOfRange {
                name: "near_radius",
                value: f64::from(self.near_radius),
                expected: "a finite distance ≥ 0 (0: no near field)".to_owned(),
            });
        }
        if !EMISSION_BANDS.contains(&self.emission_bands) || self.emission_bands > self.conv_bands {
            return Err(HvlError::OutOfRange {
                name: "emission_bands",
                value: f64::from(self.emission_bands),
                expected: format!("{EMISSION_BANDS:?} and at most conv_bands"),
            });
        }
        gather_shader(self)
    }
}

impl HvlParams {
    /// Checks the shadow sampling: rays and filter radius in range.
    fn validate_shadows(&self) -> Result<(), HvlError> {
        let s = self.shadows();
        for (name, value, range) in [
            ("shadow_rays", s.rays, shadows::RAYS_RANGE),
            (
                "shadow_filter_radius",
                s.filter_radius,
                shadows::FILTER_RADIUS_RANGE,
            ),
        ] {
            if !range.contains(&value) {
                return Err(HvlError::OutOfRange {
                    name,
                    value: f64::from(value),
                    expected: format!("{range:?}"),
                });
            }
        }
        Ok(())
    }
}
