//! The host's own images and buffers, allocated from its gpu-allocator, and its readback.

use super::HostDevice;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use shine::gpu::ash::vk;
use std::error::Error;

/// An image the host allocated itself, with a view of its one mip and layer.
pub struct HostImage {
    pub image: vk::Image,
    pub view: vk::ImageView,
    pub format: vk::Format,
    pub extent: [u32; 2],
    pub usage: vk::ImageUsageFlags,
    allocation: Option<Allocation>,
}

impl HostImage {
    /// A 2D image of `format`, `extent` and `usage`, in device memory from the host's
    /// allocator.
    pub fn new(
        host: &HostDevice,
        name: &str,
        format: vk::Format,
        extent: [u32; 2],
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, Box<dyn Error>> {
        let depth = matches!(format, vk::Format::D32_SFLOAT);
        // SAFETY: plain object creation on the host's device; destroyed by `destroy`.
        unsafe {
            let image = host.device.create_image(
                &vk::ImageCreateInfo::default()
                    .image_type(vk::ImageType::TYPE_2D)
                    .format(format)
                    .extent(vk::Extent3D {
                        width: extent[0],
                        height: extent[1],
                        depth: 1,
                    })
                    .mip_levels(1)
                    .array_layers(1)
                    .samples(vk::SampleCountFlags::TYPE_1)
                    .usage(usage),
                None,
            )?;
            let requirements = host.device.get_image_memory_requirements(image);
            let allocation = host
                .allocator()
                .lock()
                .unwrap()
                .allocate(&AllocationCreateDesc {
                    name,
                    requirements,
                    location: MemoryLocation::GpuOnly,
                    linear: false,
                    allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                })?;
            host.device
                .bind_image_memory(image, allocation.memory(), allocation.offset())?;
            let aspect = if depth {
                vk::ImageAspectFlags::DEPTH
            } else {
                vk::ImageAspectFlags::COLOR
            };
            let view = host.device.create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(format)
                    .subresource_range(range(aspect)),
                None,
            )?;
            Ok(Self {
                image,
                view,
                format,
                extent,
                usage,
                allocation: Some(allocation),
            })
        }
    }

    /// The image as shine sees it, coming from `before` and left in `after`.
    pub fn lend(
        &self,
        before: shine::graph::ExternalState,
        after: shine::graph::ExternalState,
    ) -> shine::HostTarget {
        shine::HostTarget {
            image: self.image,
            view: self.view,
            format: self.format,
            extent: self.extent,
            usage: self.usage,
            before,
            after,
        }
    }

    /// Destroys the image (the GPU must be done with it).
    pub fn destroy(mut self, host: &HostDevice) {
        // SAFETY: made on this device by `new`; the caller says the GPU is done with it.
        unsafe {
            host.device.destroy_image_view(self.view, None);
            host.device.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = host.allocator().lock().unwrap().free(a);
        }
    }
}

