//! Buffers, images and raw memory blocks on gpu-allocator. Each owns its allocation and is
//! destroyed only when the GPU is done with it (see [`crate::retire`]).

use crate::device::Device;
use crate::error::{Error, Result, VkContext};
use crate::retire::Garbage;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

pub use gpu_allocator::MemoryLocation;

/// How to create a [`Buffer`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct BufferDesc<'a> {
    /// Debug name (also shown in validation messages and captures).
    pub name: &'a str,
    /// Size in bytes (> 0).
    pub size: u64,
    /// Usage flags.
    pub usage: vk::BufferUsageFlags,
    /// Where the memory lives; host-visible locations are mapped persistently.
    pub location: MemoryLocation,
}

/// A buffer with its memory.
pub struct Buffer {
    device: Device,
    raw: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
    usage: vk::BufferUsageFlags,
    name: String,
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Buffer")
            .field("name", &self.name)
            .field("size", &self.size)
            .finish_non_exhaustive()
    }
}

impl Buffer {
    /// Creates a buffer and binds fresh memory to it.
    pub fn new(device: &Device, desc: &BufferDesc<'_>) -> Result<Self> {
        if desc.size == 0 {
            return Err(Error::InvalidUsage(format!(
                "buffer `{}` has size 0",
                desc.name
            )));
        }
        let info = vk::BufferCreateInfo::default()
            .size(desc.size)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let raw_device = device.raw();
        // SAFETY: valid create info on a live device.
        let raw = unsafe { raw_device.create_buffer(&info, None) }
            .ctx(&format!("creating buffer `{}`", desc.name))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { raw_device.get_buffer_memory_requirements(raw) };
        let allocation = match device.allocate(desc.name, requirements, desc.location, true) {
            Ok(a) => a,
            Err(e) => {
                // SAFETY: never used.
                unsafe { raw_device.destroy_buffer(raw, None) };
                return Err(e);
            }
        };
        // SAFETY: memory from the allocator fits the requirements of `raw`.
        if let Err(e) =
            unsafe { raw_device.bind_buffer_memory(raw, allocation.memory(), allocation.offset()) }
        {
            device.defer(Garbage::Buffer(raw, Some(allocation)));
            return Err(Error::vk(format!("binding memory to `{}`", desc.name), e));
        }
        device.set_name(raw, desc.name);
        Ok(Self {
            device: device.clone(),
            raw,
            allocation: Some(allocation),
            size: desc.size,
            usage: desc.usage,
            name: desc.name.to_string(),
        })
    }

    /// Creates a buffer (at least `data.len()` bytes, with `TRANSFER_DST` added) initialised
    /// with `data` through a staging copy.
    pub fn with_data(device: &Device, desc: &BufferDesc<'_>, data: &[u8]) -> Result<Self> {
        let mut desc = *desc;
        desc.size = desc.size.max(data.len() as u64);
        desc.usage |= vk::BufferUsageFlags::TRANSFER_DST;
        let buffer = Self::new(device, &desc)?;
        device.upload_buffer(&buffer, 0, data)?;
        Ok(buffer)
    }

