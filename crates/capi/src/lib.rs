//! shine's GI context for C and C++ hosts (docs/embedding.md, "C API"): the Rust
//! [`shine::embed::GiContext`] behind opaque handles, with `VkResult`-style codes
//! ([`ShineResult`]) and a message getter ([`shine_last_error`]). The header, `shine.h`, is
//! generated from this crate by cbindgen (build.rs) and is pure C99: Vulkan handles appear as
//! its own types, so it needs no Vulkan header.
//!
//! Every descriptor struct starts with a `version` the caller sets to the matching
//! `SHINE_*_VERSION`: a library built for another layout refuses it instead of misreading it.
//! Handles are numbers, never reused, that the library looks up: a null, destroyed or
//! wrong-kind handle is refused with a code and a message, never dereferenced.

mod context;
mod device;
mod error;
mod geometry;
mod handles;
mod scene;
mod types;

pub use context::*;
pub use device::*;
pub use error::{ShineResult, shine_last_error};
pub use geometry::*;
pub use handles::{
    ShineContext, ShineContext_T, ShineDevice, ShineDevice_T, ShineScene, ShineScene_T,
};
pub use scene::*;
pub use types::*;
