//! Why settings were rejected.

use std::path::PathBuf;

use crate::choice::UnknownChoice;
use crate::declare::OutOfRange;

/// Why settings were rejected: each variant names the setting and what to do.
#[derive(Debug, thiserror::Error)]
pub enum SettingsError {
    /// A numeric setting lies outside its declared range (or is not a finite number).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A named choice (tonemap operator, GI technique, …) that shine does not know.
    #[error(transparent)]
    UnknownName(#[from] UnknownChoice),
    /// A GI list that is malformed: empty entry, duplicate, or `none` combined with others.
    #[error("invalid GI technique list `{list}`: {reason}")]
    GiList {
        /// The list as given.
        list: String,
        /// What is wrong with it.
        reason: &'static str,
    },
    /// The settings file could not be read.
    #[error("cannot read settings file {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The TOML text is malformed, names an unknown setting, or has a value of the wrong type.
    #[error("invalid settings{}: {message}", origin(path))]
    Parse {
        /// The file the text came from, when it came from one.
        path: Option<PathBuf>,
        /// The TOML parser's message (with line and column).
        message: String,
    },
    /// A `key=value` override names no setting or has a value the setting cannot take.
    #[error("cannot set `{key}` to `{value}`: {reason}")]
    Override {
        /// The dotted key (`hvl.count`).
        key: String,
        /// The value given.
        value: String,
        /// Why it was refused.
        reason: String,
    },
}

/// ` in FILE` for a parse error from a file, nothing for a string.
fn origin(path: &Option<PathBuf>) -> String {
    path.as_ref()
        .map(|p| format!(" in {}", p.display()))
        .unwrap_or_default()
}
