//! `shine compare`: RMSE, relative RMSE, energy ratio, PSNR, SSIM and FLIP of an image against a
//! reference (EXR radiance, or PNG as displayed), as a table or JSON (definitions in
//! `shine::capture::image_compare`); per tile of a grid, as a FLIP map and as a signed error
//! map on request (`shine::capture::regions`).

use super::CliError;
use shine::capture::image_compare::{compare, flip_map};
use shine::capture::image_io::{HdrImage, read_exr, read_png_linear, write_png};
use shine::capture::noise_free as nf;
use shine::capture::regions::{
    Region, Surface, SurfacePixels, error_heatmap, mask_pixels, masked_metrics, region_grid,
    surface_of, surface_pixels,
};
use std::path::{Path, PathBuf};

/// Arguments of `shine compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The image under test: .exr (linear radiance) or .png (8-bit sRGB, compared as displayed).
    image: PathBuf,
    /// The reference: .exr (e.g. from `shine reference`) or .png.
    reference: PathBuf,
    /// Report format: table or json.
    #[arg(long, default_value = "table")]
    format: String,
    /// Also report energy ratio and relative RMSE per tile of an N×N grid (0: none).
    #[arg(long, default_value_t = 0)]
    regions: u32,
    /// Also write the per-pixel FLIP error as a PNG (FLIP's magma map: black where no
    /// difference shows, yellow-white where the largest does).
    #[arg(long)]
    heatmap: Option<PathBuf>,
    /// Also write the signed error relative to the reference's mean as a PNG (red: brighter,
    /// blue: darker, saturating at ±1).
    #[arg(long)]
    signed_map: Option<PathBuf>,
    /// Also report energy ratio and relative RMSE over the pixels where this image is lit
    /// (any channel above 0.5; e.g. a `cubes.mask` render of the dynamic objects).
    #[arg(long)]
    mask: Option<PathBuf>,
    /// Also report energy ratio and relative RMSE per surface orientation, from this image of
    /// world normals (`--set output.component=geometric-normal --ssaa 1`; `normal`, the
    /// shading normals, parts a normal-mapped plane into many): normals within 10° are one
    /// surface; surfaces under 1% of the pixels are left out. With --second-reference, also
    /// the noise-free metrics per surface.
    #[arg(long)]
    surfaces: Option<PathBuf>,
    /// With --surfaces: this image of world positions (`--set output.component=position
    /// --ssaa 1`) parts parallel planes, a floor from the top of a box on it: a surface's
    /// pixels lie within 1% of the scene's size of its plane.
    #[arg(long, requires = "surfaces")]
    positions: Option<PathBuf>,
    /// A second reference of another seed: the truth becomes the two references' mean, and the
    /// relative RMSE with the truth's own noise subtracted and the 99.9th percentile of the
    /// per-pixel error are reported, over every pixel and over --mask
    /// (`shine::capture::noise_free`).
    #[arg(long)]
    second_reference: Option<PathBuf>,
}

/// Reads an image to compare: EXR as radiance, PNG decoded from sRGB to the light it displays.
/// Returns the image and whether it was a PNG.
fn read_image(path: &Path) -> Result<(HdrImage, bool), CliError> {
    let png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    let image = if png {
        read_png_linear(path)
    } else {
        read_exr(path)
    };
    Ok((image.map_err(|e| format!("{}: {e}", path.display()))?, png))
}

