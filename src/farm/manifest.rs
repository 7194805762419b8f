//! What one process of a sharded sequence wrote: its frames, their sizes and hashes, and the
//! run they belong to. `shine merge` joins the manifests of every shard into the sequence's,
//! refusing a missing or twice-covered frame range and a frame file that is not what its
//! shard wrote.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::identity::fnv1a;
use crate::capture::image_io::write_bytes_atomically;
use crate::capture::sequence::FramePattern;

/// The `kind` of a sequence manifest (merge tells part kinds apart by it).
pub const SEQUENCE_KIND: &str = "shine-sequence";

/// One frame file of a manifest.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct FrameFile {
    /// Frame number in the sequence.
    pub frame: u32,
    /// The file: its name when it lies beside the manifest, else its absolute path.
    pub path: PathBuf,
    /// Its size in bytes.
    pub bytes: u64,
    /// FNV-1a of its bytes, hexadecimal.
    pub fnv1a: String,
}

/// The frames `written` of a `frames`-frame sequence of `run`, as one process wrote them.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SequenceManifest {
    /// [`SEQUENCE_KIND`].
    pub kind: String,
    /// Everything that makes two processes' frames parts of one sequence (scene, settings,
    /// clock, camera path): equal in every part.
    pub run: serde_json::Value,
    /// Frames of the whole sequence.
    pub frames: u32,
    /// The frames this manifest covers, `[start, end)`.
    pub written: [u32; 2],
    /// Frames rendered unwritten before `written.0` to warm the histories up.
    pub warm_up: u32,
    /// The files, by frame.
    pub files: Vec<FrameFile>,
}

/// Why a manifest could not be written, read or checked.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    /// A file could not be read or written.
    #[error("{path}: {why}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        why: String,
    },
    /// A frame file differs from what its shard wrote.
    #[error("{path}: {why}")]
    Changed {
        /// The frame file.
        path: PathBuf,
        /// How it differs.
        why: String,
    },
}

impl SequenceManifest {
    /// An empty manifest for frames `written` of `run`.
    pub fn new(run: serde_json::Value, frames: u32, written: [u32; 2], warm_up: u32) -> Self {
        Self {
            kind: SEQUENCE_KIND.to_owned(),
            run,
            frames,
            written,
            warm_up,
            files: Vec::new(),
        }
    }

    /// Where the manifest of frames `written` of `pattern` goes: the pattern with its frame
    /// field replaced by `A-B` (B exclusive), plus `.json` (`out/frame_0-4.png.json`).
    pub fn path_for(pattern: &FramePattern, written: [u32; 2]) -> PathBuf {
        let mut text = pattern
            .with_field(&format!("{}-{}", written[0], written[1]))
            .into_os_string();
        text.push(".json");
        PathBuf::from(text)
    }

    /// Records frame `frame`, written to `path`, by reading it back (its size and hash).
    pub fn add(&mut self, frame: u32, path: &Path, manifest: &Path) -> Result<(), ManifestError> {
        let bytes = std::fs::read(path).map_err(|e| io(path, e))?;
        self.files.push(FrameFile {
            frame,
            path: Self::recorded(path, manifest)?,
            bytes: bytes.len() as u64,
            fnv1a: format!("{:016x}", fnv1a(&bytes)),
        });
        Ok(())
    }

    /// Writes the manifest to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<(), ManifestError> {
        let text = serde_json::to_string_pretty(self).map_err(|e| ManifestError::Io {
            path: path.to_owned(),
            why: e.to_string(),
        })?;
        write_bytes_atomically(path, text.as_bytes()).map_err(|e| ManifestError::Io {
            path: path.to_owned(),
            why: e.to_string(),
        })
    }

    /// Reads a manifest, `None` when `path` holds JSON of another kind.
    pub fn read(path: &Path) -> Result<Option<Self>, ManifestError> {
        let text = std::fs::read_to_string(path).map_err(|e| io(path, e))?;
        let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| io(path, e))?;
        if value.get("kind").and_then(|k| k.as_str()) != Some(SEQUENCE_KIND) {
            return Ok(None);
        }
        serde_json::from_value(value)
            .map(Some)
            .map_err(|e| io(path, e))
    }

    /// How a manifest at `manifest` names the file `path`: by its name when it lies beside the
    /// manifest, else by its absolute path.
    pub fn recorded(path: &Path, manifest: &Path) -> Result<PathBuf, ManifestError> {
        let beside = path.parent().map(normal) == manifest.parent().map(normal);
        match (beside, path.file_name()) {
            (true, Some(name)) => Ok(PathBuf::from(name)),
            _ => std::path::absolute(path).map_err(|e| io(path, e)),
        }
    }

    /// The path of `file` as this manifest, read from `manifest`, names it.
    pub fn resolve(file: &FrameFile, manifest: &Path) -> PathBuf {
        if file.path.is_absolute() {
            file.path.clone()
        } else {
            manifest.parent().unwrap_or(Path::new("")).join(&file.path)
        }
    }

    /// Checks that every file of the manifest read from `manifest` still holds what was
    /// written (size and hash).
    pub fn verify(&self, manifest: &Path) -> Result<(), ManifestError> {
        for file in &self.files {
            let path = Self::resolve(file, manifest);
            let bytes = std::fs::read(&path).map_err(|e| ManifestError::Changed {
                path: path.clone(),
                why: format!("frame {} cannot be read: {e}", file.frame),
            })?;
            let hash = format!("{:016x}", fnv1a(&bytes));
            if bytes.len() as u64 != file.bytes || hash != file.fnv1a {
                return Err(ManifestError::Changed {
                    path,
                    why: format!(
                        "frame {} is not the file its shard wrote ({} bytes, hash {hash}; \
                         written: {} bytes, hash {})",
                        file.frame,
                        bytes.len(),
                        file.bytes,
                        file.fnv1a
                    ),
                });
            }
        }
        Ok(())
    }
}

/// `path` with an empty parent read as the current folder.
fn normal(path: &Path) -> PathBuf {
    if path.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        path.to_owned()
    }
}

fn io(path: &Path, e: impl std::fmt::Display) -> ManifestError {
    ManifestError::Io {
        path: path.to_owned(),
        why: e.to_string(),
    }
}
