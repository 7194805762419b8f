//! shine-gpu: the ash device layer of shine. Knows Vulkan, nothing of global illumination.

pub use ash::vk;
