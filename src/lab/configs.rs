//! The lab's configurations: the default space from the techniques' declarations, or a TOML
//! file; and the settings each one renders with.
//!
//! The default space is one configuration per technique at its defaults, plus one per value
//! that a setting of the technique takes at the ends and middle of its declared span
//! ([`ParamSpec::lab_values`](crate::declare::ParamSpec::lab_values)), one setting at a time.
//! A configurations file lists them instead:
//!
//! ```toml
//! [[config]]
//! label = "hvl 100"                  # optional: the settings joined by default
//! set = { gi = "hvl", "hvl.count" = 100, "hvl.near_range" = 0.0 }
//! ```
//!
//! A key that is no setting, or a value out of its domain, is refused with the file and line.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

use super::{LabConfig, LabError, LabSetup};
use crate::declare::Section;
use crate::settings::{GiTechnique, Settings, SettingsError};

/// The techniques the default space covers, in order.
pub const TECHNIQUES: [GiTechnique; 4] = [
    GiTechnique::Hvl,
    GiTechnique::Igi,
    GiTechnique::Aaf,
    GiTechnique::Proxy,
];

/// The settings every lab frame starts from: the setup's size, no supersampling, linear
/// output. The whole frame is judged, direct and indirect light, as the user sees it: the
/// raster frame carries the sky's light in its indirect image while the truth counts it as
/// direct, so the two parts alone do not compare.
pub fn base_settings(setup: &LabSetup) -> Settings {
    let mut s = Settings {
        width: setup.extent[0],
        height: setup.extent[1],
        time: setup.time,
        ..Settings::default()
    };
    s.output.ssaa = 1;
    s.output.auto_exposure = false;
    s
}

/// The settings `config` renders with over `base`, validated.
pub fn settings_of(base: &Settings, config: &LabConfig) -> Result<Settings, SettingsError> {
    let mut s = base.clone();
    for (key, value) in &config.set {
        s.set(key, value)?;
    }
    s.validate()?;
    Ok(s)
}

/// The default space: each technique at its defaults, then each of its cost or quality
/// settings at its lab values, one at a time. Combinations the settings refuse (`hvl.radius =
/// r1` with flux-placed HVLs) are left out.
pub fn default_space(setup: &LabSetup) -> Vec<LabConfig> {
    let base = base_settings(setup);
    let specs = Settings::specs();
    let mut out = Vec::new();
    for technique in TECHNIQUES {
        let name = technique.name();
        let gi = ("gi".to_owned(), name.to_owned());
        out.push(LabConfig {
            label: name.to_owned(),
            set: vec![gi.clone()],
        });
        let prefix = format!("{name}.");
        let varied = specs
            .iter()
            .filter(|s| s.key.starts_with(&prefix) && s.affects != crate::declare::Affects::Output);
        for spec in varied {
            for value in spec.lab_values() {
                let config = LabConfig {
                    label: format!(
                        "{name} {}={}",
                        &spec.key[prefix.len()..],
                        value.trim_matches('"')
                    ),
                    set: vec![gi.clone(), (spec.key.clone(), value)],
                };
                if settings_of(&base, &config).is_ok() {
                    out.push(config);
                }
            }
        }
    }
    out
}

/// A configurations file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ConfigsFile {
    config: Vec<Entry>,
}

/// One `[[config]]` of the file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    label: Option<toml::Spanned<String>>,
    set: toml::Spanned<BTreeMap<String, toml::Spanned<toml::Value>>>,
}

/// The 1-based line of byte `offset` in `text`.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// Reads a configurations file, checking each configuration's settings over the lab's base:
/// an unknown key, a value out of its domain, a repeated label or an empty list is refused
/// with the file and line.
pub fn load(path: &Path, setup: &LabSetup) -> Result<Vec<LabConfig>, LabError> {
    let text = std::fs::read_to_string(path).map_err(|source| LabError::Io {
        path: path.to_owned(),
        source,
    })?;
    parse(&text, &path.display().to_string(), setup)
}

