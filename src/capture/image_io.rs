//! Frame output: PNG (8-bit, sRGB-encoded, tonemapped) and OpenEXR (32-bit float, linear HDR).
//!
//! Every write is atomic (docs/architecture.md, "Errors and bad input"): the image is encoded into a temporary file in the target's
//! directory, flushed to disk, then renamed over the target. A failure at any step removes the
//! temporary file, so the target is either the complete new image or left as it was — never a
//! half-written file.

use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Why an image could not be written or read; each names the file and what to do.
#[derive(Debug, thiserror::Error)]
pub enum ImageIoError {
    /// The output path's extension names no format shine writes.
    #[error(
        "cannot tell the image format of {}: use the extension .png (tonemapped 8-bit sRGB) \
         or .exr (linear HDR)",
        path.display()
    )]
    UnknownFormat {
        /// The path given.
        path: PathBuf,
    },
    /// The texel data does not match the stated size.
    #[error("a {width}×{height} image needs {expected} bytes of texels, {given} given")]
    SizeMismatch {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// Bytes the size implies.
        expected: usize,
        /// Bytes given.
        given: usize,
    },
    /// Creating, writing or renaming the file failed.
    #[error("cannot write {}: {source} (check that the directory exists and is writable)", path.display())]
    Io {
        /// The target file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The encoder rejected the image.
    #[error("cannot encode {}: {source}", path.display())]
    Encode {
        /// The target file.
        path: PathBuf,
        /// The encoder's error.
        source: image::ImageError,
    },
    /// Reading or decoding an image file failed.
    #[error("cannot read image {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The decoder's error.
        source: image::ImageError,
    },
}

/// The output formats, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// `.png`: the tonemapped LDR frame, RGBA 8-bit, sRGB-encoded.
    Png,
    /// `.exr`: the exposed HDR frame, RGBA 32-bit float, linear Rec.709 (never tonemapped).
    Exr,
}

impl OutputFormat {
    /// The format a path's extension asks for (case-insensitive `.png` or `.exr`).
    pub fn from_path(path: &Path) -> Result<Self, ImageIoError> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("exr") => Ok(Self::Exr),
            _ => Err(ImageIoError::UnknownFormat {
                path: path.to_owned(),
            }),
        }
    }
}

/// An RGBA 8-bit image, rows top to bottom, sRGB-encoded (the `ldr` output).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` texels, row-major.
    pub texels: Vec<[u8; 4]>,
}

