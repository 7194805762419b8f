//! Where an image differs from its reference: the metrics of `shine compare` per tile of an
//! N×N grid, and a heatmap of the signed error.
//!
//! One number for a whole image hides a floor at 0.75× of the truth behind a ceiling at
//! 1.25×. The grid keeps them apart without knowing the scene. In the cornell box at 4×4, the
//! top row is mostly ceiling, the bottom row floor, and the outer columns the side walls. The
//! heatmap shows the rest.

use crate::capture::image_compare::{CompareError, check, clamped};
use crate::capture::image_io::{HdrImage, LdrImage};

/// The metrics of one tile of the grid.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Region {
    /// Tile column, 0 at the left.
    pub column: u32,
    /// Tile row, 0 at the top.
    pub row: u32,
    /// Mean of the reference over the tile's pixels and channels.
    pub reference_mean: f64,
    /// Σ image / Σ reference over the tile (NaN for a black reference tile).
    pub energy_ratio: f64,
    /// RMSE over the tile divided by the reference's mean there.
    pub relative_rmse: f64,
}

/// The metrics of each tile of an `n`×`n` grid over the images, rows top to bottom. Tile
/// edges fall at `⌊i · size / n⌋`; `n` must be at least 1 and at most the smaller side.
pub fn region_grid(
    image: &HdrImage,
    reference: &HdrImage,
    n: u32,
) -> Result<Vec<Region>, CompareError> {
    check(image, reference)?;
    if n == 0 || n > image.width.min(image.height) {
        return Err(CompareError::Grid(n, image.width, image.height));
    }
    let edge = |i: u32, size: u32| (u64::from(i) * u64::from(size) / u64::from(n)) as u32;
    let mut regions = Vec::with_capacity((n * n) as usize);
    for row in 0..n {
        for column in 0..n {
            let pixels = (edge(row, image.height)..edge(row + 1, image.height)).flat_map(|y| {
                (edge(column, image.width)..edge(column + 1, image.width))
                    .map(move |x| (y * image.width + x) as usize)
            });
            let (reference_mean, energy_ratio, relative_rmse) =
                pixel_metrics(image, reference, pixels);
            regions.push(Region {
                column,
                row,
                reference_mean,
                energy_ratio,
                relative_rmse,
            });
        }
    }
    Ok(regions)
}

/// The pixels where `mask` (of `reference`'s size) is lit: any channel above 0.5. A mask of
/// another size is an error, and so is one that lights no pixel.
pub fn mask_pixels(mask: &HdrImage, reference: &HdrImage) -> Result<Vec<usize>, CompareError> {
    check(mask, reference)?;
    let n = reference.width as usize * reference.height as usize;
    let pixels: Vec<usize> = (0..n)
        .filter(|&i| mask.texels[i][..3].iter().any(|&v| v > 0.5))
        .collect();
    if pixels.is_empty() {
        return Err(CompareError::EmptyMask);
    }
    Ok(pixels)
}

/// The metrics over the pixels where `mask` is lit (any channel above 0.5), e.g. the
/// receivers of one technique (`cubes.mask`): `(pixels, reference mean, energy ratio, relative
/// RMSE)`. A mask that lights no pixel is an error.
pub fn masked_metrics(
    image: &HdrImage,
    reference: &HdrImage,
    mask: &HdrImage,
) -> Result<(usize, f64, f64, f64), CompareError> {
    check(image, reference)?;
    let pixels = mask_pixels(mask, reference)?;
    let (mean, energy, relative) = pixel_metrics(image, reference, pixels.iter().copied());
    Ok((pixels.len(), mean, energy, relative))
}

/// Normals within this angle of a surface's first normal belong to it (degrees).
pub const SURFACE_ANGLE_DEGREES: f64 = 10.0;
/// Surfaces with fewer pixels than this share of the lit ones are left out.
pub const SURFACE_MIN_SHARE: f64 = 0.01;

/// The metrics over one surface of [`surface_metrics`].
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Surface {
    /// The unit normal of the surface's first pixel (row-major order).
    pub normal: [f64; 3],
    /// Pixels of the surface.
    pub pixels: usize,
    /// Mean of the reference over the surface's pixels and channels.
    pub reference_mean: f64,
    /// Σ image / Σ reference over the surface.
    pub energy_ratio: f64,
    /// RMSE over the surface divided by the reference's mean there.
    pub relative_rmse: f64,
}

/// Planes facing the same way farther apart than this share of the scene's size (the
/// diagonal of the positions' bounding box) are separate surfaces when
/// [`surface_pixels`] has positions: the floor and the top of a box on it.
pub const SURFACE_PLANE_SHARE: f64 = 0.01;

