//! What a pass does to a resource, and the Vulkan stage, access, layout and usage that follow.

use shine_gpu::vk;

type Stage = vk::PipelineStageFlags2;
type Acc = vk::AccessFlags2;
type Layout = vk::ImageLayout;

/// One way a pass uses an image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum ImageAccess {
    /// Sampled (texture) read in a compute shader.
    SampledCompute,
    /// Sampled read in a vertex shader.
    SampledVertex,
    /// Sampled read in a fragment shader.
    SampledFragment,
    /// Storage-image read in a compute shader.
    StorageReadCompute,
    /// Storage-image write in a compute shader.
    StorageWriteCompute,
    /// Storage-image read and write in a compute shader.
    StorageReadWriteCompute,
    /// Colour attachment written (load op CLEAR or DONT_CARE, no blending).
    ColorAttachmentWrite,
    /// Colour attachment read and written (load op LOAD, or blending such as additive splats).
    ColorAttachmentReadWrite,
    /// Depth(-stencil) attachment tested and written.
    DepthAttachmentWrite,
    /// Depth(-stencil) attachment tested but not written.
    DepthAttachmentRead,
    /// Source of a copy command.
    CopySrc,
    /// Destination of a copy command.
    CopyDst,
    /// Source of a blit.
    BlitSrc,
    /// Destination of a blit.
    BlitDst,
    /// Destination of a clear command.
    ClearDst,
}

/// One way a pass uses a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum BufferAccess {
    /// Uniform buffer read in a compute shader.
    UniformCompute,
    /// Uniform buffer read in a vertex shader.
    UniformVertex,
    /// Uniform buffer read in a fragment shader.
    UniformFragment,
    /// Storage-buffer read in a compute shader.
    StorageReadCompute,
    /// Storage-buffer read in a vertex shader.
    StorageReadVertex,
    /// Storage-buffer read in a fragment shader.
    StorageReadFragment,
    /// Storage-buffer write in a compute shader.
    StorageWriteCompute,
    /// Storage-buffer read and write in a compute shader.
    StorageReadWriteCompute,
    /// Vertex buffer of a draw.
    Vertex,
    /// Index buffer of a draw.
    Index,
    /// Arguments of an indirect draw or dispatch.
    Indirect,
    /// Source of a copy command.
    CopySrc,
    /// Destination of a copy command.
    CopyDst,
    /// Destination of `vkCmdFillBuffer`/`vkCmdUpdateBuffer`. The specification puts these in the
    /// CLEAR stage; validation layers before 1.3.280 model them as COPY, so both stages are used.
    Fill,
}

/// The Vulkan meaning of an access.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AccessInfo {
    /// Pipeline stages that touch the resource.
    pub stage: Stage,
    /// Memory accesses made there.
    pub access: Acc,
    /// Layout the image must be in (UNDEFINED for buffers).
    pub layout: Layout,
    /// Usage bits the resource needs (image or buffer usage, raw).
    pub usage: u32,
}

/// Every access bit that writes memory.
const WRITE_BITS: Acc = Acc::from_raw(
    Acc::SHADER_WRITE.as_raw()
        | Acc::SHADER_STORAGE_WRITE.as_raw()
        | Acc::COLOR_ATTACHMENT_WRITE.as_raw()
        | Acc::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw()
        | Acc::TRANSFER_WRITE.as_raw()
        | Acc::HOST_WRITE.as_raw()
        | Acc::MEMORY_WRITE.as_raw(),
);

impl AccessInfo {
    /// The write bits of the access mask.
    pub fn writes(&self) -> Acc {
        self.access & WRITE_BITS
    }

    /// Whether the access writes memory.
    pub fn is_write(&self) -> bool {
        !self.writes().is_empty()
    }
}

/// The write bits of an access mask.
pub(crate) fn write_bits(access: Acc) -> Acc {
    access & WRITE_BITS
}

fn image(stage: Stage, access: Acc, layout: Layout, usage: vk::ImageUsageFlags) -> AccessInfo {
    AccessInfo {
        stage,
        access,
        layout,
        usage: usage.as_raw(),
    }
}

fn buffer(stage: Stage, access: Acc, usage: vk::BufferUsageFlags) -> AccessInfo {
    AccessInfo {
        stage,
        access,
        layout: Layout::UNDEFINED,
        usage: usage.as_raw(),
    }
}

