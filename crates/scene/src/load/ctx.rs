//! The loading context shared by every step of the loader: the file name for messages and
//! the warnings met so far, plus the finiteness check every float attribute goes through.

use crate::error::{Error, Result};

/// Loading context: the file name for messages and the warnings so far.
pub(super) struct Ctx<'a> {
    /// The file (or in-memory name) being loaded, prefixed to every message.
    file: &'a str,
    /// Warnings in the order they were met (`"<file>: <element>: <message>"`).
    pub(super) warnings: Vec<String>,
}

impl<'a> Ctx<'a> {
    /// A context for `file` with no warnings yet.
    pub(super) fn new(file: &'a str) -> Self {
        Ctx {
            file,
            warnings: Vec::new(),
        }
    }

    /// The name of the file being loaded.
    pub(super) fn file(&self) -> &'a str {
        self.file
    }
}

impl Ctx<'_> {
    /// An [`Error::Invalid`] about `element` of this file.
    pub(super) fn invalid(&self, element: impl Into<String>, message: impl Into<String>) -> Error {
        Error::Invalid {
            file: self.file.to_string(),
            element: element.into(),
            message: message.into(),
        }
    }

    /// Records a warning about `element` of this file.
    pub(super) fn warn(
        &mut self,
        element: impl std::fmt::Display,
        message: impl std::fmt::Display,
    ) {
        self.warnings
            .push(format!("{}: {element}: {message}", self.file));
    }
}

/// Converts rows of floats into vectors, failing on NaN or infinity.
pub(super) fn finite_rows<T>(
    ctx: &Ctx,
    element: &str,
    what: &str,
    values: &[f32],
    dims: usize,
    make: impl Fn(&[f32]) -> T,
) -> Result<Vec<T>> {
    if let Some(bad) = values.iter().position(|x| !x.is_finite()) {
        return Err(ctx.invalid(
            format!("{element} {what}"),
            format!(
                "element {} has a NaN or infinite component ({})",
                bad / dims.max(1),
                values.get(bad).copied().unwrap_or(0.0)
            ),
        ));
    }
    Ok(values.chunks_exact(dims).map(make).collect())
}
