//! [`Settings::validate`]: every setting against its range, each range one named constant
//! (the pass that owns the parameter owns its range).

use std::fmt;
use std::ops::RangeInclusive;

use super::{GiTechnique, Settings, SettingsError};
use crate::capture::tonemap;
use crate::gpu_scene::environment_sh;
use crate::passes::{
    aaf, accumulate, amortise, composite, cubes, exposure, hvl, igi, proxy, receivers, rsm,
    shadows, sky, specular, upsample,
};

/// Output sides in pixels.
pub const EXTENT: RangeInclusive<u32> = 1..=16384;
/// Frames of one render.
pub const FRAMES: RangeInclusive<u32> = 1..=100_000;
/// Scene times in seconds.
pub const TIME: RangeInclusive<f32> = 0.0..=100_000.0;

/// Rejects `value` outside `range` (NaN included) with the field's name. Values print with
/// `Debug` so that floats keep their decimal point (`1.0..=2.0`).
fn check<T: PartialOrd + fmt::Debug>(
    field: &'static str,
    value: T,
    range: &RangeInclusive<T>,
) -> Result<(), SettingsError> {
    if range.contains(&value) {
        Ok(())
    } else {
        Err(SettingsError::OutOfRange {
            field,
            value: format!("{value:?}"),
            allowed: format!("{:?}..={:?}", range.start(), range.end()),
        })
    }
}

impl Settings {
    /// Checks every setting against its documented range.
    ///
    /// The error names the first offending field (dotted, as in the TOML file), its value and
    /// the allowed range.
    pub fn validate(&self) -> Result<(), SettingsError> {
        check("width", self.width, &EXTENT)?;
        check("height", self.height, &EXTENT)?;
        check("frames", self.frames, &FRAMES)?;
        check("time", self.time, &TIME)?;
        if !receivers::SCALES.contains(&self.receiver_scale) {
            return Err(SettingsError::OutOfRange {
                field: "receiver_scale",
                value: self.receiver_scale.to_string(),
                allowed: receivers::scale_list(),
            });
        }
        check("output.exposure", self.output.exposure, &tonemap::EXPOSURE)?;
        if self.output.ssaa != 0 {
            check("output.ssaa", self.output.ssaa, &composite::SSAA)?;
        }
        check(
            "output.adaptation",
            self.output.adaptation,
            &exposure::ADAPTATION_RANGE,
        )?;
        let ssaa = self.output.ssaa_for(self.width, self.height);
        let rendered = |side: u32| side.saturating_mul(ssaa);
        if !EXTENT.contains(&rendered(self.width)) || !EXTENT.contains(&rendered(self.height)) {
            return Err(SettingsError::OutOfRange {
                field: "output.ssaa",
                value: self.output.ssaa.to_string(),
                allowed: format!(
                    "at most {} for a {}×{} frame (the rendered size, ssaa × width and ssaa × height, must be within {:?})",
                    EXTENT.end() / self.width.max(self.height).max(1),
                    self.width,
                    self.height,
                    EXTENT
                ),
            });
        }
        check("hvl.count", self.hvl.count, &hvl::CACHE_COUNT)?;
        check(
            "hvl.radius_scale",
            self.hvl.radius_scale,
            &hvl::RADIUS_SCALE,
        )?;
        check(
            "hvl.convolution_bands",
            self.hvl.convolution_bands,
            &hvl::CONV_BANDS,
        )?;
        check(
            "hvl.emission_bands",
            self.hvl.emission_bands,
            &hvl::EMISSION_BANDS,
        )?;
        check("rsm.size", self.rsm.size, &rsm::SIZE)?;
        let rsm_texels = u64::from(self.rsm.size).pow(2);
        if u64::from(self.hvl.count) > rsm_texels {
            return Err(SettingsError::OutOfRange {
                field: "hvl.count",
                value: self.hvl.count.to_string(),
                allowed: format!(
                    "at most rsm.size² = {rsm_texels} (one RSM texel per HVL at least): raise rsm.size"
                ),
            });
        }
        check(
            "hvl.shadow_rays",
            self.hvl.shadow_rays,
            &hvl::shadows::RAYS_RANGE,
        )?;
        check(
            "hvl.shadow_filter_radius",
            self.hvl.shadow_filter_radius,
            &hvl::shadows::FILTER_RADIUS_RANGE,
        )?;
        check(
            "hvl.near_range",
            self.hvl.near_range,
            &hvl::near::RANGE_RANGE,
        )?;
        check("hvl.near_rays", self.hvl.near_rays, &hvl::near::RAYS_RANGE)?;
        check_slices("hvl.slices", self.hvl.slices)?;
        if self.hvl.emission_bands > self.hvl.convolution_bands {
            return Err(SettingsError::OutOfRange {
                field: "hvl.emission_bands",
                value: self.hvl.emission_bands.to_string(),
                allowed: format!(
                    "1..={} (at most hvl.convolution_bands)",
                    self.hvl.convolution_bands.min(*hvl::EMISSION_BANDS.end())
                ),
            });
        }
        if self.hvl.radius == hvl::RadiusHeuristic::R1
            && self.hvl.distribution == hvl::Distribution::Flux
        {
            return Err(SettingsError::OutOfRange {
                field: "hvl.radius",
                value: "r1".to_owned(),
                allowed: "r2 with hvl.distribution = \"flux\" (r1 takes its neighbours from the grid: set hvl.distribution = \"grid\")".to_owned(),
            });
        }
        check("shadow.size", self.shadow.size, &shadows::TILE_SIZE)?;
        check(
            "shadow.filter_radius",
            self.shadow.filter_radius,
            &shadows::FILTER_RADIUS,
        )?;
        check(
            "upsample.depth_epsilon",
            self.upsample.depth_epsilon,
            &upsample::DEPTH_SIGMA_RANGE,
        )?;
        check(
            "upsample.normal_power",
            self.upsample.normal_power,
            &upsample::NORMAL_POWER_RANGE,
        )?;
        check(
            "proxy.sh_order",
            self.proxy.sh_order,
            &environment_sh::ORDERS,
        )?;
        if self.proxy.expansion != 0.0 {
            check("proxy.expansion", self.proxy.expansion, &proxy::EXPANSION)?;
        }
        check(
            "proxy.indirect_expansion",
            self.proxy.indirect_expansion,
            &proxy::EXPANSION,
        )?;
        check("proxy.fit_count", self.proxy.fit_count, &proxy::FIT_COUNT)?;
        check_slices("proxy.slices", self.proxy.slices)?;
        self.validate_igi()?;
        self.validate_aaf()?;
        check(
            "history.frames",
            self.history.frames,
            &accumulate::MAX_FRAMES_RANGE,
        )?;
        check("history.clip", self.history.clip, &accumulate::CLIP_RANGE)?;
        check(
            "specular.samples",
            self.specular.samples,
            &specular::SAMPLES_RANGE,
        )?;
        check(
            "specular.limit",
            self.specular.limit,
            &specular::LIMIT_RANGE,
        )?;
        check("sky.rays", self.sky.rays, &sky::RAYS_RANGE)?;
        check("sky.range", self.sky.range, &sky::RANGE_RANGE)?;
        check(
            "sky.filter_radius",
            self.sky.filter_radius,
            &sky::FILTER_RADIUS_RANGE,
        )?;
        check("cubes.slices", self.cubes.slices, &cubes::SLICES_RANGE)?;
        check("cavity.rays", self.cavity.rays, &sky::RAYS_RANGE)?;
        check("cavity.range", self.cavity.range, &sky::CAVITY_RANGE_RANGE)?;
        Ok(())
    }

