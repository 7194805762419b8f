//! shine: a real-time soft global-illumination engine on Vulkan 1.3.
//!
//! The engine is a set of compute and raster passes (docs/architecture.md, "The frame") on [`shine_gpu`]; every
//! shader under `shaders/` is compiled and reflected at build time into [`shaders`].

#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

pub use shine_gpu as gpu;
pub use shine_graph as graph;
/// The scene format (`shine_scene`): what `GiContext::set_scene` and `Renderer::set_scene` take.
pub use shine_scene as scene;

pub mod capture;
pub mod choice;
pub mod declare;
pub mod embed;
pub mod farm;
pub mod frame;
pub mod gpu_scene;
pub mod lab;
pub mod passes;
pub mod profile;
pub mod reference;
pub mod settings;
pub mod study;

pub use frame::RenderError;
pub use frame::renderer::{FrameImage, HostTarget, Renderer};
pub use gpu_scene::{CameraPose, FrameUpdate};
pub use settings::Settings;

/// Every shader of the engine, compiled to SPIR-V 1.5 and reflected by naga at build time.
///
/// One `pub static` per shader (and per `//! variant` of it), named after its path:
/// `sh_eval.comp` variant `bands3` is [`shaders::SH_EVAL_COMP_BANDS3`].
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

    /// Looks a shader up by its name (`"sh_eval.comp:bands3"`).
    pub fn get(name: &str) -> Option<&'static shine_gpu::ShaderDesc> {
        ALL.iter().copied().find(|s| s.name == name)
    }
}
