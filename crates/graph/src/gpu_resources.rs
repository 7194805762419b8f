//! Vulkan objects the graph owns: transients bound into aliased memory blocks, and temporal
//! resources with their own block. Memory requirements are asked of the device from create
//! infos (Vulkan 1.3 `vkGetDevice*MemoryRequirements`), so planning needs no object.

use shine_gpu::{Device, MemoryBlock, MemoryLocation, vk};

use crate::alias::{MemoryNeeds, MemoryRequirements};
use crate::resource::{AnyDesc, BufferDesc, ImageDesc};

fn image_info(desc: &ImageDesc, usage: vk::ImageUsageFlags) -> vk::ImageCreateInfo<'static> {
    vk::ImageCreateInfo::default()
        .image_type(desc.image_type)
        .format(desc.format)
        .extent(desc.extent)
        .mip_levels(desc.mips)
        .array_layers(desc.layers)
        .samples(desc.samples)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
}

fn buffer_info(desc: &BufferDesc, usage: vk::BufferUsageFlags) -> vk::BufferCreateInfo<'static> {
    vk::BufferCreateInfo::default()
        .size(desc.size)
        .usage(usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
}

/// Memory requirements answered by the device.
pub(crate) struct DeviceMemory<'a>(pub &'a Device);

impl MemoryRequirements for DeviceMemory<'_> {
    fn image(&self, desc: &ImageDesc, usage: vk::ImageUsageFlags) -> MemoryNeeds {
        let info = image_info(desc, usage);
        let query = vk::DeviceImageMemoryRequirements::default().create_info(&info);
        let mut out = vk::MemoryRequirements2::default();
        // SAFETY: valid create info; Vulkan 1.3 core entry point.
        unsafe {
            self.0
                .raw()
                .get_device_image_memory_requirements(&query, &mut out)
        };
        out.memory_requirements.into()
    }

    fn buffer(&self, desc: &BufferDesc, usage: vk::BufferUsageFlags) -> MemoryNeeds {
        let info = buffer_info(desc, usage);
        let query = vk::DeviceBufferMemoryRequirements::default().create_info(&info);
        let mut out = vk::MemoryRequirements2::default();
        // SAFETY: valid create info; Vulkan 1.3 core entry point.
        unsafe {
            self.0
                .raw()
                .get_device_buffer_memory_requirements(&query, &mut out)
        };
        out.memory_requirements.into()
    }
}

/// The Vulkan object behind a graph resource during execution.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuResource {
    /// An image and a view over all of it.
    Image {
        /// The image.
        image: vk::Image,
        /// A view over every mip and layer (null for images only transfers use).
        view: vk::ImageView,
    },
    /// A buffer.
    Buffer(vk::Buffer),
}

/// A Vulkan object created by the graph; destroyed by [`RawObject::destroy`] once the GPU is
/// done with it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct RawObject(pub GpuResource);

impl RawObject {
    /// Creates the object for `desc` and binds it at `offset` of `memory`.
    pub fn create(
        device: &Device,
        name: &str,
        desc: &AnyDesc,
        usage: u32,
        memory: &MemoryBlock,
        offset: u64,
    ) -> Result<Self, shine_gpu::Error> {
        let raw = device.raw();
        let (memory, base) = memory.memory();
        match desc {
            AnyDesc::Buffer(d) => {
                let info = buffer_info(d, vk::BufferUsageFlags::from_raw(usage));
                // SAFETY: valid create info on a live device.
                let buffer = unsafe { raw.create_buffer(&info, None) }
                    .map_err(|e| shine_gpu::Error::vk(format!("creating buffer `{name}`"), e))?;
                // SAFETY: the placement lies inside the block and honours the alignment.
                if let Err(e) = unsafe { raw.bind_buffer_memory(buffer, memory, base + offset) } {
                    // SAFETY: never used.
                    unsafe { raw.destroy_buffer(buffer, None) };
                    return Err(shine_gpu::Error::vk(format!("binding `{name}`"), e));
                }
                device.set_name(buffer, name);
                Ok(Self(GpuResource::Buffer(buffer)))
            }
            AnyDesc::Image(d) => {
                let info = image_info(d, vk::ImageUsageFlags::from_raw(usage));
                // SAFETY: valid create info on a live device.
                let image = unsafe { raw.create_image(&info, None) }
                    .map_err(|e| shine_gpu::Error::vk(format!("creating image `{name}`"), e))?;
                let view_type = match (d.image_type, d.layers > 1) {
                    (vk::ImageType::TYPE_1D, false) => vk::ImageViewType::TYPE_1D,
                    (vk::ImageType::TYPE_1D, true) => vk::ImageViewType::TYPE_1D_ARRAY,
                    (vk::ImageType::TYPE_3D, _) => vk::ImageViewType::TYPE_3D,
                    (_, false) => vk::ImageViewType::TYPE_2D,
                    (_, true) => vk::ImageViewType::TYPE_2D_ARRAY,
                };
                let view_info = vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(view_type)
                    .format(d.format)
                    .subresource_range(d.full_range());
                // Images used only by transfers cannot have a view (and need none).
                let viewable = vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::STORAGE
                    | vk::ImageUsageFlags::COLOR_ATTACHMENT
                    | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                    | vk::ImageUsageFlags::INPUT_ATTACHMENT;
                let needs_view = info.usage.intersects(viewable);
                // SAFETY: the placement lies inside the block; the view covers the image.
                let view =
                    unsafe { raw.bind_image_memory(image, memory, base + offset) }.and_then(|()| {
                        if needs_view {
                            // SAFETY: the image has memory bound and a view-capable usage.
                            unsafe { raw.create_image_view(&view_info, None) }
                        } else {
                            Ok(vk::ImageView::null())
                        }
                    });
                match view {
                    Ok(view) => {
                        device.set_name(image, name);
                        Ok(Self(GpuResource::Image { image, view }))
                    }
                    Err(e) => {
                        // SAFETY: never used.
                        unsafe { raw.destroy_image(image, None) };
                        Err(shine_gpu::Error::vk(format!("preparing image `{name}`"), e))
                    }
                }
            }
        }
    }

    /// Hands the object to the device for destruction once the GPU can no longer use it
    /// (shine's submissions and the host frames of `Device::begin_host_frame`): nothing waits.
    pub fn destroy(self, device: &Device) {
        match self.0 {
            GpuResource::Buffer(b) => device.defer_buffer(b),
            GpuResource::Image { image, view } => device.defer_image(image, view),
        }
    }
}

/// A block of device memory for the given needs; `linear` for blocks holding only buffers.
pub(crate) fn allocate(
    device: &Device,
    name: &str,
    needs: MemoryNeeds,
    linear: bool,
) -> Result<MemoryBlock, shine_gpu::Error> {
    let requirements = vk::MemoryRequirements {
        size: needs.size,
        alignment: needs.alignment,
        memory_type_bits: needs.type_bits,
    };
    MemoryBlock::new(device, name, requirements, MemoryLocation::GpuOnly, linear)
}

/// Destroys `objects` once the GPU is done with them ([`RawObject::destroy`]); nothing waits.
pub(crate) fn release(device: &Device, objects: Vec<RawObject>) {
    for o in objects {
        o.destroy(device);
    }
}
