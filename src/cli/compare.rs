//! `shine compare`: RMSE, PSNR and SSIM of an image against a reference (both EXR), as a table
//! or JSON (definitions in `shine::capture::image_compare`); per tile of a grid and as a
//! heatmap on request (`shine::capture::regions`).

use super::CliError;
use shine::capture::image_compare::compare;
use shine::capture::image_io::{read_exr, write_png};
use shine::capture::regions::{Region, error_heatmap, region_grid};
use std::path::PathBuf;

/// Arguments of `shine compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The image under test (.exr).
    image: PathBuf,
    /// The reference (.exr), e.g. from `shine reference`.
    reference: PathBuf,
    /// Report format: table or json.
    #[arg(long, default_value = "table")]
    format: String,
    /// Also report energy ratio and relative RMSE per tile of an N×N grid (0: none).
    #[arg(long, default_value_t = 0)]
    regions: u32,
    /// Also write the signed error relative to the reference's mean as a PNG (red: brighter,
    /// blue: darker, saturating at ±1).
    #[arg(long)]
    heatmap: Option<PathBuf>,
}

/// Compares and prints the metrics.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let json = match args.format.as_str() {
        "table" => false,
        "json" => true,
        other => return Err(format!("unknown format `{other}` (expected table or json)").into()),
    };
    let read = |path: &PathBuf| read_exr(path).map_err(|e| format!("{}: {e}", path.display()));
    let image = read(&args.image)?;
    let reference = read(&args.reference)?;
    let c = compare(&image, &reference)?;
    let regions = match args.regions {
        0 => Vec::new(),
        n => region_grid(&image, &reference, n)?,
    };
    if let Some(path) = &args.heatmap {
        write_png(path, &error_heatmap(&image, &reference)?)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if json {
        // JSON has no infinity: identical images report a null PSNR.
        let value = serde_json::json!({
            "rmse": c.rmse,
            "relative_rmse": c.relative_rmse.is_finite().then_some(c.relative_rmse),
            "energy_ratio": c.energy_ratio.is_finite().then_some(c.energy_ratio),
            "psnr": c.psnr.is_finite().then_some(c.psnr),
            "ssim": c.ssim,
            "flip": c.flip,
            "width": image.width,
            "height": image.height,
            "regions": regions,
        });
        println!("{value}");
    } else {
        println!("metric  value");
        println!("RMSE    {:.6}", c.rmse);
        println!("RMSE/mean {:.4}", c.relative_rmse);
        println!("energy  {:.4}", c.energy_ratio);
        println!("PSNR    {:.3} dB", c.psnr);
        println!("SSIM    {:.6}", c.ssim);
        println!("FLIP    {:.6}", c.flip);
        print_regions(&regions, args.regions);
    }
    Ok(())
}

/// The tiles as two grids (energy ratio, relative RMSE), rows top to bottom.
fn print_regions(regions: &[Region], n: u32) {
    if regions.is_empty() {
        return;
    }
    for (title, value) in [
        (
            "energy ratio per tile",
            (|r: &Region| r.energy_ratio) as fn(&Region) -> f64,
        ),
        ("relative RMSE per tile", |r: &Region| r.relative_rmse),
    ] {
        println!("{title} ({n}×{n}, top row first)");
        for row in regions.chunks(n as usize) {
            let cells: Vec<String> = row.iter().map(|r| format!("{:6.3}", value(r))).collect();
            println!("  {}", cells.join(" "));
        }
    }
}
