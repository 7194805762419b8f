//! Image comparison: RMSE, PSNR and SSIM of a test image against a reference, for image tests
//! and `shine compare`.
//!
//! Both images are linear HDR radiance ([`HdrImage`]). The metrics are defined on values
//! clamped to `[0, 1]` (radiance as a display with exposure 1 shows it, before any tonemap or
//! sRGB encoding), so the dynamic range is `L = 1`:
//!
//! - **RMSE**: root mean square of the per-channel differences over the R, G, B channels of
//!   every pixel (alpha ignored).
//! - **PSNR**: `20 log10(L / RMSE)` dB (infinite for identical images).
//! - **SSIM** (Wang et al. 2004): on Rec. 709 luminance (`tonemap::luminance`), with an
//!   11×11 Gaussian window of σ = 1.5 (normalised), `C1 = (K1 L)²`, `C2 = (K2 L)²`,
//!   `K1 = 0.01`, `K2 = 0.03`, averaged over every window position that lies fully inside the
//!   image (no padding); images smaller than the window are refused.
//!
//! - **FLIP** (LDR-FLIP, Andersson et al. 2020, through the `nv-flip` binding of NVIDIA's
//!   reference implementation): the mean of its per-pixel error map (0 identical … 1), on the
//!   clamped values sRGB-encoded to 8 bits (what a display shows at exposure 1), at the
//!   binding's default 67 pixels per degree (a 0.7 m viewing distance from a 24" monitor).

use crate::capture::image_io::{HdrImage, LdrImage};
use crate::capture::tonemap;

/// Dynamic range `L` of the clamped values.
pub const DYNAMIC_RANGE: f64 = 1.0;
/// SSIM constant K1 (Wang et al. 2004).
pub const SSIM_K1: f64 = 0.01;
/// SSIM constant K2 (Wang et al. 2004).
pub const SSIM_K2: f64 = 0.03;
/// SSIM window side.
pub const SSIM_WINDOW: usize = 11;
/// SSIM window Gaussian σ.
pub const SSIM_SIGMA: f64 = 1.5;

/// Why two images cannot be compared.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CompareError {
    /// The images differ in size.
    #[error("image sizes differ: {0}×{1} against {2}×{3}")]
    SizeMismatch(u32, u32, u32, u32),
    /// The images are smaller than the SSIM window.
    #[error("images of {0}×{1} are smaller than the {SSIM_WINDOW}×{SSIM_WINDOW} SSIM window")]
    TooSmall(u32, u32),
    /// A region grid of this many tiles per side does not fit the image.
    #[error("a {0}×{0} region grid does not fit {1}×{2} images (1 to the smaller side)")]
    Grid(u32, u32, u32),
    /// An image holds fewer texels than its size says.
    #[error("an image holds {0} texels, its size needs {1}")]
    Truncated(usize, usize),
    /// A pixel index past the image's pixels.
    #[error("pixel {0} lies outside the {1} pixels of the image")]
    PixelOutOfRange(usize, usize),
    /// A mask that selects no pixel (none has a channel above 0.5).
    #[error("the mask selects no pixel (none has a channel above 0.5)")]
    EmptyMask,
}

/// The metrics of one comparison.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Comparison {
    /// Root mean square error (clamped linear values).
    pub rmse: f64,
    /// RMSE divided by the reference's mean (over pixels and channels): error relative to the
    /// signal, which PSNR on dim linear images hides (infinite for a black reference).
    pub relative_rmse: f64,
    /// Σ image / Σ reference over pixels and channels (1: the same energy).
    pub energy_ratio: f64,
    /// Peak signal-to-noise ratio in dB (`f64::INFINITY` when identical).
    pub psnr: f64,
    /// Mean structural similarity on luminance.
    pub ssim: f64,
    /// Mean LDR-FLIP error (0 identical, 1 worst).
    pub flip: f64,
}

/// Checks that two images can be compared: the same size, every texel present.
pub fn check(a: &HdrImage, b: &HdrImage) -> Result<(), CompareError> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(CompareError::SizeMismatch(
            a.width, a.height, b.width, b.height,
        ));
    }
    let n = a.width as usize * a.height as usize;
    for image in [a, b] {
        if image.texels.len() < n {
            return Err(CompareError::Truncated(image.texels.len(), n));
        }
    }
    Ok(())
}