/// The pixels of one surface of [`surface_pixels`].
#[derive(Clone, Debug, PartialEq)]
pub struct SurfacePixels {
    /// The unit normal of the surface's first pixel (row-major order).
    pub normal: [f64; 3],
    /// The surface's pixels (row-major indices).
    pub pixels: Vec<usize>,
}

/// The surfaces of an image: `normals` is an image of unit world normals (e.g.
/// `output.component = "geometric-normal"`, rendered without supersampling so edges stay
/// sharp; zero on the background; the shading normals of `"normal"` part a normal-mapped
/// plane into many). Pixels join the first surface whose normal is within
/// [`SURFACE_ANGLE_DEGREES`] of theirs, in row-major order; surfaces with fewer than
/// [`SURFACE_MIN_SHARE`] of the pixels are left out. Without `positions`, parallel planes
/// facing the same way (a floor and the top of a box on it) are one surface; with an image of
/// world positions (`output.component = "position"`, same size) a pixel also has to lie
/// within [`SURFACE_PLANE_SHARE`] of the scene's size of the surface's plane (through its
/// first pixel), so they part, and a curved object's tops, whose planes step, fall away as
/// small surfaces.
pub fn surface_pixels(
    normals: &HdrImage,
    positions: Option<&HdrImage>,
) -> Result<Vec<SurfacePixels>, CompareError> {
    if let Some(positions) = positions {
        check(positions, normals)?;
    }
    let min_cos = SURFACE_ANGLE_DEGREES.to_radians().cos();
    let point = |i: usize| positions.map(|p| p.texels[i].map(f64::from));
    let tolerance = positions.map_or(0.0, |p| SURFACE_PLANE_SHARE * scene_size(normals, p));
    let dot =
        |a: &[f64; 3], b: &[f64], o: &[f64]| (0..3).map(|c| a[c] * (b[c] - o[c])).sum::<f64>();
    let mut surfaces: Vec<(SurfacePixels, Option<[f64; 4]>)> = Vec::new();
    for (i, t) in normals.texels.iter().enumerate() {
        let Some(n) = unit_normal(t) else {
            continue;
        };
        let x = point(i);
        let joins = |(s, origin): &(SurfacePixels, Option<[f64; 4]>)| {
            dot(&s.normal, &n, &[0.0; 3]) >= min_cos
                && match (origin, &x) {
                    (Some(o), Some(x)) => dot(&s.normal, x, o).abs() <= tolerance,
                    _ => true,
                }
        };
        match surfaces.iter_mut().find(|s| joins(s)) {
            Some((s, _)) => s.pixels.push(i),
            None => surfaces.push((
                SurfacePixels {
                    normal: n,
                    pixels: vec![i],
                },
                x,
            )),
        }
    }
    let lit: usize = surfaces.iter().map(|(s, _)| s.pixels.len()).sum();
    if lit == 0 {
        return Err(CompareError::EmptyMask);
    }
    Ok(surfaces
        .into_iter()
        .map(|(s, _)| s)
        .filter(|s| s.pixels.len() as f64 >= SURFACE_MIN_SHARE * lit as f64)
        .collect())
}

/// The unit normal a texel of a normal image holds; `None` on the background (0) and for NaN
/// normals, which belong to no surface.
fn unit_normal(t: &[f32; 4]) -> Option<[f64; 3]> {
    let n = [f64::from(t[0]), f64::from(t[1]), f64::from(t[2])];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    (len.is_finite() && len > 1e-3).then(|| n.map(|c| c / len))
}

/// The diagonal of the bounding box of `positions` over the pixels with a normal
/// ([`unit_normal`]; finite positions only).
fn scene_size(normals: &HdrImage, positions: &HdrImage) -> f64 {
    let mut low = [f64::INFINITY; 3];
    let mut high = [f64::NEG_INFINITY; 3];
    for (n, p) in normals.texels.iter().zip(&positions.texels) {
        if unit_normal(n).is_none() || p[..3].iter().any(|c| !c.is_finite()) {
            continue;
        }
        for c in 0..3 {
            low[c] = low[c].min(f64::from(p[c]));
            high[c] = high[c].max(f64::from(p[c]));
        }
    }
    let d2: f64 = (0..3).map(|c| (high[c] - low[c]).powi(2)).sum();
    if d2.is_finite() { d2.sqrt() } else { 0.0 }
}

/// The metrics per surface of [`surface_pixels`] (`positions`: parallel planes apart).
pub fn surface_metrics(
    image: &HdrImage,
    reference: &HdrImage,
    normals: &HdrImage,
    positions: Option<&HdrImage>,
) -> Result<Vec<Surface>, CompareError> {
    check(normals, reference)?;
    let surfaces = surface_pixels(normals, positions)?;
    surfaces
        .iter()
        .map(|s| surface_of(image, reference, s))
        .collect()
}

