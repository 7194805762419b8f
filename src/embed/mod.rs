//! shine embedded in a host engine as a GI pass (docs/embedding.md): a [`GiContext`] made
//! once on the host's device, fed the host's G-buffer every frame ([`GiDispatch`]) and
//! recording into the host's command buffer, the way FidelityFX's GI effects integrate.

mod budget_pick;
mod context;
mod host_geometry;
mod inputs;
mod resolution;
mod warm_up;

pub use crate::frame::memory::MemoryReport;
/// What a host also needs, in one place: the image type of every input and output, the
/// per-frame scene update, the device wrapper and what it checks, and the image states.
pub use crate::frame::renderer::HostTarget;
pub use crate::gpu_scene::FrameUpdate;
pub use crate::passes::debug_view::DebugView;
pub use context::{GiBudgets, GiContext, GiContextDesc};
pub use host_geometry::{
    HostBuffer, HostInstance, HostMaterial, HostMesh, IndexFormat, MeshId, PositionFormat,
};
pub use inputs::{
    DepthConvention, GiCamera, GiDispatch, HostEnvironment, HostMotion, MaterialChannels,
    NormalEncoding,
};
pub use resolution::{INTERNAL_PERCENTS, InternalResolution};
pub use shine_gpu::{Device, EnabledFeatures, RawDevice};
pub use shine_graph::ExternalState;
pub use shine_scene::{Light, LightKind};
pub use warm_up::DispatchShape;
