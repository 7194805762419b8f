//! Pass declarations: a name, what the pass does to which resource version, how often it runs.

use crate::access::AnyAccess;
use crate::handle::ResourceId;

/// Index of a pass in declaration order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
pub struct PassId(pub u32);

/// What kind of work a pass records (used for the plan dump and by the executor).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum PassKind {
    /// A compute dispatch.
    Compute,
    /// Draws inside dynamic rendering.
    Raster,
    /// Copies, clears, fills and blits.
    Transfer,
    /// A closure recording whatever it wants.
    Raw,
}

/// How often a pass runs: on frames where `frame % period == phase`. Its outputs must persist
/// (imported or temporal resources) so they stay valid on the frames it skips.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct UpdateRate {
    /// Run every `period` frames (1: every frame).
    pub period: u32,
    /// Which frame of the period it runs on (taken modulo `period`).
    pub phase: u32,
}

impl UpdateRate {
    /// Every frame.
    pub const EVERY_FRAME: Self = Self {
        period: 1,
        phase: 0,
    };

    /// Whether a pass with this rate runs on `frame`.
    pub fn runs_on(&self, frame: u64) -> bool {
        self.period == 0 || frame % u64::from(self.period) == u64::from(self.phase % self.period)
    }
}

/// The work a pass does, declared by the code that records it (for `shine profile --roofline`):
/// floating-point operations and bytes moved to or from memory per run, each counted by a
/// formula documented beside the pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct PassCost {
    /// Floating-point operations (a fused multiply-add counts two).
    pub flops: u64,
    /// Bytes read from and written to memory (not counting cache hits the formula rules out).
    pub bytes: u64,
}

/// Whether an access record reads the version it names or writes the next one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Direction {
    /// Reads `version`.
    Read,
    /// Writes `version + 1` over `version`.
    Write,
}

/// One declared access of a pass.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) struct AccessRecord {
    pub resource: ResourceId,
    pub version: u32,
    pub direction: Direction,
    pub access: AnyAccess,
}

/// A declared pass, as the compiler sees it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) struct PassDecl {
    pub name: String,
    pub kind: PassKind,
    pub accesses: Vec<AccessRecord>,
    pub rate: UpdateRate,
    pub cost: Option<PassCost>,
}
