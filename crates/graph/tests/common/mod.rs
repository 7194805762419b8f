//! Fixtures shared by the compilation tests: fake memory needs and common imports.

#![allow(dead_code)]

use shine_graph::vk;
use shine_graph::*;

/// Memory needs by plain arithmetic: 4 bytes per texel, 256-byte alignment, one memory type.
pub struct FakeMemory;

impl MemoryRequirements for FakeMemory {
    fn image(&self, desc: &ImageDesc, _usage: vk::ImageUsageFlags) -> MemoryNeeds {
        let e = desc.extent;
        MemoryNeeds {
            size: u64::from(e.width * e.height * e.depth * desc.layers) * 4,
            alignment: 256,
            type_bits: 1,
        }
    }

    fn buffer(&self, desc: &BufferDesc, _usage: vk::BufferUsageFlags) -> MemoryNeeds {
        MemoryNeeds {
            size: desc.size,
            alignment: 256,
            type_bits: 1,
        }
    }
}

/// A 64×64 RGBA8 image.
pub fn image() -> ImageDesc {
    ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, 64, 64)
}

/// An imported buffer the caller reads back after the graph: starts unused, ends read by a copy.
pub fn output_buffer(rg: &mut RenderGraph, name: &str) -> Handle<Buffer> {
    rg.import_buffer(
        name,
        BufferDesc::new(256),
        BufferImport {
            initial: ExternalState::UNDEFINED,
            final_state: ExternalState::UNDEFINED,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            read_only: false,
        },
    )
}

/// Compile once with a fresh compiler.
pub fn compile(rg: &RenderGraph) -> Result<std::sync::Arc<Plan>, GraphError> {
    Compiler::new().compile(rg, &FakeMemory)
}

/// A barrier with the given scopes and layouts.
pub fn barrier(
    resource: ResourceId,
    src: (vk::PipelineStageFlags2, vk::AccessFlags2),
    dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    layouts: (vk::ImageLayout, vk::ImageLayout),
) -> Barrier {
    Barrier {
        resource,
        src: Scope::new(src.0, src.1),
        dst: Scope::new(dst.0, dst.1),
        old_layout: layouts.0,
        new_layout: layouts.1,
    }
}