    /// A device-local storage buffer named `name` initialised with `data` (not empty): the
    /// constructor of the read-only tables passes bind (BRDF tables, proxies, shadow records).
    pub fn storage_with_data(device: &Device, name: &str, data: &[u8]) -> Result<Self> {
        Self::with_data(
            device,
            &BufferDesc {
                name,
                size: 0,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
            data,
        )
    }

    /// A device-local storage buffer named `name` of `size` bytes (at least 16) that transfers
    /// write: the destination of uploads recorded into a frame (tables uploaded once, records
    /// rewritten every frame), where [`Buffer::storage_with_data`] would submit and wait.
    pub fn storage_for_uploads(device: &Device, name: &str, size: u64) -> Result<Self> {
        Self::new(
            device,
            &BufferDesc {
                name,
                size: size.max(16),
                usage: vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
                location: MemoryLocation::GpuOnly,
            },
        )
    }

    /// The Vulkan handle.
    pub fn raw(&self) -> vk::Buffer {
        self.raw
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.size
    }

    /// Bytes of device memory its allocation holds (its size rounded up to the allocator's
    /// granularity): what memory reports sum.
    pub fn allocated_bytes(&self) -> u64 {
        self.allocation.as_ref().map_or(0, |a| a.size())
    }

    /// Usage flags it was created with.
    pub fn usage(&self) -> vk::BufferUsageFlags {
        self.usage
    }

    /// Debug name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The persistently mapped bytes of a host-visible buffer: exactly [`Buffer::size`] of
    /// them, although the allocation behind may be larger (drivers round a buffer's memory
    /// requirements up: NVIDIA's by up to its alignment).
    pub fn mapped(&self) -> Option<&[u8]> {
        let size = self.size as usize;
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .map(|s| &s[..size])
    }

    /// The persistently mapped bytes, mutable: [`Buffer::mapped`]'s.
    pub fn mapped_mut(&mut self) -> Option<&mut [u8]> {
        let size = self.size as usize;
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .map(|s| &mut s[..size])
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        self.device
            .defer(Garbage::Buffer(self.raw, self.allocation.take()));
    }
}

/// How to create an [`Image`]: a 2D (or 2D-array) image with one view over all of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ImageDesc<'a> {
    /// Debug name.
    pub name: &'a str,
    /// Width and height in texels (> 0).
    pub extent: [u32; 2],
    /// Texel format.
    pub format: vk::Format,
    /// Usage flags.
    pub usage: vk::ImageUsageFlags,
    /// Mip levels (≥ 1).
    pub mip_levels: u32,
    /// Array layers (≥ 1).
    pub array_layers: u32,
    /// View it as an array (`texture2DArray`) even with a single layer; images of several
    /// layers always get an array view.
    pub array_view: bool,
}

impl<'a> ImageDesc<'a> {
    /// A single-mip, single-layer 2D image.
    pub fn new_2d(
        name: &'a str,
        extent: [u32; 2],
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Self {
        Self {
            name,
            extent,
            format,
            usage,
            mip_levels: 1,
            array_layers: 1,
            array_view: false,
        }
    }
}

/// The aspect flags of a format (depth, stencil or colour).
pub fn format_aspect(format: vk::Format) -> vk::ImageAspectFlags {
    match format {
        vk::Format::D16_UNORM | vk::Format::D32_SFLOAT | vk::Format::X8_D24_UNORM_PACK32 => {
            vk::ImageAspectFlags::DEPTH
        }
        vk::Format::D16_UNORM_S8_UINT
        | vk::Format::D24_UNORM_S8_UINT
        | vk::Format::D32_SFLOAT_S8_UINT => {
            vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
        }
        vk::Format::S8_UINT => vk::ImageAspectFlags::STENCIL,
        _ => vk::ImageAspectFlags::COLOR,
    }
}

/// Bytes per texel of the uncompressed formats shine reads back or uploads.
pub fn format_texel_size(format: vk::Format) -> Option<u32> {
    Some(match format {
        vk::Format::R8_UNORM | vk::Format::R8_UINT | vk::Format::S8_UINT => 1,
        vk::Format::R16_SFLOAT | vk::Format::R16_UINT | vk::Format::D16_UNORM => 2,
        vk::Format::R8G8B8A8_UNORM
        | vk::Format::R8G8B8A8_SRGB
        | vk::Format::B8G8R8A8_UNORM
        | vk::Format::B8G8R8A8_SRGB
        | vk::Format::R32_SFLOAT
        | vk::Format::R32_UINT
        | vk::Format::R16G16_SFLOAT
        | vk::Format::D32_SFLOAT
        | vk::Format::X8_D24_UNORM_PACK32
        | vk::Format::A2B10G10R10_UNORM_PACK32
        | vk::Format::B10G11R11_UFLOAT_PACK32 => 4,
        vk::Format::R16G16B16A16_SFLOAT | vk::Format::R32G32_SFLOAT => 8,
        vk::Format::R32G32B32A32_SFLOAT => 16,
        _ => return None,
    })
}

/// An image with its memory and a view over every mip and layer.
pub struct Image {
    device: Device,
    raw: vk::Image,
    view: vk::ImageView,
    allocation: Option<Allocation>,
    extent: [u32; 2],
    format: vk::Format,
    usage: vk::ImageUsageFlags,
    mip_levels: u32,
    array_layers: u32,
    name: String,
}

impl std::fmt::Debug for Image {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Image")
            .field("name", &self.name)
            .field("extent", &self.extent)
            .field("format", &self.format)
            .finish_non_exhaustive()
    }
}