    /// The `[igi]` checks of [`Settings::validate`], and the combination rule: `igi` and `hvl`
    /// both compute the one-bounce indirect light of the primary light, so a frame takes one.
    fn validate_igi(&self) -> Result<(), SettingsError> {
        let i = &self.igi;
        check("igi.n", i.n, &igi::PATTERN)?;
        check("igi.m", i.m, &igi::PATTERN)?;
        check("igi.vpl_count", i.vpl_count, &igi::VPL_COUNT)?;
        check("igi.sh_order", i.sh_order, &igi::SH_ORDERS)?;
        check("igi.filter_radius", i.filter_radius, &igi::FILTER_RADIUS)?;
        check("igi.clamp_distance", i.clamp_distance, &igi::CLAMP_DISTANCE)?;
        check_slices("igi.slices", i.slices)?;
        check(
            "igi.depth_tolerance",
            i.depth_tolerance,
            &igi::DEPTH_TOLERANCE,
        )?;
        check(
            "igi.normal_threshold",
            i.normal_threshold,
            &igi::NORMAL_THRESHOLD,
        )?;
        let rsm_texels = u64::from(self.rsm.size).pow(2);
        if u64::from(i.vpl_count) > rsm_texels {
            return Err(SettingsError::OutOfRange {
                field: "igi.vpl_count",
                value: i.vpl_count.to_string(),
                allowed: format!(
                    "at most rsm.size² = {rsm_texels} (one RSM texel per VPL at least): raise rsm.size"
                ),
            });
        }
        let bounces = [GiTechnique::Hvl, GiTechnique::Igi, GiTechnique::Aaf]
            .iter()
            .filter(|&&t| self.gi.contains(t))
            .count();
        if bounces > 1 {
            return Err(SettingsError::GiList {
                list: self.gi.to_string(),
                reason: "`hvl`, `igi` and `aaf` each compute the indirect light of the punctual \
                         lights: choose one",
            });
        }
        if self.cubes.enabled
            && (self.gi.contains(GiTechnique::Igi) || self.gi.contains(GiTechnique::Aaf))
        {
            return Err(SettingsError::GiList {
                list: self.gi.to_string(),
                reason: "`cubes.enabled` replaces the receiver-resolution light of the dynamic \
                         objects; `igi` and `aaf` light every pixel at full resolution: use \
                         `hvl`, `proxy` or `none` with the cubes",
            });
        }
        Ok(())
    }

    /// The `[aaf]` checks of [`Settings::validate`].
    fn validate_aaf(&self) -> Result<(), SettingsError> {
        let a = &self.aaf;
        check("aaf.samples", a.samples, &aaf::FIRST_SAMPLES)?;
        check("aaf.mu", a.mu, &aaf::MU_RANGE)?;
        check("aaf.omega_h", a.omega_h, &aaf::OMEGA_H_RANGE)?;
        check("aaf.spp_min", a.spp_min, &aaf::SPP_MIN)?;
        check("aaf.spp_max", a.spp_max, &aaf::SPP_MAX)?;
        check("aaf.bounces", a.bounces, &aaf::BOUNCES)?;
        check(
            "aaf.filter_degree",
            a.filter_degree,
            &shine_sh::aaf::FILTER_DEGREES,
        )?;
        check_slices("aaf.slices", a.slices)
    }
}

/// An amortised technique's `slices`: one of [`amortise::SLICE_CHOICES`].
fn check_slices(field: &'static str, value: u32) -> Result<(), SettingsError> {
    if amortise::SLICE_CHOICES.contains(&value) {
        return Ok(());
    }
    Err(SettingsError::OutOfRange {
        field,
        value: value.to_string(),
        allowed: format!("{:?}", amortise::SLICE_CHOICES),
    })
}
