//! shine-graph: the render graph that schedules every pass of a shine frame.
//!
//! Knows Vulkan (through shine-gpu) but nothing of global illumination.
//!
//! A frame declares resources ([`RenderGraph::create_image`], [`RenderGraph::import_buffer`],
//! [`RenderGraph::temporal_image`] …) and passes that read (`&Handle`) and write (`&mut Handle`,
//! which advances the handle to the version written). A [`Compiler`] turns the graph into a
//! [`Plan`]: passes that reach no output are culled, the rest are ordered (declaration order
//! unless a dependency needs otherwise), usage flags are derived from the accesses, transient
//! memory is aliased by lifetime and synchronization2 barriers are batched per pass. An
//! [`Executor`] records the plan into a caller-provided command buffer, with a debug label and
//! a GPU timestamp scope per pass.
//!
//! Declaring and compiling a frame needs no GPU:
//!
//! ```
//! use shine_graph::*;
//! # struct Fake;
//! # impl MemoryRequirements for Fake {
//! #     fn image(&self, d: &ImageDesc, _: vk::ImageUsageFlags) -> MemoryNeeds {
//! #         MemoryNeeds { size: u64::from(d.extent.width * d.extent.height) * 8, alignment: 256, type_bits: 1 }
//! #     }
//! #     fn buffer(&self, d: &BufferDesc, _: vk::BufferUsageFlags) -> MemoryNeeds {
//! #         MemoryNeeds { size: d.size, alignment: 256, type_bits: 1 }
//! #     }
//! # }
//! let mut rg = RenderGraph::new(0);
//! let mut hdr = rg.create_image("hdr", ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, 64, 64));
//! let mut history = rg.temporal_image("history", ImageDesc::new_2d(vk::Format::R16G16B16A16_SFLOAT, 64, 64));
//! rg.pass("shade", PassKind::Compute)
//!     .write(&mut hdr, ImageAccess::StorageWriteCompute);
//! rg.pass("resolve", PassKind::Compute)
//!     .read(&hdr, ImageAccess::SampledCompute)
//!     .write(&mut history, ImageAccess::StorageReadWriteCompute);
//! let plan = Compiler::new().compile(&rg, &Fake).unwrap();
//! assert_eq!(plan.order(), ["shade", "resolve"]);
//! let barrier = &plan.barriers_before("resolve")[0];
//! assert_eq!(barrier.new_layout, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
//! println!("{}", plan.dump().dot);
//! ```
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

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
mod objects;
mod pass;
mod pipelines;
mod plan;
mod raw;
mod record;
mod resource;
mod temporal;
mod timing;
mod work;

pub use access::{AccessInfo, AnyAccess, BufferAccess, ImageAccess};
pub use alias::{Heap, HeapClass, MemoryNeeds, MemoryPlan, MemoryRequirements, Placement};
pub use barrier::{Barrier, Scope};
pub use builders::{ComputePass, RasterPass};
pub use compiler::Compiler;
pub use dump::PlanDump;
pub use error::{ExecuteError, GraphError};
pub use execute::Executor;
pub use gpu_resources::GpuResource;
pub use graph::{History, PassBuilder, RenderGraph};
pub use handle::{Buffer, Handle, Image, ResourceId, ResourceType};
pub use pass::{PassCost, PassId, PassKind, UpdateRate};
pub use plan::{PassResource, Plan, PlannedPass, PlannedResource, ResourceKind, Usage};
pub use raw::RawContext;
pub use resource::{AnyDesc, BufferDesc, BufferImport, ExternalState, ImageDesc, ImageImport};
pub use shine_gpu::vk;
pub use timing::PassTiming;
pub use work::{ColorLoad, DepthLoad};