impl Image {
    /// Bytes of device memory its allocation holds: what memory reports sum.
    pub fn allocated_bytes(&self) -> u64 {
        self.allocation.as_ref().map_or(0, |a| a.size())
    }

    /// Creates an image, binds fresh memory and creates its view.
    pub fn new(device: &Device, desc: &ImageDesc<'_>) -> Result<Self> {
        if desc.extent[0] == 0
            || desc.extent[1] == 0
            || desc.mip_levels == 0
            || desc.array_layers == 0
        {
            return Err(Error::InvalidUsage(format!(
                "image `{}` has an empty extent {:?}, {} mips, {} layers",
                desc.name, desc.extent, desc.mip_levels, desc.array_layers
            )));
        }
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D {
                width: desc.extent[0],
                height: desc.extent[1],
                depth: 1,
            })
            .mip_levels(desc.mip_levels)
            .array_layers(desc.array_layers)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let raw_device = device.raw();
        // SAFETY: valid create info on a live device.
        let raw = unsafe { raw_device.create_image(&info, None) }
            .ctx(&format!("creating image `{}`", desc.name))?;
        // SAFETY: `raw` was just created on this device.
        let requirements = unsafe { raw_device.get_image_memory_requirements(raw) };
        let allocation =
            match device.allocate(desc.name, requirements, MemoryLocation::GpuOnly, false) {
                Ok(a) => a,
                Err(e) => {
                    // SAFETY: never used.
                    unsafe { raw_device.destroy_image(raw, None) };
                    return Err(e);
                }
            };
        // SAFETY: memory from the allocator fits the requirements of `raw`.
        let bound =
            unsafe { raw_device.bind_image_memory(raw, allocation.memory(), allocation.offset()) };
        // Views exist only for usages that read or write through one (a transfer-only image
        // may not have a view at all).
        let viewable = desc.usage.intersects(
            vk::ImageUsageFlags::SAMPLED
                | vk::ImageUsageFlags::STORAGE
                | vk::ImageUsageFlags::COLOR_ATTACHMENT
                | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
                | vk::ImageUsageFlags::INPUT_ATTACHMENT,
        );
        let view = bound.and_then(|()| {
            if !viewable {
                return Ok(vk::ImageView::null());
            }
            let view_info = vk::ImageViewCreateInfo::default()
                .image(raw)
                .view_type(if desc.array_layers > 1 || desc.array_view {
                    vk::ImageViewType::TYPE_2D_ARRAY
                } else {
                    vk::ImageViewType::TYPE_2D
                })
                .format(desc.format)
                .subresource_range(vk::ImageSubresourceRange {
                    aspect_mask: format_aspect(desc.format),
                    base_mip_level: 0,
                    level_count: desc.mip_levels,
                    base_array_layer: 0,
                    layer_count: desc.array_layers,
                });
            // SAFETY: the image has memory bound and the range lies inside it.
            unsafe { raw_device.create_image_view(&view_info, None) }
        });
        let view = match view {
            Ok(v) => v,
            Err(e) => {
                device.defer(Garbage::Image(raw, vk::ImageView::null(), Some(allocation)));
                return Err(Error::vk(format!("preparing image `{}`", desc.name), e));
            }
        };
        device.set_name(raw, desc.name);
        Ok(Self {
            device: device.clone(),
            raw,
            view,
            allocation: Some(allocation),
            extent: desc.extent,
            format: desc.format,
            usage: desc.usage,
            mip_levels: desc.mip_levels,
            array_layers: desc.array_layers,
            name: desc.name.to_string(),
        })
    }

    /// The Vulkan image.
    pub fn raw(&self) -> vk::Image {
        self.raw
    }

    /// The view over every mip and layer; null for an image whose usage needs no view
    /// (transfer only).
    pub fn view(&self) -> vk::ImageView {
        self.view
    }

    /// Width and height.
    pub fn extent(&self) -> [u32; 2] {
        self.extent
    }

    /// Texel format.
    pub fn format(&self) -> vk::Format {
        self.format
    }

    /// Usage flags.
    pub fn usage(&self) -> vk::ImageUsageFlags {
        self.usage
    }

    /// Debug name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The subresource range covering every mip and layer.
    pub fn full_range(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange {
            aspect_mask: format_aspect(self.format),
            base_mip_level: 0,
            level_count: self.mip_levels,
            base_array_layer: 0,
            layer_count: self.array_layers,
        }
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        self.device
            .defer(Garbage::Image(self.raw, self.view, self.allocation.take()));
    }
}

