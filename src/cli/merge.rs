//! `shine merge`: joins the parts of a sharded run (docs/many-machines.md): the partial sums
//! of `shine reference --shard` into the reference image, the manifests of `shine render
//! --frame-range/--shard` into the sequence's manifest, the results of `shine lab --shard`
//! into one lab.

use super::CliError;
use shine::farm::manifest::SequenceManifest;
use shine::farm::merge::{merge_references, merge_sequences};
use shine::farm::partial::PartialSums;
use shine::lab::LabReport;
use shine::lab::merge::merge_labs;
use shine::lab::run::write_outputs;
use shine::profile::roofline::cache_dir;
use shine::reference::ReferenceImages;
use std::path::{Path, PathBuf};

/// Arguments of `shine merge`.
#[derive(clap::Args, Debug)]
pub struct MergeArgs {
    /// The parts, all of one run: partial sums of `shine reference --shard`, the manifests
    /// (`*.json` beside the frames) of `shine render --frame-range/--shard`, or the lab.json of
    /// each `shine lab --shard` part.
    #[arg(required = true)]
    parts: Vec<PathBuf>,
    /// Output: the reference (.exr, or a .png preview), the whole sequence's manifest (.json),
    /// or the merged lab's folder (lab.json, lab.csv, plots, index.html).
    #[arg(short, long)]
    output: PathBuf,
}

/// Reads, checks and joins the parts, then writes the result atomically.
pub fn run(args: &MergeArgs) -> Result<(), CliError> {
    let first = &args.parts[0];
    if PartialSums::is_partial(first) {
        return merge_reference_parts(args);
    }
    if matches!(SequenceManifest::read(first), Ok(Some(_))) {
        return merge_sequence_parts(args);
    }
    if read_lab(first).is_ok() {
        return merge_lab_parts(args);
    }
    Err(format!(
        "{}: not a part shine merges: a `shine reference --shard` part, a sequence manifest \
         (`shine render --shard`, beside the frames) or a lab part's lab.json (`shine lab \
         --shard`)",
        first.display()
    )
    .into())
}

fn merge_reference_parts(args: &MergeArgs) -> Result<(), CliError> {
    let parts = args
        .parts
        .iter()
        .map(|path| Ok((path.clone(), PartialSums::read(path)?)))
        .collect::<Result<Vec<_>, CliError>>()?;
    let merged = merge_references(&parts)?;
    let header = &merged.header;
    let component = header.run["component"].as_str().unwrap_or("full");
    let samples = header.samples[1];
    let images = ReferenceImages::from_sums([header.width, header.height], &merged.sums, samples);
    super::reference::write_reference(&args.output, &images, component)?;
    println!(
        "wrote {} ({}×{}, {samples} spp of {component} radiance from {} parts)",
        args.output.display(),
        header.width,
        header.height,
        parts.len()
    );
    Ok(())
}

fn merge_sequence_parts(args: &MergeArgs) -> Result<(), CliError> {
    let parts = args
        .parts
        .iter()
        .map(|path| match SequenceManifest::read(path)? {
            Some(manifest) => Ok((path.clone(), manifest)),
            None => Err(format!(
                "{}: not a sequence manifest, unlike {}",
                path.display(),
                args.parts[0].display()
            )
            .into()),
        })
        .collect::<Result<Vec<_>, CliError>>()?;
    let merged = merge_sequences(&parts, &args.output)?;
    merged.write(&args.output)?;
    println!(
        "wrote {} ({} frames from {} parts, every file checked)",
        args.output.display(),
        merged.files.len(),
        parts.len()
    );
    Ok(())
}

/// A lab part's report.
fn read_lab(path: &Path) -> Result<LabReport, CliError> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    serde_json::from_str(&text)
        .map_err(|e| format!("{}: not a lab report: {e}", path.display()).into())
}

fn merge_lab_parts(args: &MergeArgs) -> Result<(), CliError> {
    let parts = args
        .parts
        .iter()
        .map(|path| Ok((path.clone(), read_lab(path)?)))
        .collect::<Result<Vec<_>, CliError>>()?;
    let merged = merge_labs(&parts)?;
    std::fs::create_dir_all(&args.output).map_err(|e| format!("{}: {e}", args.output.display()))?;
    // The pictures the parts' reports name, relative to their folders, move to the same
    // names under the merged folder.
    for (path, report) in &parts {
        let folder = path.parent().unwrap_or(Path::new("."));
        let pictures = report
            .points
            .iter()
            .flat_map(|p| [&p.image, &p.flip_map])
            .chain(report.truths.iter().map(|(_, png)| png));
        for picture in pictures {
            let to = args.output.join(picture);
            if let Some(parent) = to.parent() {
                std::fs::create_dir_all(parent)
                    .map_err(|e| format!("{}: {e}", parent.display()))?;
            }
            let bytes = std::fs::read(folder.join(picture))
                .map_err(|e| format!("{}: {e}", folder.join(picture).display()))?;
            shine::capture::image_io::write_bytes_atomically(&to, &bytes)?;
        }
    }
    write_outputs(&args.output, &merged)?;
    if let Some(cache) = cache_dir() {
        super::lab::record_budget(&cache, &merged)?;
    }
    println!(
        "wrote {} ({} points from {} parts)",
        args.output.join("index.html").display(),
        merged.points.len(),
        parts.len()
    );
    Ok(())
}