/// The whole of a one-mip, one-layer image of `aspect`.
pub(super) fn range(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// A host-visible buffer from the host's allocator.
pub struct HostBuffer {
    pub buffer: vk::Buffer,
    allocation: Option<Allocation>,
}

impl HostBuffer {
    /// A buffer of `size` bytes for `usage`, in `location` memory.
    pub fn new(
        host: &HostDevice,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, Box<dyn Error>> {
        // SAFETY: plain object creation; destroyed by `destroy`.
        unsafe {
            let buffer = host.device.create_buffer(
                &vk::BufferCreateInfo::default().size(size).usage(usage),
                None,
            )?;
            let requirements = host.device.get_buffer_memory_requirements(buffer);
            let allocation = host
                .allocator()
                .lock()
                .unwrap()
                .allocate(&AllocationCreateDesc {
                    name,
                    requirements,
                    location,
                    linear: true,
                    allocation_scheme: AllocationScheme::GpuAllocatorManaged,
                })?;
            host.device
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())?;
            Ok(Self {
                buffer,
                allocation: Some(allocation),
            })
        }
    }

    /// The mapped bytes (host-visible buffers).
    pub fn bytes(&mut self) -> &mut [u8] {
        self.allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .expect("host-visible")
    }

    /// Destroys the buffer (the GPU must be done with it).
    pub fn destroy(mut self, host: &HostDevice) {
        // SAFETY: made on this device; the caller says the GPU is done with it.
        unsafe { host.device.destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            let _ = host.allocator().lock().unwrap().free(a);
        }
    }
}

/// Copies an RGBA16F `image`, last used as `from`, to the CPU as f32 texels (the host's own
/// submission, waited for).
pub fn read_rgba16f(
    host: &HostDevice,
    image: &HostImage,
    from: shine::graph::ExternalState,
) -> Result<Vec<[f32; 4]>, Box<dyn Error>> {
    let [w, h] = image.extent;
    let bytes = u64::from(w) * u64::from(h) * 8;
    let mut buffer = HostBuffer::new(
        host,
        "host readback",
        bytes,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    let cb = host.begin()?;
    let barrier = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(from.stage)
        .src_access_mask(from.access)
        .dst_stage_mask(vk::PipelineStageFlags2::COPY)
        .dst_access_mask(vk::AccessFlags2::TRANSFER_READ)
        .old_layout(from.layout)
        .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
        .image(image.image)
        .subresource_range(range(vk::ImageAspectFlags::COLOR))];
    // SAFETY: handles of the host's device; the submission is waited for below.
    unsafe {
        host.device.cmd_pipeline_barrier2(
            cb,
            &vk::DependencyInfo::default().image_memory_barriers(&barrier),
        );
        host.device.cmd_copy_image_to_buffer(
            cb,
            image.image,
            vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
            buffer.buffer,
            &[whole_copy(image.extent)],
        );
    }
    host.submit_and_wait(cb)?;
    let texels = buffer.bytes()[..bytes as usize]
        .chunks_exact(8)
        .map(|t| {
            let half = |i: usize| f16_to_f32(u16::from_le_bytes([t[2 * i], t[2 * i + 1]]));
            [half(0), half(1), half(2), half(3)]
        })
        .collect();
    buffer.destroy(host);
    Ok(texels)
}

/// A buffer ↔ image copy of a whole one-mip, one-layer colour image of `extent`, texels packed.
fn whole_copy([width, height]: [u32; 2]) -> vk::BufferImageCopy {
    vk::BufferImageCopy::default()
        .image_subresource(vk::ImageSubresourceLayers {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        })
        .image_extent(vk::Extent3D {
            width,
            height,
            depth: 1,
        })
}

/// IEEE half to single precision.
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exponent = i32::from((h >> 10) & 0x1f);
    let mantissa = f32::from(h & 0x3ff);
    sign * match exponent {
        0 => mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        e => (1.0 + mantissa / 1024.0) * 2f32.powi(e - 15),
    }
}

impl HostImage {
    /// Fills an RGBA32F image (made with `TRANSFER_DST`) with `texels` through a staging
    /// buffer (the host's own submission, waited for), leaving it in
    /// `SHADER_READ_ONLY_OPTIMAL`.
    pub fn upload_rgba32f(
        &self,
        host: &HostDevice,
        texels: &[[f32; 4]],
    ) -> Result<(), Box<dyn Error>> {
        let bytes: &[u8] = bytemuck::cast_slice(texels);
        let mut staging = HostBuffer::new(
            host,
            "host upload",
            bytes.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.bytes()[..bytes.len()].copy_from_slice(bytes);
        let cb = host.begin()?;
        let to = |old, new, src_stage, src_access, dst_stage, dst_access| {
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(src_stage)
                .src_access_mask(src_access)
                .dst_stage_mask(dst_stage)
                .dst_access_mask(dst_access)
                .old_layout(old)
                .new_layout(new)
                .image(self.image)
                .subresource_range(range(vk::ImageAspectFlags::COLOR))
        };
        // SAFETY: handles of the host's device; the submission is waited for below.
        unsafe {
            host.device.cmd_pipeline_barrier2(
                cb,
                &vk::DependencyInfo::default().image_memory_barriers(&[to(
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::PipelineStageFlags2::NONE,
                    vk::AccessFlags2::NONE,
                    vk::PipelineStageFlags2::COPY,
                    vk::AccessFlags2::TRANSFER_WRITE,
                )]),
            );
            host.device.cmd_copy_buffer_to_image(
                cb,
                staging.buffer,
                self.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[whole_copy(self.extent)],
            );
            host.device.cmd_pipeline_barrier2(
                cb,
                &vk::DependencyInfo::default().image_memory_barriers(&[to(
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::PipelineStageFlags2::COPY,
                    vk::AccessFlags2::TRANSFER_WRITE,
                    vk::PipelineStageFlags2::ALL_COMMANDS,
                    vk::AccessFlags2::MEMORY_READ,
                )]),
            );
        }
        host.submit_and_wait(cb)?;
        staging.destroy(host);
        Ok(())
    }
}