impl ImageAccess {
    /// Stage, access mask, layout and usage of this access.
    pub fn info(self) -> AccessInfo {
        use ImageAccess::*;
        use vk::ImageUsageFlags as U;
        let depth_stages = Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS;
        match self {
            SampledCompute => image(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_SAMPLED_READ,
                Layout::SHADER_READ_ONLY_OPTIMAL,
                U::SAMPLED,
            ),
            SampledVertex => image(
                Stage::VERTEX_SHADER,
                Acc::SHADER_SAMPLED_READ,
                Layout::SHADER_READ_ONLY_OPTIMAL,
                U::SAMPLED,
            ),
            SampledFragment => image(
                Stage::FRAGMENT_SHADER,
                Acc::SHADER_SAMPLED_READ,
                Layout::SHADER_READ_ONLY_OPTIMAL,
                U::SAMPLED,
            ),
            StorageReadCompute => image(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_READ,
                Layout::GENERAL,
                U::STORAGE,
            ),
            StorageWriteCompute => image(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_WRITE,
                Layout::GENERAL,
                U::STORAGE,
            ),
            StorageReadWriteCompute => image(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_READ | Acc::SHADER_STORAGE_WRITE,
                Layout::GENERAL,
                U::STORAGE,
            ),
            ColorAttachmentWrite => image(
                Stage::COLOR_ATTACHMENT_OUTPUT,
                Acc::COLOR_ATTACHMENT_WRITE,
                Layout::COLOR_ATTACHMENT_OPTIMAL,
                U::COLOR_ATTACHMENT,
            ),
            ColorAttachmentReadWrite => image(
                Stage::COLOR_ATTACHMENT_OUTPUT,
                Acc::COLOR_ATTACHMENT_READ | Acc::COLOR_ATTACHMENT_WRITE,
                Layout::COLOR_ATTACHMENT_OPTIMAL,
                U::COLOR_ATTACHMENT,
            ),
            DepthAttachmentWrite => image(
                depth_stages,
                Acc::DEPTH_STENCIL_ATTACHMENT_READ | Acc::DEPTH_STENCIL_ATTACHMENT_WRITE,
                Layout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                U::DEPTH_STENCIL_ATTACHMENT,
            ),
            DepthAttachmentRead => image(
                depth_stages,
                Acc::DEPTH_STENCIL_ATTACHMENT_READ,
                Layout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                U::DEPTH_STENCIL_ATTACHMENT,
            ),
            CopySrc => image(
                Stage::COPY,
                Acc::TRANSFER_READ,
                Layout::TRANSFER_SRC_OPTIMAL,
                U::TRANSFER_SRC,
            ),
            CopyDst => image(
                Stage::COPY,
                Acc::TRANSFER_WRITE,
                Layout::TRANSFER_DST_OPTIMAL,
                U::TRANSFER_DST,
            ),
            BlitSrc => image(
                Stage::BLIT,
                Acc::TRANSFER_READ,
                Layout::TRANSFER_SRC_OPTIMAL,
                U::TRANSFER_SRC,
            ),
            BlitDst => image(
                Stage::BLIT,
                Acc::TRANSFER_WRITE,
                Layout::TRANSFER_DST_OPTIMAL,
                U::TRANSFER_DST,
            ),
            ClearDst => image(
                Stage::CLEAR,
                Acc::TRANSFER_WRITE,
                Layout::TRANSFER_DST_OPTIMAL,
                U::TRANSFER_DST,
            ),
        }
    }
}

impl BufferAccess {
    /// Stage, access mask and usage of this access (the layout is UNDEFINED).
    pub fn info(self) -> AccessInfo {
        use BufferAccess::*;
        use vk::BufferUsageFlags as U;
        match self {
            UniformCompute => buffer(Stage::COMPUTE_SHADER, Acc::UNIFORM_READ, U::UNIFORM_BUFFER),
            UniformVertex => buffer(Stage::VERTEX_SHADER, Acc::UNIFORM_READ, U::UNIFORM_BUFFER),
            UniformFragment => buffer(Stage::FRAGMENT_SHADER, Acc::UNIFORM_READ, U::UNIFORM_BUFFER),
            StorageReadCompute => buffer(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_READ,
                U::STORAGE_BUFFER,
            ),
            StorageReadVertex => buffer(
                Stage::VERTEX_SHADER,
                Acc::SHADER_STORAGE_READ,
                U::STORAGE_BUFFER,
            ),
            StorageReadFragment => buffer(
                Stage::FRAGMENT_SHADER,
                Acc::SHADER_STORAGE_READ,
                U::STORAGE_BUFFER,
            ),
            StorageWriteCompute => buffer(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_WRITE,
                U::STORAGE_BUFFER,
            ),
            StorageReadWriteCompute => buffer(
                Stage::COMPUTE_SHADER,
                Acc::SHADER_STORAGE_READ | Acc::SHADER_STORAGE_WRITE,
                U::STORAGE_BUFFER,
            ),
            Vertex => buffer(
                Stage::VERTEX_ATTRIBUTE_INPUT,
                Acc::VERTEX_ATTRIBUTE_READ,
                U::VERTEX_BUFFER,
            ),
            Index => buffer(Stage::INDEX_INPUT, Acc::INDEX_READ, U::INDEX_BUFFER),
            Indirect => buffer(
                Stage::DRAW_INDIRECT,
                Acc::INDIRECT_COMMAND_READ,
                U::INDIRECT_BUFFER,
            ),
            CopySrc => buffer(Stage::COPY, Acc::TRANSFER_READ, U::TRANSFER_SRC),
            CopyDst => buffer(Stage::COPY, Acc::TRANSFER_WRITE, U::TRANSFER_DST),
            Fill => buffer(
                Stage::CLEAR | Stage::COPY,
                Acc::TRANSFER_WRITE,
                U::TRANSFER_DST,
            ),
        }
    }
}

/// An access to either kind of resource.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum AnyAccess {
    /// An image access.
    Image(ImageAccess),
    /// A buffer access.
    Buffer(BufferAccess),
}

impl AnyAccess {
    /// Stage, access mask, layout and usage of this access.
    pub fn info(self) -> AccessInfo {
        match self {
            AnyAccess::Image(a) => a.info(),
            AnyAccess::Buffer(a) => a.info(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writes_are_classified() {
        assert!(ImageAccess::StorageWriteCompute.info().is_write());
        assert!(ImageAccess::DepthAttachmentWrite.info().is_write());
        assert!(!ImageAccess::DepthAttachmentRead.info().is_write());
        assert!(!ImageAccess::SampledFragment.info().is_write());
        assert!(BufferAccess::Fill.info().is_write());
        assert!(!BufferAccess::Vertex.info().is_write());
        assert_eq!(
            ImageAccess::ColorAttachmentReadWrite.info().writes(),
            Acc::COLOR_ATTACHMENT_WRITE
        );
    }
}
