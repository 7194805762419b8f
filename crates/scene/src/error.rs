//! Errors of the scene crate. Every error names the file and the glTF element it is about.

use std::path::PathBuf;

/// An error while loading, building or writing a scene.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read.
    #[error("{path}: cannot read: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// A file could not be written.
    #[error("{path}: cannot write: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The file is not well-formed glTF (bad JSON, bad GLB container, invalid references).
    #[error("{file}: not a valid glTF 2.0 file: {source}")]
    Gltf {
        /// The file (or the name given to in-memory data).
        file: String,
        /// What the gltf crate reported.
        source: gltf::Error,
    },
    /// A glTF element holds data the loader cannot use.
    #[error("{file}: {element}: {message}")]
    Invalid {
        /// The file (or the name given to in-memory data).
        file: String,
        /// The element, e.g. `meshes[2] "chair" primitives[0] POSITION`.
        element: String,
        /// What is wrong and, where it helps, what to do.
        message: String,
    },
    /// `builtin::build` or `builtin::export` was asked for a scene that does not exist.
    #[error("unknown built-in scene {name:?}; the built-in scenes are: {known}")]
    UnknownBuiltin {
        /// The requested name.
        name: String,
        /// The known names, comma separated.
        known: String,
    },
}

/// Result with this crate's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