/// The metrics of `image` against `reference` over one surface of [`surface_pixels`] (of a
/// normal image of their size).
pub fn surface_of(
    image: &HdrImage,
    reference: &HdrImage,
    surface: &SurfacePixels,
) -> Result<Surface, CompareError> {
    check(image, reference)?;
    let n = reference.texels.len();
    if let Some(&i) = surface.pixels.iter().find(|&&i| i >= n) {
        return Err(CompareError::PixelOutOfRange(i, n));
    }
    let (reference_mean, energy_ratio, relative_rmse) =
        pixel_metrics(image, reference, surface.pixels.iter().copied());
    Ok(Surface {
        normal: surface.normal,
        pixels: surface.pixels.len(),
        reference_mean,
        energy_ratio,
        relative_rmse,
    })
}

/// Reference mean, energy ratio and relative RMSE over `pixels` (indices, row-major), on
/// clamped channels as every metric of `shine compare`.
fn pixel_metrics(
    image: &HdrImage,
    reference: &HdrImage,
    pixels: impl Iterator<Item = usize>,
) -> (f64, f64, f64) {
    let (mut sum_image, mut sum_reference, mut squared, mut values) = (0.0, 0.0, 0.0, 0.0);
    for i in pixels {
        for c in 0..3 {
            let (a, b) = (clamped(image.texels[i][c]), clamped(reference.texels[i][c]));
            sum_image += a;
            sum_reference += b;
            squared += (a - b) * (a - b);
            values += 1.0;
        }
    }
    let reference_mean = sum_reference / values;
    (
        reference_mean,
        sum_image / sum_reference,
        (squared / values).sqrt() / reference_mean,
    )
}

/// Signed error at which the heatmap saturates, relative to the reference's mean.
pub const HEATMAP_RANGE: f64 = 1.0;