/// [`load`] on text, `origin` naming it in errors.
pub fn parse(text: &str, origin: &str, setup: &LabSetup) -> Result<Vec<LabConfig>, LabError> {
    let at = |offset: usize, what: String| {
        LabError::Invalid(format!("{origin}:{}: {what}", line_of(text, offset)))
    };
    let file: ConfigsFile = toml::from_str(text).map_err(|e| {
        let offset = e.span().map_or(0, |s| s.start);
        at(offset, e.message().to_owned())
    })?;
    if file.config.is_empty() {
        return Err(LabError::Invalid(format!(
            "{origin}: no [[config]] in the file"
        )));
    }
    let base = base_settings(setup);
    let mut out: Vec<LabConfig> = Vec::new();
    for entry in file.config {
        let entry_offset = entry.set.span().start;
        let mut settings = base.clone();
        let mut set = Vec::new();
        for (key, value) in entry.set.get_ref() {
            let text_value = match value.get_ref() {
                toml::Value::String(s) => s.clone(),
                other => other.to_string(),
            };
            settings
                .set(key, &text_value)
                .map_err(|e| at(value.span().start, e.to_string()))?;
            set.push((key.clone(), text_value));
        }
        if let Err(e) = settings.validate() {
            let message = e.to_string();
            let offset = entry
                .set
                .get_ref()
                .iter()
                .find(|(k, _)| message.contains(&format!("`{k}`")))
                .map_or(entry_offset, |(_, v)| v.span().start);
            return Err(at(offset, message));
        }
        let label = match &entry.label {
            Some(l) => l.get_ref().clone(),
            None => set
                .iter()
                .map(|(k, v)| format!("{k}={}", v.trim_matches('"')))
                .collect::<Vec<_>>()
                .join(" "),
        };
        if out.iter().any(|c| c.label == label) {
            let offset = entry
                .label
                .as_ref()
                .map_or(entry_offset, |l| l.span().start);
            return Err(at(offset, format!("label `{label}` is used twice")));
        }
        out.push(LabConfig { label, set });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_space_covers_every_technique_and_validates() {
        let setup = LabSetup::default();
        let space = default_space(&setup);
        for t in TECHNIQUES {
            assert!(space.iter().any(|c| c.label == t.name()), "{}", t.name());
        }
        assert!(space.len() > 40, "{}", space.len());
        let base = base_settings(&setup);
        for c in &space {
            settings_of(&base, c).unwrap();
        }
        // The lab span, not the domain: no 10 000 HVLs.
        assert!(space.iter().any(|c| c.label == "hvl count=1600"));
        assert!(!space.iter().any(|c| c.label == "hvl count=10000"));
        // The refused combination is left out, its valid neighbours are in.
        assert!(!space.iter().any(|c| c.label == "hvl radius=r1"));
        assert!(space.iter().any(|c| c.label == "hvl distribution=grid"));
    }

    #[test]
    fn a_file_lists_configurations() {
        let text = "[[config]]\nset = { gi = \"hvl\", \"hvl.count\" = 100 }\n\n\
                    [[config]]\nlabel = \"igi 2x2\"\nset = { gi = \"igi\", \"igi.n\" = 2, \"igi.m\" = 2 }\n";
        let configs = parse(text, "c.toml", &LabSetup::default()).unwrap();
        assert_eq!(configs.len(), 2);
        assert_eq!(configs[0].label, "gi=hvl hvl.count=100");
        assert_eq!(configs[0].get("hvl.count"), Some("100"));
        assert_eq!(configs[1].label, "igi 2x2");
        assert_eq!(configs[1].technique(), "igi");
    }

    #[test]
    fn bad_files_name_the_file_and_line() {
        let setup = LabSetup::default();
        let cases = [
            // an unknown key on line 3
            (
                "[[config]]\nlabel = \"a\"\nset = { gi = \"hvl\", \"hvl.cuont\" = 5 }\n",
                "c.toml:3:",
                "cuont",
            ),
            // a value out of range on line 4
            (
                "[[config]]\nset = { gi = \"hvl\" }\n[[config]]\nset = { \"hvl.count\" = 5 }\n",
                "c.toml:4:",
                "hvl.count",
            ),
            // a repeated label on line 4
            (
                "[[config]]\nlabel = \"x\"\nset = { gi = \"hvl\" }\n[[config]]\nlabel = \"x\"\nset = { gi = \"igi\" }\n",
                "c.toml:5:",
                "twice",
            ),
            // a malformed file
            ("[[config]]\nset = { gi = \n", "c.toml:2:", ""),
            // a section the file does not know
            ("[[confg]]\nset = {}\n", "c.toml:1:", "confg"),
        ];
        for (text, place, what) in cases {
            let message = parse(text, "c.toml", &setup).unwrap_err().to_string();
            assert!(message.starts_with(place), "{text:?}: {message}");
            assert!(message.contains(what), "{text:?}: {message}");
        }
        let message = parse("config = []\n", "c.toml", &setup)
            .unwrap_err()
            .to_string();
        assert!(message.contains("no [[config]]"), "{message}");
    }
}
