//! `shine merge`: joins the parts of a sharded run: a reference's partial sums into the
//! reference, a sequence's manifests into the sequence's (a lab's reports:
//! `lab::merge`). A part of another run, a missing
//! part and a part given twice are refused, naming the part.

use std::path::{Path, PathBuf};

use super::Shard;
use super::manifest::{FrameFile, SequenceManifest};
use super::partial::{PartialHeader, PartialSums};

/// Why parts were not merged.
#[derive(Debug, thiserror::Error)]
pub enum MergeError {
    /// No part was given.
    #[error("no part to merge")]
    Empty,
    /// A part of a shard index or frame range no file holds.
    #[error("missing: {0}")]
    Missing(String),
    /// Two files hold the same part.
    #[error("{what} given twice: {first} and {second}")]
    Duplicate {
        /// The part.
        what: String,
        /// One file holding it.
        first: PathBuf,
        /// The other.
        second: PathBuf,
    },
    /// A part belongs to another run than the first part.
    #[error("{part} is not part of the run of {first}: {why}")]
    OtherRun {
        /// The odd part.
        part: PathBuf,
        /// The first part.
        first: PathBuf,
        /// What differs.
        why: String,
    },
    /// A part could not be read, or holds what its run cannot.
    #[error("{0}")]
    Part(String),
}

/// The first key (dotted path) where two run descriptions differ.
fn difference(a: &serde_json::Value, b: &serde_json::Value, at: &str) -> Option<String> {
    match (a, b) {
        (serde_json::Value::Object(x), serde_json::Value::Object(y)) => {
            let keys = x.keys().chain(y.keys());
            for key in keys {
                let path = if at.is_empty() {
                    key.clone()
                } else {
                    format!("{at}.{key}")
                };
                match (x.get(key), y.get(key)) {
                    (Some(p), Some(q)) => {
                        if let Some(d) = difference(p, q, &path) {
                            return Some(d);
                        }
                    }
                    _ => return Some(format!("`{path}` is in one only")),
                }
            }
            None
        }
        _ if a == b => None,
        _ => Some(format!("`{at}` is {a} there, {b} here")),
    }
}

/// Refuses `part`'s `run` unless it equals `first`'s, naming the first key that differs.
pub fn same_run(
    first: (&Path, &serde_json::Value),
    part: (&Path, &serde_json::Value),
) -> Result<(), MergeError> {
    match difference(first.1, part.1, "") {
        None => Ok(()),
        Some(why) => Err(MergeError::OtherRun {
            part: part.0.to_owned(),
            first: first.0.to_owned(),
            why,
        }),
    }
}

/// A reference merged from its parts: the header of the whole run and its sums.
#[derive(Debug)]
pub struct MergedReference {
    /// The run, with shard 0/1 and every sample.
    pub header: PartialHeader,
    /// The summed planes ([`PartialSums::sums`]).
    pub sums: Vec<[f32; 4]>,
}

/// The parts of a run with `count` shards, by shard index: each shard exactly once, or the
/// missing or doubled one named. `shard_of` reads a part's shard (after the caller checked
/// that it belongs to the run).
pub fn by_shard<T>(
    parts: &[(PathBuf, T)],
    count: u32,
    shard_of: impl Fn(&T) -> Shard,
) -> Result<Vec<(&Path, &T)>, MergeError> {
    let mut slots: Vec<Option<(&Path, &T)>> = vec![None; count as usize];
    for (path, part) in parts {
        let shard = shard_of(part);
        let slot = slots
            .get_mut(shard.index as usize)
            .filter(|_| shard.count == count)
            .ok_or_else(|| {
                MergeError::Part(format!(
                    "{}: part {shard} is not one of {count} parts",
                    path.display()
                ))
            })?;
        if let Some((other, _)) = slot {
            return Err(MergeError::Duplicate {
                what: format!("part {shard}"),
                first: other.to_path_buf(),
                second: path.clone(),
            });
        }
        *slot = Some((path, part));
    }
    slots
        .into_iter()
        .enumerate()
        .map(|(index, slot)| {
            slot.ok_or_else(|| {
                let shard = Shard {
                    index: index as u32,
                    count,
                };
                MergeError::Missing(format!("part {shard}"))
            })
        })
        .collect()
}

/// Adds the partial sums `parts` (file, part) of one reference, in shard order, after checking
/// that they are every shard of one run exactly once and that their samples tile `0..spp`.
pub fn merge_references(parts: &[(PathBuf, PartialSums)]) -> Result<MergedReference, MergeError> {
    let (first_path, first) = parts.first().ok_or(MergeError::Empty)?;
    for (path, part) in parts {
        same_run((first_path, &first.header.run), (path, &part.header.run))?;
        let size = |p: &PartialSums| (p.header.width, p.header.height);
        if size(part) != size(first) {
            return Err(MergeError::OtherRun {
                part: path.clone(),
                first: first_path.clone(),
                why: format!("{:?} pixels, not {:?}", size(part), size(first)),
            });
        }
    }
    let ordered = by_shard(parts, first.header.shard.count, |p| p.header.shard)?;
    let mut next = 0u32;
    let mut sums = vec![[0.0f32; 4]; first.sums.len()];
    for (path, part) in ordered {
        let [start, end] = part.header.samples;
        if start != next || end < start {
            return Err(MergeError::Part(format!(
                "{}: part {} holds samples {start}..{end}, where the parts before it end at \
                 {next}",
                path.display(),
                part.header.shard
            )));
        }
        next = end;
        for (sum, add) in sums.iter_mut().zip(&part.sums) {
            for c in 0..4 {
                sum[c] += add[c];
            }
        }
    }
    let spp = first.header.run.get("spp").and_then(|v| v.as_u64());
    if spp.is_some_and(|spp| spp != u64::from(next)) {
        return Err(MergeError::Part(format!(
            "the parts hold samples 0..{next} of a {}-spp reference",
            spp.unwrap_or(0)
        )));
    }
    Ok(MergedReference {
        header: PartialHeader {
            shard: Shard::WHOLE,
            samples: [0, next],
            ..first.header.clone()
        },
        sums,
    })
}

