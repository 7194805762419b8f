//! Shader descriptions produced by build.rs from naga's reflection (docs/architecture.md, "Shaders").
//!
//! Every pipeline layout in shine is derived from these; none is written by hand.

use ash::vk;
use std::ffi::CStr;

/// Pipeline stage of a shader module.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ShaderStage {
    /// Compute shader.
    Compute,
    /// Vertex shader.
    Vertex,
    /// Fragment shader.
    Fragment,
}

impl ShaderStage {
    /// The Vulkan stage flag.
    pub fn flags(self) -> vk::ShaderStageFlags {
        match self {
            Self::Compute => vk::ShaderStageFlags::COMPUTE,
            Self::Vertex => vk::ShaderStageFlags::VERTEX,
            Self::Fragment => vk::ShaderStageFlags::FRAGMENT,
        }
    }
}

/// Kind of a reflected descriptor.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DescriptorKind {
    /// `uniform` block.
    UniformBuffer,
    /// `buffer` block.
    StorageBuffer {
        /// False for `readonly` blocks.
        writable: bool,
    },
    /// Separate `textureND` (sampled image).
    SampledImage,
    /// `imageND` (storage image).
    StorageImage {
        /// False for `readonly` images.
        writable: bool,
    },
    /// Separate `sampler`.
    Sampler,
}

impl DescriptorKind {
    /// The Vulkan descriptor type.
    pub fn vk(self) -> vk::DescriptorType {
        match self {
            Self::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            Self::StorageBuffer { .. } => vk::DescriptorType::STORAGE_BUFFER,
            Self::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
            Self::StorageImage { .. } => vk::DescriptorType::STORAGE_IMAGE,
            Self::Sampler => vk::DescriptorType::SAMPLER,
        }
    }

    /// Whether the shader may write through this binding.
    pub fn writes(self) -> bool {
        matches!(
            self,
            Self::StorageBuffer { writable: true } | Self::StorageImage { writable: true }
        )
    }
}

/// One descriptor binding of a shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BindingDesc {
    /// `layout(set = …)`.
    pub set: u32,
    /// `layout(binding = …)`.
    pub binding: u32,
    /// The GLSL instance name (block type name for anonymous blocks); resources bind by it.
    pub name: &'static str,
    /// Descriptor kind.
    pub kind: DescriptorKind,
    /// Array length, 1 for a single descriptor.
    pub count: u32,
}

/// One vertex-shader input.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct VertexInputDesc {
    /// `layout(location = …)`.
    pub location: u32,
    /// Attribute format matching the GLSL type.
    pub format: vk::Format,
}

/// A shader compiled and reflected at build time.
#[derive(Debug)]
pub struct ShaderDesc {
    /// Path under shaders/, with `:variant` for a `#define` variant.
    pub name: &'static str,
    /// Pipeline stage.
    pub stage: ShaderStage,
    /// Entry point name.
    pub entry: &'static CStr,
    /// Descriptor bindings, sorted by (set, binding).
    pub bindings: &'static [BindingDesc],
    /// Bytes of the push-constant block, 0 when the shader has none.
    pub push_constant_size: u32,
    /// Workgroup size of a compute shader (`[0; 3]` for other stages).
    pub workgroup_size: [u32; 3],
    /// Vertex inputs of a vertex shader, sorted by location.
    pub vertex_inputs: &'static [VertexInputDesc],
    /// SPIR-V 1.5 words.
    pub spirv: &'static [u32],
}

impl ShaderDesc {
    /// Looks a binding up by name.
    pub fn binding(&self, name: &str) -> Option<&BindingDesc> {
        self.bindings.iter().find(|b| b.name == name)
    }

    /// Workgroups needed to cover `threads` invocations (compute shaders).
    pub fn groups_for(&self, threads: [u32; 3]) -> [u32; 3] {
        let mut groups = [0; 3];
        for (axis, group) in groups.iter_mut().enumerate() {
            *group = threads[axis].div_ceil(self.workgroup_size[axis].max(1));
        }
        groups
    }
}
