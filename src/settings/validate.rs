//! [`Settings::validate`]: every setting against the domain its declaration gives
//! (`#[setting(range = …)]`, src/declare.rs), then the rules that tie settings of different
//! sections together.

use std::ops::RangeInclusive;

use super::{GiTechnique, Settings, SettingsError};
use crate::declare::{OutOfRange, Section};

/// Output sides in pixels.
pub const EXTENT: RangeInclusive<u32> = 1..=16384;
/// Frames of one render.
pub const FRAMES: RangeInclusive<u32> = 1..=100_000;
/// Scene times in seconds.
pub const TIME: RangeInclusive<f32> = 0.0..=100_000.0;

impl Settings {
    /// Checks every setting against its declared domain, then the rules between sections.
    ///
    /// The error names the first offending field (dotted, as in the TOML file), its value and
    /// what is allowed.
    pub fn validate(&self) -> Result<(), SettingsError> {
        self.check_in("")?;
        self.check_rendered_size()?;
        self.check_rsm_counts()?;
        self.check_combinations()
    }

    /// The rendered frame (`ssaa` × the output) within [`EXTENT`].
    fn check_rendered_size(&self) -> Result<(), OutOfRange> {
        let ssaa = self.output.ssaa_for(self.width, self.height);
        let rendered = |side: u32| side.saturating_mul(ssaa);
        if EXTENT.contains(&rendered(self.width)) && EXTENT.contains(&rendered(self.height)) {
            return Ok(());
        }
        Err(OutOfRange {
            field: "output.ssaa".to_owned(),
            value: self.output.ssaa.to_string(),
            allowed: format!(
                "at most {} for a {}×{} frame (the rendered size, ssaa × width and ssaa × height, must be within {:?})",
                EXTENT.end() / self.width.max(self.height).max(1),
                self.width,
                self.height,
                EXTENT
            ),
        })
    }

    /// HVLs and VPLs: at least one RSM texel each.
    fn check_rsm_counts(&self) -> Result<(), OutOfRange> {
        let rsm_texels = u64::from(self.rsm.size).pow(2);
        for (field, count, what) in [
            ("hvl.count", self.hvl.count, "HVL"),
            ("igi.vpl_count", self.igi.vpl_count, "VPL"),
        ] {
            if u64::from(count) > rsm_texels {
                return Err(OutOfRange {
                    field: field.to_owned(),
                    value: count.to_string(),
                    allowed: format!(
                        "at most rsm.size² = {rsm_texels} (one RSM texel per {what} at least): raise rsm.size"
                    ),
                });
            }
        }
        Ok(())
    }

    /// The combination rules of the `gi` list: `igi`, `hvl` and `aaf` each compute the
    /// one-bounce indirect light of the punctual lights, so a frame takes one; the cubes
    /// replace receiver-resolution light only.
    fn check_combinations(&self) -> Result<(), SettingsError> {
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
}