/// A channel as the metrics see it: clamped to the dynamic range, NaN as 0.
pub(crate) fn clamped(v: f32) -> f64 {
    // NaN maps to 0 (clamp would keep it).
    if v.is_nan() {
        0.0
    } else {
        f64::from(v).clamp(0.0, DYNAMIC_RANGE)
    }
}

/// RMSE of `image` against `reference` (see the module documentation).
pub fn rmse(image: &HdrImage, reference: &HdrImage) -> Result<f64, CompareError> {
    check(image, reference)?;
    let n = image.width as usize * image.height as usize;
    let sum: f64 = image
        .texels
        .iter()
        .zip(&reference.texels)
        .take(n)
        .map(|(a, b)| {
            (0..3)
                .map(|c| (clamped(a[c]) - clamped(b[c])).powi(2))
                .sum::<f64>()
        })
        .sum();
    Ok((sum / (3 * n) as f64).sqrt())
}

/// [`Comparison::relative_rmse`] and [`Comparison::energy_ratio`] alone, without SSIM and
/// FLIP (what a sequence's every frame is judged by).
pub fn relative_error(image: &HdrImage, reference: &HdrImage) -> Result<(f64, f64), CompareError> {
    let rmse = rmse(image, reference)?;
    let (image_sum, reference_sum) = sums(image, reference)?;
    let values = 3.0 * f64::from(image.width) * f64::from(image.height);
    Ok((rmse / (reference_sum / values), image_sum / reference_sum))
}

/// Sums of `image` and `reference` over pixels and channels (clamped as for the RMSE).
fn sums(image: &HdrImage, reference: &HdrImage) -> Result<(f64, f64), CompareError> {
    check(image, reference)?;
    let n = image.width as usize * image.height as usize;
    let sum = |i: &HdrImage| {
        i.texels
            .iter()
            .take(n)
            .map(|t| (0..3).map(|c| clamped(t[c])).sum::<f64>())
            .sum::<f64>()
    };
    Ok((sum(image), sum(reference)))
}

/// PSNR in dB of `image` against `reference`: `20 log10(L / RMSE)`.
pub fn psnr(image: &HdrImage, reference: &HdrImage) -> Result<f64, CompareError> {
    Ok(psnr_of_rmse(rmse(image, reference)?))
}

/// PSNR in dB for an RMSE (infinite for 0).
pub fn psnr_of_rmse(rmse: f64) -> f64 {
    if rmse == 0.0 {
        f64::INFINITY
    } else {
        20.0 * (DYNAMIC_RANGE / rmse).log10()
    }
}

fn luminance(image: &HdrImage) -> Vec<f64> {
    let [r, g, b] = tonemap::REC709_LUMA.map(f64::from);
    image
        .texels
        .iter()
        .map(|t| r * clamped(t[0]) + g * clamped(t[1]) + b * clamped(t[2]))
        .collect()
}

/// Separable convolution with the normalised Gaussian window, "valid" region only.
fn blur(values: &[f64], width: usize, height: usize, kernel: &[f64]) -> Vec<f64> {
    let k = kernel.len();
    let (w2, h2) = (width + 1 - k, height + 1 - k);
    let mut rows = vec![0.0; w2 * height];
    for y in 0..height {
        for x in 0..w2 {
            rows[y * w2 + x] = (0..k).map(|i| kernel[i] * values[y * width + x + i]).sum();
        }
    }
    let mut out = vec![0.0; w2 * h2];
    for y in 0..h2 {
        for x in 0..w2 {
            out[y * w2 + x] = (0..k).map(|i| kernel[i] * rows[(y + i) * w2 + x]).sum();
        }
    }
    out
}

