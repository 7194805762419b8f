//! The passes of the frame (DESIGN §4), one module per pass.

pub mod hvl;
