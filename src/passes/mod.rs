//! The passes of a frame (DESIGN §4): each adds its work to a [`crate::graph::RenderGraph`],
//! returns its output handles and has a CPU reference used by its GPU test.

pub mod receivers;
pub mod upsample;
