//! A sharded lab's reports joined into the whole lab's (`shine merge`, docs/many-machines.md).

use std::path::{Path, PathBuf};

use super::{LabPart, LabReport};
use crate::farm::Shard;
use crate::farm::merge::{MergeError, by_shard, same_run};

/// Joins the reports `parts` (file, report) of one sharded lab: they must be parts of one
/// run (conditions, scenes, configurations, device, driver, revision), each shard once. The
/// points come out in the run's order; a scene's failure reported by several parts once.
pub fn merge_labs(parts: &[(PathBuf, LabReport)]) -> Result<LabReport, MergeError> {
    let (first_path, first) = parts.first().ok_or(MergeError::Empty)?;
    let whole = |path: &Path| {
        MergeError::Part(format!(
            "{}: a whole lab's report, not a part of one (`shine lab --shard`)",
            path.display()
        ))
    };
    let first_part = first.part.as_ref().ok_or_else(|| whole(first_path))?;
    let identity = |r: &LabReport, part: &LabPart| {
        serde_json::json!({
            "setup": r.setup,
            "device": r.device,
            "driver": r.driver,
            "revision": r.revision,
            "scenes": part.scenes,
            "configs": part.configs,
            "shards": part.shard.count,
        })
    };
    let run = identity(first, first_part);
    for (path, report) in parts {
        let part = report.part.as_ref().ok_or_else(|| whole(path))?;
        same_run((first_path, &run), (path, &identity(report, part)))?;
    }
    let ordered = by_shard(parts, first_part.shard.count, |r| {
        r.part.as_ref().map_or(Shard::WHOLE, |p| p.shard)
    })?;
    let mut merged = LabReport {
        points: Vec::new(),
        failures: Vec::new(),
        truths: Vec::new(),
        part: None,
        ..first.clone()
    };
    for (_, report) in ordered {
        merged.points.extend(report.points.iter().cloned());
        for failure in &report.failures {
            if !merged.failures.contains(failure) {
                merged.failures.push(failure.clone());
            }
        }
        for truth in &report.truths {
            if !merged.truths.contains(truth) {
                merged.truths.push(truth.clone());
            }
        }
    }
    Ok(merged)
}