/// Compares and prints the metrics.
pub fn run(args: &CompareArgs) -> Result<(), CliError> {
    let json = match args.format.as_str() {
        "table" => false,
        "json" => true,
        other => return Err(format!("unknown format `{other}` (expected table or json)").into()),
    };
    let (image, image_png) = read_image(&args.image)?;
    let (reference, reference_png) = read_image(&args.reference)?;
    let displayed = image_png || reference_png;
    if displayed {
        // What a PNG comparison means, once, where a person reads it (not in the JSON on stdout).
        eprintln!(
            "note: PNG input is compared as displayed (8-bit sRGB decoded to linear [0, 1], after any tonemap): \
             energy ratio and relative RMSE are those of the displayed images, not of the radiance; \
             compare EXR files for radiance"
        );
    }
    let mask = match &args.mask {
        Some(path) => Some(read_image(path)?.0),
        None => None,
    };
    // The surfaces' pixels, found once for their metrics and their noise-free reports.
    let surface_sets = match &args.surfaces {
        Some(path) => {
            let positions = match &args.positions {
                Some(p) => Some(read_exr_only(p, "--positions", "positions")?),
                None => None,
            };
            let normals = read_exr_only(path, "--surfaces", "normals")?;
            shine::capture::image_compare::check(&normals, &reference)?;
            surface_pixels(&normals, positions.as_ref())?
        }
        None => Vec::new(),
    };
    let surfaces = surface_sets
        .iter()
        .map(|s| surface_of(&image, &reference, s))
        .collect::<Result<Vec<Surface>, _>>()?;
    let noise_free = match &args.second_reference {
        Some(path) => {
            let second = read_image(path)?.0;
            let mut reports = vec![(
                "every pixel".to_string(),
                nf::noise_free(&image, &reference, &second, None)?,
            )];
            if let Some(mask) = &mask {
                let pixels = mask_pixels(mask, &reference)?;
                reports.push((
                    "mask".to_string(),
                    nf::noise_free(&image, &reference, &second, Some(&pixels))?,
                ));
            }
            for s in &surface_sets {
                let m = nf::noise_free(&image, &reference, &second, Some(&s.pixels))?;
                reports.push((surface_label(s), m));
            }
            reports
        }
        None => Vec::new(),
    };
    let c = compare(&image, &reference)?;
    let regions = match args.regions {
        0 => Vec::new(),
        n => region_grid(&image, &reference, n)?,
    };
    let masked = match &mask {
        Some(mask) => Some(masked_metrics(&image, &reference, mask)?),
        None => None,
    };
    if let Some(path) = &args.heatmap {
        write_png(path, &flip_map(&image, &reference)?)
            .map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if let Some(path) = &args.signed_map {
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
            "displayed": displayed,
            "width": image.width,
            "height": image.height,
            "regions": regions,
            "surfaces": surfaces,
            "noise_free": noise_free.iter().map(|(over, m)| serde_json::json!({"over": over, "metrics": m})).collect::<Vec<_>>(),
            "mask": masked.map(|(pixels, mean, energy, relative)| serde_json::json!({
                "pixels": pixels,
                "reference_mean": mean,
                "energy_ratio": energy.is_finite().then_some(energy),
                "relative_rmse": relative.is_finite().then_some(relative),
            })),
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
        if let Some((pixels, _, energy, relative)) = masked {
            println!("masked ({pixels} pixels): energy {energy:.4}, RMSE/mean {relative:.4}");
        }
        print_noise_free(&noise_free);
        print_regions(&regions, args.regions);
        print_surfaces(&surfaces);
    }
    Ok(())
}

/// Reads a guide image that must be EXR: a PNG clamps negative components away.
fn read_exr_only(path: &Path, flag: &str, what: &str) -> Result<HdrImage, CliError> {
    match read_image(path)? {
        (_, true) => Err(format!(
            "{}: {flag} needs the {what} as EXR (a PNG loses their negative components)",
            path.display()
        )
        .into()),
        (image, false) => Ok(image),
    }
}

/// How the noise-free report names a surface: by its normal.
fn surface_label(s: &SurfacePixels) -> String {
    let [x, y, z] = s.normal;
    format!("surface ({x:+.2} {y:+.2} {z:+.2})")
}

/// One line per pixel set: the metrics against the two seeds' mean.
fn print_noise_free(reports: &[(String, nf::NoiseFree)]) {
    if reports.is_empty() {
        return;
    }
    println!(
        "against the two references' mean (pixels, energy, RMSE/mean, noise-free RMSE/mean, seeds' RMSE/mean, p{} |error|/mean)",
        nf::PERCENTILE
    );
    for (over, m) in reports {
        println!(
            "  {over}: {} px, energy {:.4}, RMSE/mean {:.4}, noise-free {:.4}, seeds {:.4}, p{} {:.4}",
            m.pixels,
            m.energy_ratio,
            m.relative_rmse,
            m.noise_free_relative_rmse,
            m.truth_noise,
            nf::PERCENTILE,
            m.error_percentile
        );
    }
}

/// One line per surface: its normal, pixels, energy ratio and relative RMSE.
fn print_surfaces(surfaces: &[Surface]) {
    if surfaces.is_empty() {
        return;
    }
    println!("per surface (normal: pixels, energy ratio, relative RMSE)");
    for s in surfaces {
        let [x, y, z] = s.normal;
        println!(
            "  ({x:+.2} {y:+.2} {z:+.2}): {:6} px, energy {:.3}, RMSE/mean {:.3}",
            s.pixels, s.energy_ratio, s.relative_rmse
        );
    }
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
