//! shine-graph: the render graph that schedules every pass of a shine frame.
//!
//! Knows Vulkan (through shine-gpu) but nothing of global illumination.
//!
//! A frame declares resources ([`RenderGraph::create_image`], [`RenderGraph::import_buffer`],
//! [`RenderGraph::temporal_image`] …) and passes that read (`&Handle`) and write (`&mut Handle`,
//! which advances the handle to the version written). A [`Compiler`] turns the graph into a
//! [`Plan`]: passes that reach no output are culled, the rest are ordered (declaration order
//! unless a dependency needs otherwise), usage flags are derived from the accesses, transient
//! memory is aliased by lifetime and synchronization2 barriers are batched per pass.

mod access;
mod alias;
mod barrier;
mod builders;
mod compile;
mod compiler;
mod dump;
mod error;
mod execute;
mod gpu_resources;
mod graph;
mod handle;
mod pass;
mod plan;
mod resource;
mod temporal;
mod work;

pub use access::{AccessInfo, AnyAccess, BufferAccess, ImageAccess};
pub use alias::{Heap, HeapClass, MemoryNeeds, MemoryPlan, MemoryRequirements, Placement};
pub use barrier::{Barrier, Scope};
pub use builders::{ComputePass, RasterPass};
pub use compiler::Compiler;
pub use dump::PlanDump;
pub use error::GraphError;
pub use execute::{ExecuteError, Executor, PassTiming, RawContext};
pub use gpu_resources::GpuResource;
pub use graph::{History, PassBuilder, RenderGraph};
pub use handle::{Buffer, Handle, Image, ResourceId, ResourceType};
pub use pass::{PassId, PassKind, UpdateRate};
pub use plan::{PassResource, Plan, PlannedPass, PlannedResource, ResourceKind, Usage};
pub use resource::{AnyDesc, BufferDesc, BufferImport, ExternalState, ImageDesc, ImageImport};
pub use shine_gpu::vk;
pub use work::{ColorLoad, DepthLoad};