/// Device memory not tied to one resource: the render graph binds several transient
/// resources to one block when their lifetimes do not overlap.
pub struct MemoryBlock {
    device: Device,
    allocation: Option<Allocation>,
}

impl MemoryBlock {
    /// Allocates memory satisfying `requirements`. `linear` is true when only buffers (or
    /// linear images) will be bound, so the allocator respects bufferImageGranularity.
    pub fn new(
        device: &Device,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Self> {
        Ok(Self {
            device: device.clone(),
            allocation: Some(device.allocate(name, requirements, location, linear)?),
        })
    }

    /// The `VkDeviceMemory` and the offset of this block inside it.
    pub fn memory(&self) -> (vk::DeviceMemory, u64) {
        self.allocation
            .as_ref()
            // SAFETY: the memory stays allocated while this block lives; callers bind
            // resources to it and must not free it.
            .map_or((vk::DeviceMemory::null(), 0), |a| {
                (unsafe { a.memory() }, a.offset())
            })
    }

    /// Size in bytes.
    pub fn size(&self) -> u64 {
        self.allocation.as_ref().map_or(0, |a| a.size())
    }
}

impl Drop for MemoryBlock {
    fn drop(&mut self) {
        if let Some(a) = self.allocation.take() {
            self.device.defer(Garbage::Memory(a));
        }
    }
}

/// A sampler, destroyed when the GPU is done with it.
pub struct Sampler {
    device: Device,
    raw: vk::Sampler,
}

impl Sampler {
    /// Creates a sampler.
    pub fn new(device: &Device, info: &vk::SamplerCreateInfo<'_>) -> Result<Self> {
        // SAFETY: valid create info on a live device.
        let raw = unsafe { device.raw().create_sampler(info, None) }.ctx("creating a sampler")?;
        Ok(Self {
            device: device.clone(),
            raw,
        })
    }

    /// The Vulkan handle.
    pub fn raw(&self) -> vk::Sampler {
        self.raw
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        self.device.defer(Garbage::Sampler(self.raw));
    }
}

impl Device {
    /// Allocates memory through gpu-allocator.
    pub(crate) fn allocate(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
    ) -> Result<Allocation> {
        let allocation = self
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|source| Error::Allocation {
                name: name.to_string(),
                source,
            })?;
        self.allocated(allocation.size());
        Ok(allocation)
    }
}