/// The signed error `(image − reference) / mean(reference)` per pixel, on the mean of the
/// three channels, as a diverging map: white where equal, red where the image is brighter,
/// blue where darker, saturating at ±[`HEATMAP_RANGE`].
pub fn error_heatmap(image: &HdrImage, reference: &HdrImage) -> Result<LdrImage, CompareError> {
    check(image, reference)?;
    let n = (image.width * image.height) as usize;
    let mean = |t: &[f32; 4]| (0..3).map(|c| clamped(t[c])).sum::<f64>() / 3.0;
    let reference_mean = reference.texels[..n].iter().map(mean).sum::<f64>() / n as f64;
    let scale = if reference_mean > 0.0 {
        1.0 / (reference_mean * HEATMAP_RANGE)
    } else {
        0.0
    };
    let texels = image.texels[..n]
        .iter()
        .zip(&reference.texels[..n])
        .map(|(a, b)| {
            let e = ((mean(a) - mean(b)) * scale).clamp(-1.0, 1.0);
            let fade = (255.0 * (1.0 - e.abs())).round() as u8;
            if e >= 0.0 {
                [255, fade, fade, 255]
            } else {
                [fade, fade, 255, 255]
            }
        })
        .collect();
    Ok(LdrImage {
        width: image.width,
        height: image.height,
        texels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::capture::image_io::grey_image as image;

    /// A mask of the left half scores the brighter half alone; a mask of another size is an
    /// error.
    #[test]
    fn a_mask_scores_its_pixels_alone() {
        let reference = image(8, 6, |_, _| 0.25);
        let test = image(8, 6, |x, _| if x < 4 { 0.5 } else { 0.25 });
        let mask = image(8, 6, |x, _| if x < 4 { 1.0 } else { 0.0 });
        let (pixels, mean, energy, error) = masked_metrics(&test, &reference, &mask).unwrap();
        assert_eq!(pixels, 24);
        assert!((mean - 0.25).abs() < 1e-12 && (energy - 2.0).abs() < 1e-12);
        assert!((error - 1.0).abs() < 1e-12);
        assert!(masked_metrics(&test, &reference, &image(4, 6, |_, _| 1.0)).is_err());
        assert!(masked_metrics(&test, &reference, &image(8, 6, |_, _| 0.0)).is_err());
    }

    /// Normals facing +x on the left half (5° apart per column, all within 10° of the first),
    /// +y on the right but one background pixel and a lone −z pixel (under 1%: left out):
    /// the left surface scores energy 2, the right 1; a normal image of another size or all
    /// background is an error.
    #[test]
    fn surfaces_gather_pixels_by_normal() {
        let (w, h) = (20, 10);
        let reference = image(w, h, |_, _| 0.25);
        let test = image(w, h, |x, _| if x < 10 { 0.5 } else { 0.25 });
        let mut normals = image(w, h, |_, _| 0.0);
        for y in 0..h {
            for x in 0..w {
                let t = &mut normals.texels[(y * w + x) as usize];
                let n = if x < 10 {
                    let a = (x % 2) as f32 * 5f32.to_radians();
                    [a.cos(), a.sin(), 0.0]
                } else if (x, y) == (19, 9) {
                    [0.0, 0.0, -1.0]
                } else if (x, y) == (18, 9) {
                    [0.0; 3]
                } else {
                    [0.0, 1.0, 0.0]
                };
                t[..3].copy_from_slice(&n);
            }
        }
        let surfaces = surface_metrics(&test, &reference, &normals, None).unwrap();
        assert_eq!(surfaces.len(), 2, "{surfaces:?}");
        assert_eq!((surfaces[0].pixels, surfaces[1].pixels), (100, 98));
        assert!((surfaces[0].energy_ratio - 2.0).abs() < 1e-12);
        assert!((surfaces[1].energy_ratio - 1.0).abs() < 1e-12);
        assert!(surfaces[1].normal[1] > 0.999);
        assert!(surface_metrics(&test, &reference, &image(4, 6, |_, _| 1.0), None).is_err());
        assert!(surface_metrics(&test, &reference, &image(w, h, |_, _| 0.0), None).is_err());
    }

    /// A floor (y = 0) and a box top (y = 0.5) on it face the same way: one surface by their
    /// normals alone, two with positions; a pixel 0.5% of the scene off the floor's plane stays
    /// on it; positions of another size are an error.
    #[test]
    fn positions_part_parallel_planes() {
        let (w, h) = (20, 10);
        let normals = image(w, h, |_, _| 0.0);
        let normals = HdrImage {
            texels: normals
                .texels
                .iter()
                .map(|_| [0.0, 1.0, 0.0, 1.0])
                .collect(),
            ..normals
        };
        let mut positions = image(w, h, |_, _| 0.0);
        for y in 0..h {
            for x in 0..w {
                let top = x >= 15 && y < 4;
                let height = if top {
                    0.5
                } else if (x, y) == (3, 3) {
                    0.1
                } else {
                    0.0
                };
                positions.texels[(y * w + x) as usize] = [x as f32, height, y as f32, 1.0];
            }
        }
        let alone = surface_pixels(&normals, None).unwrap();
        assert_eq!(alone.len(), 1, "{alone:?}");
        let parted = surface_pixels(&normals, Some(&positions)).unwrap();
        let sizes: Vec<usize> = parted.iter().map(|s| s.pixels.len()).collect();
        assert_eq!(sizes, vec![180, 20], "{parted:?}");
        assert!(parted[0].pixels.contains(&(3 * w as usize + 3)));
        assert!(surface_pixels(&normals, Some(&image(4, 6, |_, _| 0.0))).is_err());
    }

    /// An image twice as bright on its left half: the left tiles report energy 2 and relative
    /// RMSE 1, the right ones 1 and 0; the heatmap is red on the left and white on the right.
    #[test]
    fn tiles_keep_halves_apart() {
        let reference = image(8, 6, |_, _| 0.25);
        let test = image(8, 6, |x, _| if x < 4 { 0.5 } else { 0.25 });
        let regions = region_grid(&test, &reference, 2).unwrap();
        assert_eq!(regions.len(), 4);
        for r in &regions {
            let (energy, error) = if r.column == 0 {
                (2.0, 1.0)
            } else {
                (1.0, 0.0)
            };
            assert!((r.energy_ratio - energy).abs() < 1e-12, "{r:?}");
            assert!((r.relative_rmse - error).abs() < 1e-12, "{r:?}");
            assert!((r.reference_mean - 0.25).abs() < 1e-12);
        }
        let map = error_heatmap(&test, &reference).unwrap();
        assert_eq!(map.texels[0], [255, 0, 0, 255]);
        assert_eq!(map.texels[7], [255, 255, 255, 255]);
        let darker = error_heatmap(&reference, &test).unwrap();
        assert_eq!(darker.texels[0][2], 255);
        assert!(darker.texels[0][0] < 255);
    }

    #[test]
    fn bad_grids_are_errors() {
        let a = image(8, 6, |_, _| 0.25);
        assert_eq!(region_grid(&a, &a, 0), Err(CompareError::Grid(0, 8, 6)));
        assert_eq!(region_grid(&a, &a, 7), Err(CompareError::Grid(7, 8, 6)));
        let b = image(6, 6, |_, _| 0.25);
        assert!(matches!(
            region_grid(&a, &b, 2),
            Err(CompareError::SizeMismatch(..))
        ));
    }
}
