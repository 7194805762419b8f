//! `shine compare`: RMSE, PSNR and SSIM of an image against a reference (both EXR), as a table
//! or JSON (definitions in `shine::capture::image_compare`).

use super::CliError;
use shine::capture::image_compare::compare;
use shine::capture::image_io::read_exr;
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
    }
    Ok(())
}