/// Mean SSIM of `image` against `reference` (see the module documentation).
pub fn ssim(image: &HdrImage, reference: &HdrImage) -> Result<f64, CompareError> {
    check(image, reference)?;
    let (w, h) = (image.width as usize, image.height as usize);
    if w < SSIM_WINDOW || h < SSIM_WINDOW {
        return Err(CompareError::TooSmall(image.width, image.height));
    }
    let half = (SSIM_WINDOW / 2) as f64;
    let mut kernel: Vec<f64> = (0..SSIM_WINDOW)
        .map(|i| (-((i as f64 - half).powi(2)) / (2.0 * SSIM_SIGMA * SSIM_SIGMA)).exp())
        .collect();
    let total: f64 = kernel.iter().sum();
    kernel.iter_mut().for_each(|k| *k /= total);
    let n = w * h;
    let x: Vec<f64> = luminance(image).into_iter().take(n).collect();
    let y: Vec<f64> = luminance(reference).into_iter().take(n).collect();
    let product =
        |a: &[f64], b: &[f64]| -> Vec<f64> { a.iter().zip(b).map(|(p, q)| p * q).collect() };
    let mu_x = blur(&x, w, h, &kernel);
    let mu_y = blur(&y, w, h, &kernel);
    let xx = blur(&product(&x, &x), w, h, &kernel);
    let yy = blur(&product(&y, &y), w, h, &kernel);
    let xy = blur(&product(&x, &y), w, h, &kernel);
    let c1 = (SSIM_K1 * DYNAMIC_RANGE).powi(2);
    let c2 = (SSIM_K2 * DYNAMIC_RANGE).powi(2);
    let sum: f64 = (0..mu_x.len())
        .map(|i| {
            let (mx, my) = (mu_x[i], mu_y[i]);
            let vx = xx[i] - mx * mx;
            let vy = yy[i] - my * my;
            let cov = xy[i] - mx * my;
            ((2.0 * mx * my + c1) * (2.0 * cov + c2)) / ((mx * mx + my * my + c1) * (vx + vy + c2))
        })
        .sum();
    Ok(sum / mu_x.len() as f64)
}

/// The clamped RGB of `image`, sRGB-encoded to 8 bits.
fn srgb8(image: &HdrImage) -> Vec<u8> {
    let n = image.width as usize * image.height as usize;
    image
        .texels
        .iter()
        .take(n)
        .flat_map(|t| [t[0], t[1], t[2]])
        .map(|c| (crate::capture::tonemap::srgb_oetf(c.clamp(0.0, 1.0)) * 255.0).round() as u8)
        .collect()
}

/// The per-pixel LDR-FLIP error of `image` against `reference` (see the module documentation).
fn flip_error(
    image: &HdrImage,
    reference: &HdrImage,
) -> Result<nv_flip::FlipImageFloat, CompareError> {
    check(image, reference)?;
    let (w, h) = (image.width, image.height);
    if w == 0 || h == 0 {
        return Err(CompareError::TooSmall(w, h));
    }
    let test = nv_flip::FlipImageRgb8::with_data(w, h, &srgb8(image));
    let reference = nv_flip::FlipImageRgb8::with_data(w, h, &srgb8(reference));
    Ok(nv_flip::flip(
        reference,
        test,
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    ))
}

/// Mean LDR-FLIP error of `image` against `reference` (see the module documentation).
pub fn flip(image: &HdrImage, reference: &HdrImage) -> Result<f64, CompareError> {
    let map = flip_error(image, reference)?;
    Ok(f64::from(nv_flip::FlipPool::from_image(&map).mean()))
}

/// The per-pixel FLIP error of `image` against `reference` on FLIP's magma colour map (black:
/// no visible difference, yellow-white: the largest), as FLIP's own tool writes it.
pub fn flip_map(image: &HdrImage, reference: &HdrImage) -> Result<LdrImage, CompareError> {
    let map = flip_error(image, reference)?.apply_color_lut(&nv_flip::magma_lut());
    Ok(LdrImage {
        width: image.width,
        height: image.height,
        texels: map
            .to_vec()
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2], 255])
            .collect(),
    })
}

