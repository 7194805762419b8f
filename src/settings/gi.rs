//! The `gi` setting: which indirect-light techniques a frame combines.

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::fmt;
use std::str::FromStr;

use super::SettingsError;
use crate::choice::UnknownChoice;

crate::choice::named_choice! {
    /// One indirect-light technique that shine implements today.
    pub enum GiTechnique ("GI technique") {
        /// Harmonics Virtual Lights (paper 003).
        Hvl = "hvl",
        /// Instant GI with interleaved sampling and SH-filtered incoming radiance (paper 000).
        Igi = "igi",
        /// Sphere proxies under the environment light (paper 002): proxy-shadowed environment
        /// plus proxy indirect light.
        Proxy = "proxy",
        /// Axis-aligned filtering of path-traced indirect light (paper 004).
        Aaf = "aaf",
    }
}

/// The name of the empty technique list: direct light only.
const NO_GI: &str = "none";

/// The set of GI techniques a frame combines, written `hvl`, `none`, `proxy` or `hvl,proxy`.
///
/// `hvl,proxy` adds both indirect terms at receiver resolution before one upsample: the HVL
/// indirect light of the primary light and the proxy-shadowed environment plus proxy indirect
/// light (paper 002 pairs them the same way). Without `proxy` the environment lights nothing
/// (direct light and HVL only).
///
/// `none` (the empty list) renders direct light only. Order is kept as given; each technique
/// appears at most once.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct GiTechniques(Vec<GiTechnique>);

impl GiTechniques {
    /// Direct light only.
    pub fn none() -> Self {
        Self(Vec::new())
    }

    /// The techniques, in the order given.
    pub fn techniques(&self) -> &[GiTechnique] {
        &self.0
    }

    /// Whether `technique` is part of the frame.
    pub fn contains(&self, technique: GiTechnique) -> bool {
        self.0.contains(&technique)
    }

    /// Whether the frame has no indirect light at all.
    pub fn is_none(&self) -> bool {
        self.0.is_empty()
    }
}

impl Default for GiTechniques {
    /// `hvl`, the technique of issue 6.
    fn default() -> Self {
        Self(vec![GiTechnique::Hvl])
    }
}

impl FromStr for GiTechniques {
    type Err = SettingsError;

    fn from_str(list: &str) -> Result<Self, SettingsError> {
        let invalid = |reason| SettingsError::GiList {
            list: list.to_owned(),
            reason,
        };
        let names: Vec<&str> = list.split(',').map(str::trim).collect();
        if names == [NO_GI] {
            return Ok(Self::none());
        }
        let mut techniques = Vec::with_capacity(names.len());
        for name in names {
            if name.is_empty() {
                return Err(invalid("empty technique name (write e.g. `hvl` or `none`)"));
            }
            if name == NO_GI {
                return Err(invalid("`none` cannot be combined with other techniques"));
            }
            let technique = name.parse::<GiTechnique>().map_err(|_| UnknownChoice {
                what: "GI technique",
                name: name.to_owned(),
                known: known_gi(),
            })?;
            if techniques.contains(&technique) {
                return Err(invalid("a technique is listed twice"));
            }
            techniques.push(technique);
        }
        Ok(Self(techniques))
    }
}

/// Every technique name, `none` included.
fn known_gi() -> String {
    let mut names: Vec<&str> = GiTechnique::ALL.iter().map(|t| t.name()).collect();
    names.push(NO_GI);
    names.join(", ")
}

impl fmt::Display for GiTechniques {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0.is_empty() {
            return f.write_str(NO_GI);
        }
        let names: Vec<&str> = self.0.iter().map(|t| t.name()).collect();
        f.write_str(&names.join(","))
    }
}

impl Serialize for GiTechniques {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for GiTechniques {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let text = String::deserialize(d)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

impl crate::declare::SettingValue for GiTechniques {
    fn domain(&self) -> crate::declare::Domain {
        crate::declare::Domain::Text
    }
}
