//! What a raw pass ([`crate::RenderGraph::raw_pass`]) sees while it records: the device, the
//! command buffer and the Vulkan objects behind the graph's handles.
//!
//! A leaf module: the pass's work (`work::RawFn`) names this context and execution builds it,
//! so neither has to depend on the other for it.

use shine_gpu::{Device, vk};

use crate::gpu_resources::GpuResource;
use crate::handle::{Buffer, Handle, Image};

/// What a raw pass gets: the device, the command buffer and the graph's resources.
pub struct RawContext<'a> {
    /// The device.
    pub device: &'a Device,
    /// The command buffer being recorded.
    pub cb: vk::CommandBuffer,
    /// The object behind each resource, indexed by resource id.
    resources: &'a [Option<GpuResource>],
}

impl<'a> RawContext<'a> {
    /// The context of a pass recording into `cb`, where `resources` is indexed by resource id.
    pub(crate) fn new(
        device: &'a Device,
        cb: vk::CommandBuffer,
        resources: &'a [Option<GpuResource>],
    ) -> Self {
        Self {
            device,
            cb,
            resources,
        }
    }

    /// The image and view behind a handle (any version).
    pub fn image(&self, handle: &Handle<Image>) -> Option<(vk::Image, vk::ImageView)> {
        match self.resources.get(handle.id.0 as usize).copied().flatten() {
            Some(GpuResource::Image { image, view }) => Some((image, view)),
            _ => None,
        }
    }

    /// The buffer behind a handle (any version).
    pub fn buffer(&self, handle: &Handle<Buffer>) -> Option<vk::Buffer> {
        match self.resources.get(handle.id.0 as usize).copied().flatten() {
            Some(GpuResource::Buffer(b)) => Some(b),
            _ => None,
        }
    }
}
