//! Quality studies: how a technique's error falls with the samples it spends, against a
//! high-sample truth of the same quantity (`shine study`).
//!
//! [`aaf`] is paper 004's error-vs-spp study (its Fig. 10 and §6): uniform Monte Carlo of the
//! diffuse indirect light, unfiltered and filtered, against AAF's adaptive sampling and filter
//! at several μ, and the samples (and time) uniform sampling needs to reach AAF's error. It
//! renders through the render graph directly ([`runner::AafRunner`]): the study needs
//! per-pixel sample counts and filter widths the frame does not expose. docs/quality.md holds
//! the measured numbers.
//!
//! A study reports its progress through [`Progress`] and never prints; the CLI draws the bars.

pub mod aaf;
pub mod metrics;
pub mod plot;
pub mod report;
pub mod runner;
pub mod switch_off;
pub mod temporal;
pub mod temporal_plot;

use crate::capture::image_io::ImageIoError;
use crate::frame::RenderError;

/// Why a study could not run or write its outputs.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// A study parameter is out of range.
    #[error("{0}")]
    Invalid(String),
    /// Rendering failed (device, graph, scene upload, AAF parameters).
    #[error(transparent)]
    Render(#[from] RenderError),
    /// An image could not be written.
    #[error(transparent)]
    Image(#[from] ImageIoError),
    /// The error plot could not be drawn.
    #[error("cannot draw the plot {0}")]
    Plot(String),
    /// The scene has nothing to measure (no lit, non-background pixel).
    #[error("{0}")]
    NothingToMeasure(String),
}

/// Where a long study reports how far it is (the CLI shows progress bars; tests ignore it).
pub trait Progress {
    /// A new stage `name` of `total` steps begins (the previous one is finished).
    fn stage(&mut self, name: &str, total: u64);
    /// `steps` more steps of the stage are done; `message` says what runs now.
    fn advance(&mut self, steps: u64, message: &str);
    /// The study is done.
    fn finish(&mut self);
}

/// A [`Progress`] that shows nothing.
#[derive(Debug, Default, Clone, Copy)]
pub struct Silent;

impl Progress for Silent {
    fn stage(&mut self, _: &str, _: u64) {}
    fn advance(&mut self, _: u64, _: &str) {}
    fn finish(&mut self) {}
}
