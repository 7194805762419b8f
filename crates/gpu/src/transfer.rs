//! Staging uploads and readbacks. Each is synchronous (submit and wait): for loading scenes,
//! capturing frames and tests, never for per-frame streaming.

use crate::device::Device;
use crate::error::{Error, Result};
use crate::memory::{Buffer, BufferDesc, Image, MemoryLocation, format_texel_size};
use ash::vk;

/// Any earlier or later GPU access: transfers here are rare and synchronous, so they fence
/// themselves off from everything.
const ANY_ACCESS: (vk::PipelineStageFlags2, vk::AccessFlags2) = (
    vk::PipelineStageFlags2::ALL_COMMANDS,
    vk::AccessFlags2::from_raw(
        vk::AccessFlags2::MEMORY_READ.as_raw() | vk::AccessFlags2::MEMORY_WRITE.as_raw(),
    ),
);
/// The copy's write.
const COPY_WRITE: (vk::PipelineStageFlags2, vk::AccessFlags2) = (
    vk::PipelineStageFlags2::COPY,
    vk::AccessFlags2::TRANSFER_WRITE,
);
/// The copy's read.
const COPY_READ: (vk::PipelineStageFlags2, vk::AccessFlags2) = (
    vk::PipelineStageFlags2::COPY,
    vk::AccessFlags2::TRANSFER_READ,
);
/// A copy's or a blit's write (mip levels are written by both).
const TRANSFER_WRITE: (vk::PipelineStageFlags2, vk::AccessFlags2) = (
    vk::PipelineStageFlags2::from_raw(
        vk::PipelineStageFlags2::COPY.as_raw() | vk::PipelineStageFlags2::BLIT.as_raw(),
    ),
    vk::AccessFlags2::TRANSFER_WRITE,
);
/// A blit's read.
const BLIT_READ: (vk::PipelineStageFlags2, vk::AccessFlags2) = (
    vk::PipelineStageFlags2::BLIT,
    vk::AccessFlags2::TRANSFER_READ,
);
/// The host reading a readback.
const HOST_READ: (vk::PipelineStageFlags2, vk::AccessFlags2) =
    (vk::PipelineStageFlags2::HOST, vk::AccessFlags2::HOST_READ);

