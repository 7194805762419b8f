//! Settings in and out: TOML text and files, and dotted-key overrides from the command line.

use std::path::Path;

use super::{Settings, SettingsError};

impl Settings {
    /// Parses settings from TOML text over the defaults, then validates them.
    ///
    /// Unknown settings and wrongly typed values are errors (with line and column).
    pub fn from_toml_str(text: &str) -> Result<Self, SettingsError> {
        Self::parse(text, None)
    }

    /// Reads a TOML settings file over the defaults, then validates it.
    pub fn load(path: &Path) -> Result<Self, SettingsError> {
        let text = std::fs::read_to_string(path).map_err(|source| SettingsError::Read {
            path: path.to_owned(),
            source,
        })?;
        Self::parse(&text, Some(path))
    }

    /// Parses and validates `text`, naming `path` in errors.
    fn parse(text: &str, path: Option<&Path>) -> Result<Self, SettingsError> {
        let settings: Self = toml::from_str(text).map_err(|e| SettingsError::Parse {
            path: path.map(Path::to_owned),
            message: e.to_string(),
        })?;
        settings.validate()?;
        Ok(settings)
    }

    /// The settings as a TOML document that [`Settings::from_toml_str`] reads back unchanged.
    pub fn to_toml_string(&self) -> Result<String, toml::ser::Error> {
        toml::to_string(self)
    }

    /// Overrides one setting by its dotted TOML key (`width`, `hvl.count`, `output.tonemap`)
    /// with a value written as in TOML (`2000`, `1.5`) or as a bare word (`aces`, `hvl,proxy`).
    ///
    /// This is how command-line flags apply over a settings file. The result is not validated:
    /// call [`Settings::validate`] once every override is applied.
    pub fn set(&mut self, key: &str, value: &str) -> Result<(), SettingsError> {
        let refuse = |reason: String| SettingsError::Override {
            key: key.to_owned(),
            value: value.to_owned(),
            reason,
        };
        let mut table = toml::Table::try_from(&*self).map_err(|e| refuse(e.to_string()))?;
        let parsed = toml::from_str::<toml::Table>(&format!("v = {value}"))
            .ok()
            .and_then(|mut t| t.remove("v"))
            .unwrap_or_else(|| toml::Value::String(value.to_owned()));
        let mut slot = &mut table;
        let mut section = String::from("the top level");
        let mut parts = key.split('.').peekable();
        while let Some(part) = parts.next() {
            let known = slot.keys().cloned().collect::<Vec<_>>().join(", ");
            let entry = slot.get_mut(part).ok_or_else(|| {
                refuse(format!("no setting `{part}` in {section} (known: {known})"))
            })?;
            if parts.peek().is_none() {
                if entry.is_table() {
                    return Err(refuse(format!("`{key}` is a section, not a setting")));
                }
                *entry = parsed;
                break;
            }
            slot = entry
                .as_table_mut()
                .ok_or_else(|| refuse(format!("`{part}` is a setting, not a section")))?;
            section = format!("[{part}]");
        }
        *self = table
            .try_into()
            .map_err(|e: toml::de::Error| refuse(e.message().trim().to_owned()))?;
        Ok(())
    }
}
