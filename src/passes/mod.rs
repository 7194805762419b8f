//! The passes of a frame (DESIGN §4), one module each: a function that adds the pass to a
//! render graph and returns its output handles. Formats and units: docs/frame.md.

pub mod direct;
pub mod gbuffer;
