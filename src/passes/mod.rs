//! The passes of a frame (docs/architecture.md, docs/frame.md): one module per pass, each adding its work
//! to a [`crate::graph::RenderGraph`] and returning its output handles, with a CPU reference of
//! the same computation for its GPU test where one exists.

pub mod aaf;
pub mod brdf_tables;
pub mod composite;
pub mod direct;
pub mod gbuffer;
pub mod gi_add;
pub mod hvl;
pub mod igi;
pub mod path_trace;
pub mod proxy;
pub mod receivers;
pub mod rsm;
pub mod shadows;
pub mod upsample;