impl Device {
    fn staging(
        &self,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Buffer> {
        Buffer::new(
            self,
            &BufferDesc {
                name,
                size,
                usage,
                location,
            },
        )
    }

    /// A host-visible transfer source holding `data`.
    fn staging_with(&self, name: &str, data: &[u8]) -> Result<Buffer> {
        let mut staging = self.staging(
            name,
            data.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        let mapped = staging
            .mapped_mut()
            .ok_or_else(|| Error::InvalidUsage("staging memory is not host-visible".into()))?;
        mapped[..data.len()].copy_from_slice(data);
        Ok(staging)
    }

    /// Writes `data` at `offset` of `buffer` through a staging buffer and a copy (the buffer
    /// needs `TRANSFER_DST`); host-visible buffers can also be written through
    /// [`Buffer::mapped_mut`].
    pub fn upload_buffer(&self, buffer: &Buffer, offset: u64, data: &[u8]) -> Result<()> {
        let end = offset.checked_add(data.len() as u64);
        if end.is_none_or(|end| end > buffer.size()) {
            return Err(Error::InvalidUsage(format!(
                "upload of {} bytes at {offset} overflows `{}` ({} bytes)",
                data.len(),
                buffer.name(),
                buffer.size()
            )));
        }
        if data.is_empty() {
            return Ok(());
        }
        let staging = self.staging_with("staging upload", data)?;
        let region = [vk::BufferCopy {
            src_offset: 0,
            dst_offset: offset,
            size: data.len() as u64,
        }];
        self.run_once(|cmd| {
            cmd.memory_barrier(ANY_ACCESS, COPY_WRITE);
            cmd.copy_buffer(staging.raw(), buffer.raw(), &region);
            cmd.memory_barrier(COPY_WRITE, ANY_ACCESS);
            Ok(())
        })?;
        Ok(())
    }

    /// Reads a whole buffer back (it needs `TRANSFER_SRC`). Waits for the copy.
    pub fn read_buffer(&self, buffer: &Buffer) -> Result<Vec<u8>> {
        self.read_raw_buffer(buffer.raw(), 0, buffer.size())
    }

    /// `size` bytes at `offset` of any buffer of this device with `TRANSFER_SRC` usage (a host
    /// engine's, say), copied back after every earlier write on the device: submits and
    /// waits.
    pub fn read_raw_buffer(&self, buffer: vk::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
        if size == 0 {
            return Ok(Vec::new());
        }
        let staging = self.staging(
            "staging readback",
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let region = [vk::BufferCopy {
            src_offset: offset,
            dst_offset: 0,
            size,
        }];
        self.run_once(|cmd| {
            cmd.memory_barrier(ANY_ACCESS, COPY_READ);
            cmd.copy_buffer(buffer, staging.raw(), &region);
            cmd.memory_barrier(COPY_WRITE, HOST_READ);
            Ok(())
        })?;
        staging
            .mapped()
            .map(<[u8]>::to_vec)
            .ok_or_else(|| Error::InvalidUsage("readback memory is not host-visible".into()))
    }

    /// Uploads mip 0 of every layer of `image` from tightly packed texels (layer after layer),
    /// fills every further mip level by linear blits from the one above (a box filter of each
    /// 2×2 block; the image then needs `TRANSFER_SRC` too), and leaves the image in
    /// `final_layout` (it needs `TRANSFER_DST`).
    pub fn upload_image(
        &self,
        image: &Image,
        data: &[u8],
        final_layout: vk::ImageLayout,
    ) -> Result<()> {
        let expected = image_bytes(image)? * u64::from(image.full_range().layer_count);
        if data.len() as u64 != expected {
            return Err(Error::InvalidUsage(format!(
                "image `{}` needs {expected} bytes, {} given",
                image.name(),
                data.len()
            )));
        }
        let staging = self.staging_with("staging image upload", data)?;
        let range = image.full_range();
        self.run_once(|cmd| {
            cmd.image_barrier(
                image.raw(),
                range,
                (
                    vk::ImageLayout::UNDEFINED,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                ),
                ANY_ACCESS,
                TRANSFER_WRITE,
            );
            let mut region = [copy_region(image, 0)];
            region[0].image_subresource.layer_count = range.layer_count;
            let raw = cmd.device().raw().clone();
            let cb = cmd.raw();
            // SAFETY: the image is in TRANSFER_DST_OPTIMAL and the region lies inside both.
            unsafe {
                raw.cmd_copy_buffer_to_image(
                    cb,
                    staging.raw(),
                    image.raw(),
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &region,
                )
            };
            // Level l is written by a blit from level l - 1, which is first made a source.
            let level_size = |l: u32| level_extent(image, l).map(|side| side as i32);
            for level in 1..range.level_count {
                let source = vk::ImageSubresourceRange {
                    base_mip_level: level - 1,
                    level_count: 1,
                    ..range
                };
                cmd.image_barrier(
                    image.raw(),
                    source,
                    (
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    ),
                    TRANSFER_WRITE,
                    BLIT_READ,
                );
                let layers = |mip_level| vk::ImageSubresourceLayers {
                    aspect_mask: range.aspect_mask,
                    mip_level,
                    base_array_layer: 0,
                    layer_count: range.layer_count,
                };
                let [sw, sh] = level_size(level - 1);
                let [dw, dh] = level_size(level);
                let blit = [vk::ImageBlit {
                    src_subresource: layers(level - 1),
                    src_offsets: [vk::Offset3D::default(), vk::Offset3D { x: sw, y: sh, z: 1 }],
                    dst_subresource: layers(level),
                    dst_offsets: [vk::Offset3D::default(), vk::Offset3D { x: dw, y: dh, z: 1 }],
                }];
                // SAFETY: level - 1 is a transfer source, level a transfer destination, and
                // both regions lie inside their levels.
                unsafe {
                    raw.cmd_blit_image(
                        cb,
                        image.raw(),
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        image.raw(),
                        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                        &blit,
                        vk::Filter::LINEAR,
                    )
                };
            }
            let last = range.level_count - 1;
            if last > 0 {
                cmd.image_barrier(
                    image.raw(),
                    vk::ImageSubresourceRange {
                        level_count: last,
                        ..range
                    },
                    (vk::ImageLayout::TRANSFER_SRC_OPTIMAL, final_layout),
                    BLIT_READ,
                    ANY_ACCESS,
                );
            }
            cmd.image_barrier(
                image.raw(),
                vk::ImageSubresourceRange {
                    base_mip_level: last,
                    level_count: 1,
                    ..range
                },
                (vk::ImageLayout::TRANSFER_DST_OPTIMAL, final_layout),
                TRANSFER_WRITE,
                ANY_ACCESS,
            );
            Ok(())
        })?;
        Ok(())
    }

    /// Reads mip 0, layer 0 of `image`, currently in `layout` (it needs `TRANSFER_SRC`), as
    /// tightly packed texels; the image is returned to `layout`.
    pub fn read_image(&self, image: &Image, layout: vk::ImageLayout) -> Result<Vec<u8>> {
        self.read_image_level(image, layout, 0)
    }

    /// Reads mip `level`, layer 0 of `image` as [`Device::read_image`] reads mip 0.
    pub fn read_image_level(
        &self,
        image: &Image,
        layout: vk::ImageLayout,
        level: u32,
    ) -> Result<Vec<u8>> {
        let levels = image.full_range().level_count;
        if level >= levels {
            return Err(Error::InvalidUsage(format!(
                "image `{}` has {levels} mip levels, level {level} asked for",
                image.name()
            )));
        }
        let bytes = level_bytes(image, level)?;
        let staging = self.staging(
            "staging image readback",
            bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let range = image.full_range();
        self.run_once(|cmd| {
            cmd.image_barrier(
                image.raw(),
                range,
                (layout, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
                ANY_ACCESS,
                COPY_READ,
            );
            let region = [copy_region(image, level)];
            let raw = cmd.device().raw().clone();
            let cb = cmd.raw();
            // SAFETY: the image is in TRANSFER_SRC_OPTIMAL and the region lies inside both.
            unsafe {
                raw.cmd_copy_image_to_buffer(
                    cb,
                    image.raw(),
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    staging.raw(),
                    &region,
                )
            };
            let back = if layout == vk::ImageLayout::UNDEFINED {
                vk::ImageLayout::GENERAL
            } else {
                layout
            };
            cmd.image_barrier(
                image.raw(),
                range,
                (vk::ImageLayout::TRANSFER_SRC_OPTIMAL, back),
                COPY_READ,
                ANY_ACCESS,
            );
            cmd.memory_barrier(COPY_WRITE, HOST_READ);
            Ok(())
        })?;
        staging
            .mapped()
            .map(<[u8]>::to_vec)
            .ok_or_else(|| Error::InvalidUsage("readback memory is not host-visible".into()))
    }
}

/// Width and height of mip `level` of `image`.
fn level_extent(image: &Image, level: u32) -> [u32; 2] {
    image.extent().map(|side| (side >> level).max(1))
}

/// Bytes of one layer of mip `level` of `image`, tightly packed.
fn level_bytes(image: &Image, level: u32) -> Result<u64> {
    let [w, h] = level_extent(image, level);
    Ok(u64::from(w) * u64::from(h) * texel_bytes(image)?)
}

/// Bytes of one layer of mip 0 of `image`, tightly packed.
fn image_bytes(image: &Image) -> Result<u64> {
    level_bytes(image, 0)
}

/// Bytes of one texel of `image`'s format, or an error for formats transfers do not handle.
fn texel_bytes(image: &Image) -> Result<u64> {
    let texel = format_texel_size(image.format()).ok_or_else(|| {
        Error::InvalidUsage(format!(
            "image `{}`: transfers of {:?} are not supported",
            image.name(),
            image.format()
        ))
    })?;
    Ok(u64::from(texel))
}

fn copy_region(image: &Image, level: u32) -> vk::BufferImageCopy {
    let [width, height] = level_extent(image, level);
    let range = image.full_range();
    vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: range.aspect_mask,
            mip_level: level,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D {
            width,
            height,
            depth: 1,
        },
    }
}