/// Joins the manifests `parts` (file, manifest) of one sequence into the manifest of the
/// whole, to be written at `output`: they must be of one run and cover every frame once,
/// and every frame file must still hold what its shard wrote.
pub fn merge_sequences(
    parts: &[(PathBuf, SequenceManifest)],
    output: &Path,
) -> Result<SequenceManifest, MergeError> {
    let (first_path, first) = parts.first().ok_or(MergeError::Empty)?;
    let mut sorted: Vec<&(PathBuf, SequenceManifest)> = parts.iter().collect();
    for (path, part) in &sorted {
        same_run((first_path, &first.run), (path, &part.run))?;
        if part.frames != first.frames {
            return Err(MergeError::OtherRun {
                part: path.clone(),
                first: first_path.clone(),
                why: format!("{} frames, not {}", part.frames, first.frames),
            });
        }
        let [start, end] = part.written;
        let listed: Vec<u32> = part.files.iter().map(|f| f.frame).collect();
        if start >= end || end > part.frames || listed != (start..end).collect::<Vec<_>>() {
            return Err(MergeError::Part(format!(
                "{}: frames {start}..{end} of {} listed as {listed:?}: the manifest is damaged",
                path.display(),
                part.frames
            )));
        }
    }
    sorted.sort_by_key(|(_, part)| part.written);
    let mut merged = SequenceManifest::new(first.run.clone(), first.frames, [0, first.frames], 0);
    let mut next = 0u32;
    let mut last: Option<&Path> = None;
    for (path, part) in sorted {
        let [start, end] = part.written;
        if start > next {
            return Err(MergeError::Missing(format!(
                "frames {next}..{start} of {} (no part covers them)",
                first.frames
            )));
        }
        if start < next {
            return Err(MergeError::Duplicate {
                what: format!("frames {start}..{}", next.min(end)),
                first: last.unwrap_or(path).to_path_buf(),
                second: path.clone(),
            });
        }
        part.verify(path)
            .map_err(|e| MergeError::Part(e.to_string()))?;
        for file in &part.files {
            let at = SequenceManifest::resolve(file, path);
            merged.files.push(FrameFile {
                path: SequenceManifest::recorded(&at, output)
                    .map_err(|e| MergeError::Part(e.to_string()))?,
                ..file.clone()
            });
        }
        next = end;
        last = Some(path);
    }
    if next < first.frames {
        return Err(MergeError::Missing(format!(
            "frames {next}..{} of {} (no part covers them)",
            first.frames, first.frames
        )));
    }
    Ok(merged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::farm::partial::PartialHeader;

    fn part(index: u32, count: u32, samples: [u32; 2]) -> (PathBuf, PartialSums) {
        (
            PathBuf::from(format!("ref.{index}.part")),
            PartialSums {
                header: PartialHeader {
                    run: serde_json::json!({"scene": "s", "spp": 8, "seed": 0}),
                    shard: Shard { index, count },
                    samples,
                    width: 1,
                    height: 1,
                },
                sums: vec![[samples[1] as f32 - samples[0] as f32, 0.0, 0.0, 1.0]; 3],
            },
        )
    }

    #[test]
    fn references_add_their_parts() {
        let merged = merge_references(&[part(1, 2, [4, 8]), part(0, 2, [0, 4])]).unwrap();
        assert_eq!(merged.header.samples, [0, 8]);
        assert_eq!(merged.sums[0], [8.0, 0.0, 0.0, 2.0]);
    }

    #[test]
    fn a_missing_or_doubled_part_is_named() {
        let err = merge_references(&[part(0, 3, [0, 2]), part(2, 3, [5, 8])]).unwrap_err();
        assert_eq!(err.to_string(), "missing: part 1/3");
        let err = merge_references(&[part(0, 2, [0, 4]), part(0, 2, [0, 4])]).unwrap_err();
        assert!(
            matches!(&err, MergeError::Duplicate { what, .. } if what == "part 0/2"),
            "{err}"
        );
        let mut other = part(1, 2, [4, 8]);
        other.1.header.run["seed"] = serde_json::json!(7);
        let err = merge_references(&[part(0, 2, [0, 4]), other]).unwrap_err();
        assert!(
            err.to_string().contains("`seed` is 0 there, 7 here"),
            "{err}"
        );
    }
}
