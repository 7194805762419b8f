//! A sequence's frames split over processes: the frames a process writes (`--frame-range A..B`
//! or a [`Shard`](super::Shard) of them) and the frames it renders before them, unwritten, to
//! warm its histories up ([`SequenceSlice::warm_up`]).

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use crate::passes::accumulate::TAA_MAX_FRAMES;
use crate::passes::amortise::RESOLVE_ALPHA;
use crate::settings::Settings;

/// Frames rendered, unwritten, before a slice's first frame, in units of its longest history
/// ([`longest_history`], [`SequenceSlice::warm_up`]). Every history blends each new frame in
/// with a weight of at least 1/n, so what a cold start lacks against the one-process run's
/// history shrinks by (1 − 1/n) per frame, but an exponential average never forgets: after
/// 8 n frames, frames 96..104 of `builtin:animated` and `builtin:room` (32², defaults) differ from
/// the one-process run's by 1e-6 to 2e-6 RMSE (relative < 1e-5), not bit for bit. The frames are
/// bit for bit the one-process run's when the warm-up reaches frame 0 (`--warm-up` ≥ A), and for
/// any range when the frames keep no history (docs/many-machines.md).
pub const WARM_UP_HISTORIES: u32 = 8;

/// Frames `start..end` of a sequence (end exclusive; `A..=B` includes B).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// First frame written.
    pub start: u32,
    /// One past the last frame written.
    pub end: u32,
}

/// Why a frame range was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("frame range `{text}`: {why}")]
pub struct FrameRangeError {
    text: String,
    why: String,
}

impl FromStr for FrameRange {
    type Err = FrameRangeError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let error = |why: &str| FrameRangeError {
            text: s.to_owned(),
            why: why.to_owned(),
        };
        let (a, b, inclusive) = match s.split_once("..=") {
            Some((a, b)) => (a, b, true),
            None => {
                let (a, b) = s.split_once("..").ok_or_else(|| {
                    error("write A..B (frames A to B − 1) or A..=B (frames A to B)")
                })?;
                (a, b, false)
            }
        };
        let number = |t: &str| {
            t.trim()
                .parse::<u32>()
                .map_err(|_| error("A and B must be frame numbers (from 0)"))
        };
        let (start, last) = (number(a)?, number(b)?);
        let end = if inclusive {
            last.checked_add(1).ok_or_else(|| error("B is too large"))?
        } else {
            last
        };
        if end <= start {
            return Err(error("the range holds no frame"));
        }
        Ok(Self { start, end })
    }
}

impl fmt::Display for FrameRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.start, self.end)
    }
}

/// The frames one process of a sequence renders: `written` (its share), after the warm-up
/// frames `rendered.start..written.start`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SequenceSlice {
    /// Every frame rendered, warm-up included.
    pub rendered: Range<u32>,
    /// The frames written.
    pub written: Range<u32>,
}

impl SequenceSlice {
    /// The slice writing `range` of a `frames`-frame sequence after `warm_up` frames
    /// ([`SequenceSlice::warm_up`] by default); refused when the range leaves the sequence.
    pub fn new(range: FrameRange, frames: u32, warm_up: u32) -> Result<Self, FrameRangeError> {
        if range.end > frames {
            return Err(FrameRangeError {
                text: range.to_string(),
                why: format!("the sequence has frames 0..{frames} (--frames {frames})"),
            });
        }
        Ok(Self {
            rendered: range.start.saturating_sub(warm_up)..range.end,
            written: range.start..range.end,
        })
    }

    /// The whole sequence in one process.
    pub fn whole(frames: u32) -> Self {
        Self {
            rendered: 0..frames,
            written: 0..frames,
        }
    }

    /// Warm-up frames before a slice whose longest history is `history` frames:
    /// [`WARM_UP_HISTORIES`] of them (none without a history).
    pub fn warm_up(history: u32) -> u32 {
        if history <= 1 {
            0
        } else {
            history.saturating_mul(WARM_UP_HISTORIES)
        }
    }
}

/// The longest memory, in frames, of the histories a sequence rendered with `settings` keeps:
/// the indirect light's (`history.frames`), TAA's ([`TAA_MAX_FRAMES`]) when on, the automatic
/// exposure's (1 / `output.adaptation`) when the frames are tonemapped (`ldr`) with it, and an
/// amortised technique's (`*.slices` frames per refresh, each refresh blending in
/// [`RESOLVE_ALPHA`] of the fresh light: slices / α), and HVL's and IGI's samples' own
/// (1 / `history.samples`, which `history.frames = 1` leaves on).
pub fn longest_history(settings: &Settings, ldr: bool) -> u32 {
    let taa = if settings.output.taa {
        TAA_MAX_FRAMES
    } else {
        1
    };
    let exposure = if ldr && settings.output.auto_exposure {
        (1.0 / settings.output.adaptation).ceil() as u32
    } else {
        1
    };
    let slices = [
        settings.hvl.slices,
        settings.igi.slices,
        settings.aaf.slices,
        settings.proxy.slices,
        settings.cubes.slices,
    ]
    .into_iter()
    .max()
    .unwrap_or(1);
    let amortised = if slices > 1 {
        (slices as f32 / RESOLVE_ALPHA).ceil() as u32
    } else {
        1
    };
    let samples = if settings.history.samples < 1.0 {
        (1.0 / settings.history.samples).ceil() as u32
    } else {
        1
    };
    settings
        .history
        .max_frames
        .max(taa)
        .max(exposure)
        .max(amortised)
        .max(samples)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_parse_exclusive_and_inclusive() {
        assert_eq!("4..8".parse(), Ok(FrameRange { start: 4, end: 8 }));
        assert_eq!("4..=8".parse(), Ok(FrameRange { start: 4, end: 9 }));
        for bad in ["8..4", "4..4", "4", "a..3", "1..=x"] {
            let err = bad.parse::<FrameRange>().unwrap_err().to_string();
            assert!(err.contains(bad), "{err}");
        }
    }

    #[test]
    fn slices_warm_up_inside_the_sequence() {
        let range = FrameRange { start: 40, end: 48 };
        let slice = SequenceSlice::new(range, 64, 12).unwrap();
        assert_eq!(slice.written, 40..48);
        assert_eq!(slice.rendered, 28..48);
        let early = SequenceSlice::new(FrameRange { start: 2, end: 6 }, 64, 8).unwrap();
        assert_eq!(early.rendered, 0..6);
        assert_eq!(SequenceSlice::new(range, 64, 0).unwrap().rendered, 40..48);
        assert!(SequenceSlice::new(range, 47, 8).is_err());
        assert_eq!(SequenceSlice::warm_up(1), 0);
        assert_eq!(SequenceSlice::warm_up(4), 4 * WARM_UP_HISTORIES);
    }

    #[test]
    fn every_history_counts() {
        let mut settings = Settings::default();
        settings.history.max_frames = 1;
        settings.history.samples = 1.0;
        settings.output.auto_exposure = false;
        assert_eq!(longest_history(&settings, true), 1);
        settings.history.samples = 0.25;
        assert_eq!(longest_history(&settings, true), 4);
        settings.hvl.slices = 4;
        assert_eq!(longest_history(&settings, false), 8);
        settings.output.taa = true;
        assert_eq!(longest_history(&settings, false), TAA_MAX_FRAMES);
        settings.output.auto_exposure = true;
        settings.output.adaptation = 0.01;
        assert_eq!(longest_history(&settings, false), TAA_MAX_FRAMES);
        assert_eq!(longest_history(&settings, true), 100);
    }
}
