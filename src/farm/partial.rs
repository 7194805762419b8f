//! A reference's partial sums: shard `i` of `n` traces the global sample indices
//! `Shard::range(spp)` of every pixel ([`crate::reference::PathTracer::start_at_sample`]) and
//! writes their sums and counts, with the run they belong to. Every pixel's random numbers are
//! keyed by (seed, pixel, global sample index), so the parts hold exactly the samples of the
//! one-process reference; their merge adds the sums in shard order, which differs from the
//! one-process run's order of additions only (docs/many-machines.md states the bound).
//!
//! File layout: [`PARTIAL_MAGIC`], the header's length (u64, little-endian), the header
//! (JSON, [`PartialHeader`]), then the sums as little-endian f32: three planes (direct,
//! indirect, full) of width × height × (r, g, b, samples).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::Shard;
use crate::capture::image_io::write_bytes_atomically;

/// The first bytes of a partial-sum file.
pub const PARTIAL_MAGIC: &[u8] = b"shine partial sums\n";
/// Planes of a reference's sums (direct, indirect, full).
pub const PLANES: usize = 3;

/// What a partial-sum file holds.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PartialHeader {
    /// Everything that makes two parts samples of one reference (scene, size, bounces,
    /// flags, seed, time, environment, total samples, the component written): equal in every
    /// part.
    pub run: serde_json::Value,
    /// Which part of the reference.
    pub shard: Shard,
    /// The global sample indices traced, `[first, end)`.
    pub samples: [u32; 2],
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// One part of a reference: its header and sums.
#[derive(Clone, Debug, PartialEq)]
pub struct PartialSums {
    /// What the part is.
    pub header: PartialHeader,
    /// [`PLANES`] planes of width × height × (Σr, Σg, Σb, samples).
    pub sums: Vec<[f32; 4]>,
}

/// Why a partial-sum file could not be written or read.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {why}")]
pub struct PartialError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub why: String,
}

impl PartialSums {
    /// Writes the part to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<(), PartialError> {
        let error = |why: String| PartialError {
            path: path.to_owned(),
            why,
        };
        let expected = self.texels();
        if self.sums.len() != expected {
            return Err(error(format!(
                "{} sums for {expected} texels of {}×{}",
                self.sums.len(),
                self.header.width,
                self.header.height
            )));
        }
        let header = serde_json::to_vec(&self.header).map_err(|e| error(e.to_string()))?;
        let mut bytes = Vec::with_capacity(PARTIAL_MAGIC.len() + 8 + header.len() + expected * 16);
        bytes.extend_from_slice(PARTIAL_MAGIC);
        bytes.extend_from_slice(&(header.len() as u64).to_le_bytes());
        bytes.extend_from_slice(&header);
        for texel in &self.sums {
            for v in texel {
                bytes.extend_from_slice(&v.to_le_bytes());
            }
        }
        write_bytes_atomically(path, &bytes).map_err(|e| error(e.to_string()))
    }

    /// Whether `path` starts like a partial-sum file (merge tells part kinds apart by it).
    pub fn is_partial(path: &Path) -> bool {
        use std::io::Read;
        let mut start = vec![0u8; PARTIAL_MAGIC.len()];
        std::fs::File::open(path)
            .and_then(|mut f| f.read_exact(&mut start))
            .is_ok()
            && start == PARTIAL_MAGIC
    }

    /// Reads a part, refusing a truncated or malformed file by name.
    pub fn read(path: &Path) -> Result<Self, PartialError> {
        let error = |why: String| PartialError {
            path: path.to_owned(),
            why,
        };
        let bytes = std::fs::read(path).map_err(|e| error(e.to_string()))?;
        let rest = bytes.strip_prefix(PARTIAL_MAGIC).ok_or_else(|| {
            error("not a shine partial-sum file (`shine reference --shard`)".into())
        })?;
        let truncated = || error("the file is truncated".into());
        let (length, rest) = rest.split_first_chunk::<8>().ok_or_else(truncated)?;
        let length = usize::try_from(u64::from_le_bytes(*length)).map_err(|_| truncated())?;
        if rest.len() < length {
            return Err(truncated());
        }
        let (header, data) = rest.split_at(length);
        let header: PartialHeader =
            serde_json::from_slice(header).map_err(|e| error(format!("header: {e}")))?;
        let part = Self {
            header,
            sums: Vec::new(),
        };
        let expected = part.texels();
        if expected.checked_mul(16) != Some(data.len()) {
            return Err(error(format!(
                "{} bytes of sums where {}×{} needs {} planes of 16 bytes per pixel: the file is \
                 truncated or damaged",
                data.len(),
                part.header.width,
                part.header.height,
                PLANES
            )));
        }
        let sums = data
            .chunks_exact(16)
            .map(|t| {
                let f = |k: usize| f32::from_le_bytes([t[k], t[k + 1], t[k + 2], t[k + 3]]);
                [f(0), f(4), f(8), f(12)]
            })
            .collect();
        Ok(Self { sums, ..part })
    }

    /// Texels of the sums: [`PLANES`] × width × height (`usize::MAX` when that overflows, which
    /// no file matches).
    fn texels(&self) -> usize {
        (self.header.width as usize)
            .checked_mul(self.header.height as usize)
            .and_then(|pixels| pixels.checked_mul(PLANES))
            .unwrap_or(usize::MAX)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn part() -> PartialSums {
        PartialSums {
            header: PartialHeader {
                run: serde_json::json!({"scene": "builtin-cornell-box", "spp": 8}),
                shard: Shard { index: 1, count: 2 },
                samples: [4, 8],
                width: 2,
                height: 1,
            },
            sums: (0..6).map(|k| [k as f32, 0.5, -1.0, 4.0]).collect(),
        }
    }

    #[test]
    fn parts_round_trip_exactly() {
        let dir = std::env::temp_dir().join(format!("shine-partial-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("ref.part");
        part().write(&path).unwrap();
        assert!(PartialSums::is_partial(&path));
        assert_eq!(PartialSums::read(&path).unwrap(), part());
        // A truncated file is refused by name.
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        let err = PartialSums::read(&path).unwrap_err().to_string();
        assert!(
            err.contains("ref.part") && err.contains("truncated"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
