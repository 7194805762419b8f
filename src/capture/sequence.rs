//! Image sequences: output paths with a frame field (`out/frame_%04d.png`) and the camera
//! paths a static scene can be captured along (`--camera-orbit`).

use std::path::{Path, PathBuf};

use glam::{Mat4, Vec3};

/// An output path with at most one printf-style frame field: `%d` or `%0Nd` (N = 1..=9).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FramePattern {
    /// The text before the field (the whole path when there is none).
    prefix: String,
    /// The text after the field.
    suffix: String,
    /// Zero-padded width of the field; `None` when the path has no field.
    width: Option<usize>,
}

/// Why an output pattern was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PatternError {
    /// Several frames would all go to one file.
    #[error(
        "`{0}` has no frame field but {1} frames were asked for: put %d or %04d in the file name (e.g. out/frame_%04d.png)"
    )]
    NoField(String, u32),
    /// A `%` that is not a supported frame field, or more than one field.
    #[error("`{0}`: {1}")]
    Malformed(String, &'static str),
}

impl FramePattern {
    /// Parses `path` for a sequence of `frames` frames.
    pub fn parse(path: &Path, frames: u32) -> Result<Self, PatternError> {
        let text = path.to_string_lossy().into_owned();
        let malformed = |why| PatternError::Malformed(text.clone(), why);
        let mut found: Option<(usize, usize, Option<usize>)> = None;
        let bytes = text.as_bytes();
        let mut i = 0;
        while i < bytes.len() {
            if bytes[i] != b'%' {
                i += 1;
                continue;
            }
            // `%d` or `%0Nd`.
            let (end, width) = match (bytes.get(i + 1), bytes.get(i + 2), bytes.get(i + 3)) {
                (Some(b'd'), ..) => (i + 2, 1),
                (Some(b'0'), Some(n @ b'1'..=b'9'), Some(b'd')) => (i + 4, usize::from(n - b'0')),
                _ => {
                    return Err(malformed(
                        "a % must start a frame field, %d or %0Nd (N = 1–9)",
                    ));
                }
            };
            if found.is_some() {
                return Err(malformed("only one frame field is allowed"));
            }
            found = Some((i, end, Some(width)));
            i = end;
        }
        match found {
            Some((start, end, width)) => Ok(Self {
                prefix: text[..start].to_owned(),
                suffix: text[end..].to_owned(),
                width,
            }),
            None if frames > 1 => Err(PatternError::NoField(text, frames)),
            None => Ok(Self {
                prefix: text,
                suffix: String::new(),
                width: None,
            }),
        }
    }

    /// The path with `text` in place of the frame field (appended to the path when it has
    /// none: `x.png` gives `x.png` + `text`).
    pub fn with_field(&self, text: &str) -> PathBuf {
        PathBuf::from(format!("{}{text}{}", self.prefix, self.suffix))
    }

    /// The path of frame `index`.
    pub fn path(&self, index: u32) -> PathBuf {
        match self.width {
            Some(w) => PathBuf::from(format!("{}{index:0w$}{}", self.prefix, self.suffix)),
            None => PathBuf::from(&self.prefix),
        }
    }
}

/// The camera-to-world matrix `camera` turned by `degrees` about the vertical (+Y) axis
/// through `center`: a turntable orbit around the scene.
pub fn orbit(camera: Mat4, center: Vec3, degrees: f32) -> Mat4 {
    Mat4::from_translation(center)
        * Mat4::from_rotation_y(degrees.to_radians())
        * Mat4::from_translation(-center)
        * camera
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_are_expanded_and_padded() {
        let p = FramePattern::parse(Path::new("out/f_%04d.png"), 12).unwrap();
        assert_eq!(p.path(7), PathBuf::from("out/f_0007.png"));
        assert_eq!(p.path(12345), PathBuf::from("out/f_12345.png"));
        let p = FramePattern::parse(Path::new("f%d.exr"), 3).unwrap();
        assert_eq!(p.path(2), PathBuf::from("f2.exr"));
    }

    #[test]
    fn a_single_frame_needs_no_field() {
        let p = FramePattern::parse(Path::new("out.png"), 1).unwrap();
        assert_eq!(p.path(0), PathBuf::from("out.png"));
    }

    #[test]
    fn bad_patterns_are_refused() {
        assert!(matches!(
            FramePattern::parse(Path::new("out.png"), 2),
            Err(PatternError::NoField(_, 2))
        ));
        for bad in ["a%s.png", "a%04x.png", "%d_%d.png", "a%.png", "a%00d.png"] {
            assert!(
                matches!(
                    FramePattern::parse(Path::new(bad), 4),
                    Err(PatternError::Malformed(..))
                ),
                "{bad}"
            );
        }
    }

    #[test]
    fn orbit_keeps_the_distance_to_the_centre() {
        let camera = Mat4::from_translation(Vec3::new(3.0, 1.0, 0.0));
        let c = Vec3::new(1.0, 0.0, 0.0);
        let moved = orbit(camera, c, 90.0).transform_point3(Vec3::ZERO);
        assert!((moved.distance(c) - Vec3::new(3.0, 1.0, 0.0).distance(c)).abs() < 1e-5);
        assert!((moved - Vec3::new(1.0, 1.0, -2.0)).length() < 1e-5);
        assert_eq!(orbit(camera, c, 0.0), camera);
    }
}
