//! shine-gpu: the ash device layer of shine. Knows Vulkan, nothing of global illumination.
//!
//! - [`Device`]: headless creation with selection (`SHINE_DEVICE`) and a precise report of
//!   missing features, or [`Device::from_raw`] around a host engine's objects.
//! - [`Buffer`], [`Image`], [`MemoryBlock`] on gpu-allocator, destroyed when the GPU is done.
//! - [`ComputePipeline`], [`GraphicsPipeline`] from build-time reflection ([`ShaderDesc`]).
//! - [`Commands`] / [`Submission`]: recording, fenced submission, timestamp scopes, labels.
//! - Validation: [`Validation`] policy and message counts ([`Device::message_counts`]).
#![cfg_attr(not(test), deny(clippy::unwrap_used, clippy::expect_used))]

mod commands;
mod descriptors;
mod device;
mod error;
mod features;
mod instance;
mod memory;
mod pipeline;
mod pipeline_cache;
mod retire;
mod shader;
mod timestamps;
mod transfer;
mod usage;
mod validation;

/// The ash version shine is built on: a host engine must use the same one to lend its handles.
pub use ash;
pub use ash::vk;
pub use commands::{Commands, SCOPES_PER_RECORDING, Submission};
pub use descriptors::{Descriptor, DescriptorArena};
pub use device::{Device, DeviceDesc, DeviceInfo, RawDevice};
pub use error::{Error, Result};
pub use features::{EnabledFeatures, FeatureStatus, REQUIREMENTS, Requirements};
pub use instance::Adapter;
pub use memory::{
    Buffer, BufferDesc, Image, ImageDesc, MemoryBlock, MemoryLocation, Sampler, format_aspect,
    format_texel_size,
};
pub use pipeline::{
    Blend, ComputePipeline, DepthState, GraphicsPipeline, GraphicsPipelineDesc, LayoutBinding,
    PipelineLayout, VertexBufferLayout,
};
pub use shader::{BindingDesc, DescriptorKind, ShaderDesc, ShaderStage, VertexInputDesc};
pub use timestamps::{ScopeTiming, TimestampPool, ticks_to_ns};
pub use usage::MemoryUsage;
pub use validation::{KEPT_MESSAGES, MessageCounts, Validation};
