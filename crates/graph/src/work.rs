//! What a pass records when it runs: a dispatch, draws, a transfer or a closure.

use std::fmt;

use shine_gpu::{GraphicsPipelineDesc, ShaderDesc, vk};

use crate::handle::ResourceId;
use crate::raw::RawContext;

/// What a shader binding points at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Bound {
    /// A graph resource, in the layout its access needs (images).
    Resource(ResourceId, vk::ImageLayout),
    /// A caller-owned sampler.
    Sampler(vk::Sampler),
}

/// A compute dispatch.
#[derive(Clone, Debug)]
pub(crate) struct ComputeWork {
    pub shader: &'static ShaderDesc,
    pub bindings: Vec<(&'static str, Bound)>,
    pub push: Vec<u8>,
    pub threads: [u32; 3],
}

/// How a colour attachment starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColorLoad {
    /// Keep the contents (the pass reads and writes them).
    Load,
    /// Clear to this RGBA value.
    Clear([f32; 4]),
    /// Contents are undefined (the pass overwrites every texel it needs).
    DontCare,
}

/// How a depth attachment starts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum DepthLoad {
    /// Keep the contents.
    Load,
    /// Clear to this depth.
    Clear(f32),
    /// Contents are undefined.
    DontCare,
}

/// One attachment of a raster pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Attachment {
    pub resource: ResourceId,
    pub load: vk::AttachmentLoadOp,
    pub clear: [f32; 4],
}

/// One draw call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Draw {
    Vertices { count: u32, instances: u32 },
    Indexed { count: u32, instances: u32 },
}

/// Draws inside one dynamic-rendering scope.
#[derive(Clone, Debug)]
pub(crate) struct RasterWork {
    pub pipeline: GraphicsPipelineDesc,
    pub colors: Vec<Attachment>,
    pub depth: Option<Attachment>,
    pub bindings: Vec<(&'static str, Bound)>,
    pub vertex_buffers: Vec<ResourceId>,
    pub index_buffer: Option<(ResourceId, vk::IndexType)>,
    pub push: Vec<u8>,
    pub draws: Vec<Draw>,
    /// Render area, viewport and scissor: `None` covers the whole attachments.
    pub area: Option<vk::Rect2D>,
}

/// A transfer command on whole resources.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum TransferOp {
    CopyBuffer {
        src: ResourceId,
        dst: ResourceId,
    },
    CopyImageToBuffer {
        src: ResourceId,
        dst: ResourceId,
    },
    CopyBufferToImage {
        src: ResourceId,
        dst: ResourceId,
    },
    ClearImage {
        dst: ResourceId,
        color: [f32; 4],
    },
    FillBuffer {
        dst: ResourceId,
        value: u32,
    },
    Blit {
        src: ResourceId,
        dst: ResourceId,
        filter: vk::Filter,
    },
}

/// A closure recording commands itself.
pub(crate) type RawFn = Box<dyn FnOnce(&mut RawContext<'_>) -> Result<(), shine_gpu::Error>>;

/// The work of one pass.
pub(crate) enum Work {
    /// Accesses only: the pass records nothing but its barriers and scope.
    Declared,
    Compute(ComputeWork),
    Raster(Box<RasterWork>),
    Transfer(TransferOp),
    Raw(RawFn),
}

impl fmt::Debug for Work {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Work::Declared => f.write_str("Declared"),
            Work::Compute(c) => write!(f, "Compute({})", c.shader.name),
            Work::Raster(r) => write!(f, "Raster({})", r.pipeline.vertex.name),
            Work::Transfer(t) => write!(f, "Transfer({t:?})"),
            Work::Raw(_) => f.write_str("Raw"),
        }
    }
}