/// RMSE (absolute and relative to the reference's mean), energy ratio, PSNR, SSIM and FLIP
/// of `image` against `reference`.
pub fn compare(image: &HdrImage, reference: &HdrImage) -> Result<Comparison, CompareError> {
    let rmse = rmse(image, reference)?;
    let (relative_rmse, energy_ratio) = relative_error(image, reference)?;
    Ok(Comparison {
        rmse,
        relative_rmse,
        energy_ratio,
        psnr: psnr_of_rmse(rmse),
        ssim: ssim(image, reference)?,
        flip: flip(image, reference)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::capture::image_io::grey_image as image;

    #[test]
    fn identical_images_are_perfect() {
        let a = image(16, 16, |x, y| ((x * 7 + y * 3) % 11) as f32 / 11.0);
        let c = compare(&a, &a).expect("compare");
        assert_eq!(c.rmse, 0.0);
        assert!(c.psnr.is_infinite());
        assert!((c.ssim - 1.0).abs() < 1e-12, "{}", c.ssim);
    }

    #[test]
    fn constant_offset_gives_known_rmse_and_psnr() {
        let a = image(16, 16, |_, _| 0.5);
        let b = image(16, 16, |_, _| 0.6);
        let c = compare(&a, &b).expect("compare");
        assert!((c.rmse - 0.1).abs() < 1e-6);
        assert!((c.psnr - 20.0).abs() < 1e-4);
        // The signal: against a reference of mean 0.6, 0.1 is 1/6 of it, and 0.5/0.6 of the
        // energy is there.
        assert!(
            (c.relative_rmse - 0.1 / 0.6).abs() < 1e-6,
            "{}",
            c.relative_rmse
        );
        assert!(
            (c.energy_ratio - 0.5 / 0.6).abs() < 1e-6,
            "{}",
            c.energy_ratio
        );
        // Flat images: SSIM is the luminance term (2·0.5·0.6 + C1) / (0.25 + 0.36 + C1).
        let c1 = 1e-4;
        assert!(
            (c.ssim - (0.6 + c1) / (0.61 + c1)).abs() < 1e-6,
            "{}",
            c.ssim
        );
    }

    #[test]
    fn values_are_clamped_to_the_dynamic_range() {
        let a = image(12, 12, |_, _| 5.0);
        let b = image(12, 12, |_, _| 1.0);
        assert_eq!(rmse(&a, &b), Ok(0.0));
    }

    #[test]
    fn structure_loss_lowers_ssim_more_than_brightness() {
        let reference = image(
            32,
            32,
            |x, y| if (x / 4 + y / 4) % 2 == 0 { 0.2 } else { 0.8 },
        );
        let blurred = image(32, 32, |_, _| 0.5);
        let brighter = image(
            32,
            32,
            |x, y| if (x / 4 + y / 4) % 2 == 0 { 0.25 } else { 0.85 },
        );
        assert!(ssim(&blurred, &reference).unwrap() < 0.2);
        assert!(ssim(&brighter, &reference).unwrap() > 0.95);
    }

    #[test]
    fn flip_is_zero_for_identical_images_and_grows_with_the_difference() {
        let reference = image(32, 32, |x, y| ((x * 7 + y * 3) % 16) as f32 / 16.0);
        assert_eq!(flip(&reference, &reference).unwrap(), 0.0);
        let near = image(32, 32, |x, y| ((x * 7 + y * 3) % 16) as f32 / 16.0 + 0.02);
        let far = image(32, 32, |x, y| ((x * 7 + y * 3) % 16) as f32 / 16.0 + 0.2);
        let (a, b) = (
            flip(&near, &reference).unwrap(),
            flip(&far, &reference).unwrap(),
        );
        assert!(0.0 < a && a < b && b <= 1.0, "{a} {b}");
        let empty = image(0, 0, |_, _| 0.0);
        assert_eq!(flip(&empty, &empty), Err(CompareError::TooSmall(0, 0)));
    }

    #[test]
    fn bad_inputs_are_errors() {
        let a = image(16, 16, |_, _| 0.0);
        let b = image(16, 15, |_, _| 0.0);
        assert_eq!(
            rmse(&a, &b),
            Err(CompareError::SizeMismatch(16, 16, 16, 15))
        );
        let tiny = image(8, 8, |_, _| 0.0);
        assert_eq!(ssim(&tiny, &tiny), Err(CompareError::TooSmall(8, 8)));
    }
}