/// An RGBA 32-bit float image, rows top to bottom, linear radiance (the `hdr` output).
#[derive(Debug, Clone, PartialEq)]
pub struct HdrImage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` texels, row-major.
    pub texels: Vec<[f32; 4]>,
}

/// Checks that `bytes` holds exactly `width × height` texels of `texel_size` bytes.
fn check_size(
    width: u32,
    height: u32,
    texel_size: usize,
    given: usize,
) -> Result<(), ImageIoError> {
    let expected = width as usize * height as usize * texel_size;
    if expected == given && expected > 0 {
        Ok(())
    } else {
        Err(size_error(width, height, texel_size, given))
    }
}

impl LdrImage {
    /// Wraps tightly packed RGBA8 bytes, as read back from an `R8G8B8A8_UNORM` image.
    pub fn from_rgba8_bytes(width: u32, height: u32, bytes: &[u8]) -> Result<Self, ImageIoError> {
        check_size(width, height, 4, bytes.len())?;
        Ok(Self {
            width,
            height,
            texels: bytemuck::pod_collect_to_vec(bytes),
        })
    }
}

impl HdrImage {
    /// Wraps tightly packed little-endian RGBA32F bytes, as read back from an
    /// `R32G32B32A32_SFLOAT` image.
    pub fn from_rgba32f_bytes(width: u32, height: u32, bytes: &[u8]) -> Result<Self, ImageIoError> {
        check_size(width, height, 16, bytes.len())?;
        Ok(Self {
            width,
            height,
            texels: bytemuck::pod_collect_to_vec(bytes),
        })
    }
}

/// Writes `image` as an 8-bit RGBA PNG, atomically.
pub fn write_png(path: &Path, image: &LdrImage) -> Result<(), ImageIoError> {
    let bytes: &[u8] = bytemuck::cast_slice(&image.texels);
    check_size(image.width, image.height, 4, bytes.len())?;
    let buffer = image::RgbaImage::from_raw(image.width, image.height, bytes.to_vec())
        .ok_or_else(|| size_error(image.width, image.height, 4, bytes.len()))?;
    write_atomically(path, |w| {
        buffer
            .write_to(w, image::ImageFormat::Png)
            .map_err(|e| encode_error(path, e))
    })
}

/// Writes `image` as a 32-bit float RGBA OpenEXR, atomically. Values are stored exactly.
pub fn write_exr(path: &Path, image: &HdrImage) -> Result<(), ImageIoError> {
    check_size(image.width, image.height, 16, image.texels.len() * 16)?;
    let floats: Vec<f32> = image.texels.iter().flatten().copied().collect();
    let buffer = image::Rgba32FImage::from_raw(image.width, image.height, floats)
        .ok_or_else(|| size_error(image.width, image.height, 16, image.texels.len() * 16))?;
    write_atomically(path, |w| {
        buffer
            .write_to(w, image::ImageFormat::OpenExr)
            .map_err(|e| encode_error(path, e))
    })
}

/// The size error for a buffer the encoder's container refused.
fn size_error(width: u32, height: u32, texel_size: usize, given: usize) -> ImageIoError {
    ImageIoError::SizeMismatch {
        width,
        height,
        expected: width as usize * height as usize * texel_size,
        given,
    }
}

/// Reads an OpenEXR file as RGBA32F (for comparisons against references).
pub fn read_exr(path: &Path) -> Result<HdrImage, ImageIoError> {
    let decoded = open(path, image::ImageFormat::OpenExr)?.into_rgba32f();
    Ok(HdrImage {
        width: decoded.width(),
        height: decoded.height(),
        texels: decoded.pixels().map(|p| p.0).collect(),
    })
}

/// Reads a PNG file as RGBA8 (for comparisons against references).
pub fn read_png(path: &Path) -> Result<LdrImage, ImageIoError> {
    let decoded = open(path, image::ImageFormat::Png)?.into_rgba8();
    Ok(LdrImage {
        width: decoded.width(),
        height: decoded.height(),
        texels: decoded.pixels().map(|p| p.0).collect(),
    })
}

/// Reads a PNG as the light it displays: 8-bit sRGB decoded to linear [0, 1] (alpha 1). For
/// comparing tonemapped images: the values are what a screen shows, not scene radiance.
pub fn read_png_linear(path: &Path) -> Result<HdrImage, ImageIoError> {
    let ldr = read_png(path)?;
    let decode = |v: u8| crate::capture::tonemap::srgb_eotf(f32::from(v) / 255.0);
    Ok(HdrImage {
        width: ldr.width,
        height: ldr.height,
        texels: ldr
            .texels
            .iter()
            .map(|t| [decode(t[0]), decode(t[1]), decode(t[2]), 1.0])
            .collect(),
    })
}

/// Decodes `path` as `format`, whatever its extension says.
fn open(path: &Path, format: image::ImageFormat) -> Result<image::DynamicImage, ImageIoError> {
    let read_error = |source| ImageIoError::Read {
        path: path.to_owned(),
        source,
    };
    let file = File::open(path).map_err(|e| read_error(image::ImageError::IoError(e)))?;
    image::load(std::io::BufReader::new(file), format).map_err(read_error)
}

/// Distinguishes temporary files of concurrent writes within one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// A temporary file next to the target, removed on drop unless it was renamed into place.
struct TempFile {
    path: PathBuf,
    keep: bool,
}

impl Drop for TempFile {
    fn drop(&mut self) {
        if !self.keep {
            // Best effort: the write already failed and that error is what the caller sees.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// Writes `bytes` to `path` atomically (temporary file in the same directory, then rename):
/// for reports and traces as much as images.
pub fn write_bytes_atomically(path: &Path, bytes: &[u8]) -> Result<(), ImageIoError> {
    write_atomically(path, |w| w.write_all(bytes).map_err(|e| io_error(path, e)))
}

/// Removes the temporary files that writes of `path` (`write_atomically`) left behind when
/// their process was killed: a re-queued task calls it for the files it is about to write, so
/// no half-written file stays beside them. Only for paths no other running process writes.
pub fn remove_stale_temporaries(path: &Path) -> Result<(), ImageIoError> {
    let Some(name) = path.file_name() else {
        return Ok(());
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let entries = match std::fs::read_dir(dir) {
        Ok(entries) => entries,
        // No folder yet: nothing was left there (the write reports the missing folder).
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_error(path, e)),
    };
    for entry in entries {
        let entry = entry.map_err(|e| io_error(path, e))?;
        let file = entry.file_name().to_string_lossy().into_owned();
        // Exactly `.{name}.{pid}-{counter}.tmp`, what `write_atomically` names them.
        let ours = file
            .strip_prefix(&prefix)
            .and_then(|rest| rest.strip_suffix(".tmp"))
            .and_then(|id| id.split_once('-'))
            .is_some_and(|(pid, n)| {
                let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
                digits(pid) && digits(n)
            });
        if ours {
            std::fs::remove_file(entry.path()).map_err(|e| io_error(&entry.path(), e))?;
        }
    }
    Ok(())
}

/// The I/O error of writing `path`.
fn io_error(path: &Path, source: std::io::Error) -> ImageIoError {
    ImageIoError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The encoder error of writing `path`.
fn encode_error(path: &Path, source: image::ImageError) -> ImageIoError {
    ImageIoError::Encode {
        path: path.to_owned(),
        source,
    }
}

/// Runs `write` into a temporary file in `path`'s directory, syncs it, and renames it to
/// `path`; on any failure the temporary file is removed.
fn write_atomically(
    path: &Path,
    write: impl FnOnce(&mut BufWriter<File>) -> Result<(), ImageIoError>,
) -> Result<(), ImageIoError> {
    let name = path.file_name().ok_or_else(|| {
        io_error(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "the path names no file"),
        )
    })?;
    let temp_name = format!(
        ".{}.{}-{}.tmp",
        name.to_string_lossy(),
        std::process::id(),
        TEMP_COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let mut temp = TempFile {
        path: path.with_file_name(temp_name),
        keep: false,
    };
    let file = OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&temp.path)
        .map_err(|e| io_error(path, e))?;
    let mut writer = BufWriter::new(file);
    write(&mut writer)?;
    let file = writer
        .into_inner()
        .map_err(|e| io_error(path, e.into_error()))?;
    file.sync_all().map_err(|e| io_error(path, e))?;
    drop(file);
    std::fs::rename(&temp.path, path).map_err(|e| io_error(path, e))?;
    temp.keep = true;
    Ok(())
}

/// Writes the frame in the format `path`'s extension names: the LDR image for `.png`, the HDR
/// image for `.exr`.
pub fn write_frame(path: &Path, ldr: &LdrImage, hdr: &HdrImage) -> Result<(), ImageIoError> {
    match OutputFormat::from_path(path)? {
        OutputFormat::Png => write_png(path, ldr),
        OutputFormat::Exr => write_exr(path, hdr),
    }
}

/// A grey test image: every pixel's rgb is `f(x, y)`, alpha 1 (the image tests' input).
#[cfg(test)]
pub(crate) fn grey_image(width: u32, height: u32, f: impl Fn(u32, u32) -> f32) -> HdrImage {
    HdrImage {
        width,
        height,
        texels: (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| {
                let v = f(x, y);
                [v, v, v, 1.0]
            })
            .collect(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh, empty directory for one test, removed when dropped.
    struct Scratch(PathBuf);

    impl Scratch {
        fn new(test: &str) -> Self {
            let dir =
                std::env::temp_dir().join(format!("shine-image-io-{}-{test}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).unwrap();
            Self(dir)
        }

        fn entries(&self) -> Vec<String> {
            let mut names: Vec<String> = std::fs::read_dir(&self.0)
                .unwrap()
                .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
                .collect();
            names.sort();
            names
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    fn hdr_ramp(width: u32, height: u32) -> HdrImage {
        let texels = (0..width * height)
            .map(|i| {
                let x = i as f32;
                [x * 0.37, 1e-7 * x, 1000.0 + x * 3.1, 1.0 / (x + 1.0)]
            })
            .collect();
        HdrImage {
            width,
            height,
            texels,
        }
    }

    fn ldr_ramp(width: u32, height: u32) -> LdrImage {
        let texels = (0..width * height)
            .map(|i| {
                [
                    (i % 256) as u8,
                    (i * 7 % 256) as u8,
                    255 - (i % 256) as u8,
                    200,
                ]
            })
            .collect();
        LdrImage {
            width,
            height,
            texels,
        }
    }

    #[test]
    fn exr_round_trip_is_exact() {
        let scratch = Scratch::new("exr");
        let path = scratch.0.join("frame.exr");
        let image = hdr_ramp(13, 7);
        write_exr(&path, &image).unwrap();
        let back = read_exr(&path).unwrap();
        assert_eq!(back.width, 13);
        assert_eq!(back.height, 7);
        let bits =
            |i: &HdrImage| -> Vec<u32> { i.texels.iter().flatten().map(|f| f.to_bits()).collect() };
        assert_eq!(bits(&back), bits(&image));
        assert_eq!(scratch.entries(), ["frame.exr"]);
    }

    #[test]
    fn png_round_trip_is_exact() {
        let scratch = Scratch::new("png");
        let path = scratch.0.join("frame.PNG");
        let image = ldr_ramp(17, 5);
        write_frame(&path, &image, &hdr_ramp(1, 1)).unwrap();
        assert_eq!(read_png(&path).unwrap(), image);
        assert_eq!(scratch.entries(), ["frame.PNG"]);
    }

    #[test]
    fn rewriting_replaces_the_file() {
        let scratch = Scratch::new("rewrite");
        let path = scratch.0.join("frame.png");
        write_png(&path, &ldr_ramp(4, 4)).unwrap();
        let second = ldr_ramp(8, 2);
        write_png(&path, &second).unwrap();
        assert_eq!(read_png(&path).unwrap(), second);
        assert_eq!(scratch.entries(), ["frame.png"]);
    }

    #[test]
    fn bytes_from_readback_wrap() {
        let bytes: Vec<u8> = (0..2 * 16).map(|i| i as u8).collect();
        let hdr = HdrImage::from_rgba32f_bytes(2, 1, &bytes).unwrap();
        assert_eq!(hdr.texels[1][0].to_le_bytes(), [16, 17, 18, 19]);
        let ldr = LdrImage::from_rgba8_bytes(4, 2, &bytes).unwrap();
        assert_eq!(ldr.texels[7], [28, 29, 30, 31]);
        let message = HdrImage::from_rgba32f_bytes(3, 1, &bytes)
            .unwrap_err()
            .to_string();
        assert_eq!(message, "a 3×1 image needs 48 bytes of texels, 32 given");
    }

    #[test]
    fn unknown_extensions_are_refused_by_name() {
        let scratch = Scratch::new("ext");
        for name in ["frame.jpg", "frame", "frame.png.bak"] {
            let path = scratch.0.join(name);
            let message = write_frame(&path, &ldr_ramp(2, 2), &hdr_ramp(2, 2))
                .unwrap_err()
                .to_string();
            assert!(
                message.contains(name) && message.contains(".exr"),
                "{message}"
            );
        }
        assert!(scratch.entries().is_empty());
    }

    #[test]
    fn stale_temporaries_of_one_file_are_removed_and_no_other() {
        let scratch = Scratch::new("stale");
        for name in [
            ".ref.4242-0.tmp",
            ".ref.7-13.tmp",
            ".ref.part.4242-0.tmp",
            ".ref.x.tmp",
            "ref",
        ] {
            std::fs::write(scratch.0.join(name), b"x").unwrap();
        }
        remove_stale_temporaries(&scratch.0.join("ref")).unwrap();
        assert_eq!(
            scratch.entries(),
            [".ref.part.4242-0.tmp", ".ref.x.tmp", "ref"]
        );
    }

    #[test]
    fn a_failed_write_leaves_nothing_behind() {
        let scratch = Scratch::new("fail");
        // A missing directory: nothing can be created.
        let missing = scratch.0.join("no-such-dir").join("frame.exr");
        let message = write_exr(&missing, &hdr_ramp(2, 2))
            .unwrap_err()
            .to_string();
        assert!(message.contains("no-such-dir"), "{message}");
        // The target is a directory: the image is fully encoded, then the rename fails; the
        // temporary file must be gone and the directory untouched.
        std::fs::create_dir(scratch.0.join("taken.png")).unwrap();
        let message = write_png(&scratch.0.join("taken.png"), &ldr_ramp(3, 3))
            .unwrap_err()
            .to_string();
        assert!(message.contains("taken.png"), "{message}");
        assert_eq!(scratch.entries(), ["taken.png"]);
        assert!(scratch.0.join("taken.png").is_dir());
        // Wrong texel count: refused before any file is created.
        let bad = LdrImage {
            width: 3,
            height: 3,
            texels: vec![[0; 4]; 4],
        };
        assert!(write_png(&scratch.0.join("bad.png"), &bad).is_err());
        assert_eq!(scratch.entries(), ["taken.png"]);
    }
}
