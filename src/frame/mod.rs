//! The frame: the renderer that owns a scene on the device, the technique objects that own
//! their persistent state, and the composition of their passes into one render graph per frame
//! (docs/architecture.md, "The frame" and "The life of a technique").
//!
//! Each technique is one object with `prepare` (upload what its parameters need, import it
//! into the frame's graph, return a typed prepared state) and, on that state, `declare` (add
//! its passes, return its output image). A technique that was not prepared has no state to
//! declare with. `Renderer::declare_frame` composes them in one place.

pub mod aaf;
pub mod accumulate;
pub mod cubes;
pub mod error;
pub mod exposure;
pub mod hvl;
pub mod igi;
pub mod memory;
pub mod motion;
pub mod params;
pub mod proxy;
pub mod renderer;
pub mod shadows;

pub use error::RenderError;
