//! Per-frame uploads without waiting: a ring of host-visible staging buffers, one set per
//! frame in flight, copied into device buffers (and the BVH's images) by `update …` transfer
//! passes recorded into the frame's own command buffer.
//!
//! Frame `f` writes the staging buffers of its graph's slot (`RenderGraph::slot`, `f mod n`
//! for an executor with `n` frames in flight). The executor lets at most `n` frames run ahead
//! of the GPU (a host recording with [`crate::Renderer::record`] promises the same), so when
//! frame `f` is declared, frame `f - n`, the last reader of that slot, has completed. Staging buffers are created on first use with the size of their
//! destination (or of the prefix rewritten) and then reused, so a steady stream of frames
//! allocates nothing.

use shine_gpu::{Buffer, BufferDesc, Device, Image, MemoryLocation, format_texel_size, vk};
use shine_graph::{ExternalState, Handle, RenderGraph};

use super::{BUFFER_READ, STORAGE_READ};

/// A ring of staging buffers for the device buffers a frame rewrites.
pub struct UploadRing {
    device: Device,
    /// Per slot: (name, staging buffer); as many slots as the graphs' frames in flight.
    slots: Vec<Vec<(String, Buffer)>>,
    /// Per slot: the frame that last used it and the staging buffers of its one-off uploads
    /// ([`UploadRing::upload_once`]), dropped when the slot comes round again.
    once: Vec<(u64, Vec<Buffer>)>,
}

impl UploadRing {
    /// An empty ring: slots are made as the frames' graphs ask for them.
    pub fn new(device: &Device) -> Self {
        Self {
            device: device.clone(),
            slots: Vec::new(),
            once: Vec::new(),
        }
    }

    /// Bytes of device memory its staging buffers hold.
    pub fn allocated_bytes(&self) -> u64 {
        self.slots
            .iter()
            .flatten()
            .map(|(_, b)| b)
            .chain(self.once.iter().flat_map(|(_, b)| b))
            .map(Buffer::allocated_bytes)
            .sum()
    }

    /// Adds a transfer pass `upload <name>` writing `data` into `dst` (a device buffer with
    /// `TRANSFER_DST`, read by any stage after the frame) from a staging buffer of its own,
    /// kept until this frame's slot comes round again: for data written once (tables), where
    /// [`UploadRing::upload`] would keep a staging buffer per slot for ever. Returns `dst`'s
    /// handle after the copy. Nothing waits: the copy runs in the frame's command buffer.
    pub fn upload_once(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        dst: &Buffer,
        data: &[u8],
    ) -> Result<Handle<crate::graph::Buffer>, shine_gpu::Error> {
        if data.is_empty() || data.len() as u64 > dst.size() {
            return Err(shine_gpu::Error::InvalidUsage(format!(
                "upload `{name}`: {} bytes for a {}-byte buffer",
                data.len(),
                dst.size()
            )));
        }
        let mut staging = Buffer::new(
            &self.device,
            &BufferDesc {
                name: &format!("staging {name}"),
                size: data.len() as u64,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )?;
        staging
            .mapped_mut()
            .ok_or_else(|| {
                shine_gpu::Error::InvalidUsage(format!(
                    "staging buffer `{name}` is not host-visible"
                ))
            })?
            .copy_from_slice(data);
        let src =
            rg.import_gpu_buffer(&staging, ExternalState::UNDEFINED, ExternalState::UNDEFINED);
        let mut handle = rg.import_gpu_buffer(dst, ExternalState::UNDEFINED, BUFFER_READ);
        rg.copy_buffer(&format!("upload {name}"), &src, &mut handle);
        if self.once.len() != rg.frames_in_flight() {
            self.once = (0..rg.frames_in_flight())
                .map(|_| (0, Vec::new()))
                .collect();
        }
        let (frame, buffers) = &mut self.once[rg.slot()];
        if *frame != rg.frame() {
            // The slot's last frame has completed (module docs): its staging buffers can go.
            buffers.clear();
            *frame = rg.frame();
        }
        buffers.push(staging);
        Ok(handle)
    }

    /// Writes `data` into this frame's staging buffer `name` and adds a transfer pass
    /// `update <name>` copying it into `dst` (a persistent device buffer with `TRANSFER_DST`,
    /// read by any stage before and after the frame). Returns `dst`'s handle after the copy:
    /// readers must use it, so the graph orders them after the update.
    pub fn upload(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        dst: &Buffer,
        data: &[u8],
    ) -> Result<Handle<crate::graph::Buffer>, shine_gpu::Error> {
        self.stage(rg, name, dst, data, dst.size())
    }

    /// As [`UploadRing::upload`], but rewrites only the first `data.len()` bytes of `dst`
    /// (the rest keeps what it holds). `data` must keep its length from frame to frame, or
    /// the staging buffer is replaced.
    pub fn upload_prefix(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        dst: &Buffer,
        data: &[u8],
    ) -> Result<Handle<crate::graph::Buffer>, shine_gpu::Error> {
        self.stage(rg, name, dst, data, (data.len() as u64).max(4))
    }

    /// Writes `data` (whole rows of tightly packed texels) into this frame's staging buffer
    /// `name` and adds a transfer pass `update <name>` copying it into the leading rows of
    /// `dst` (a persistent 2D image with `TRANSFER_DST` in `GENERAL` layout, read by any stage
    /// before and after the frame; the other rows keep what they hold). `data` must keep its
    /// length from frame to frame, or the staging buffer is replaced. Returns `dst`'s handle
    /// after the copy.
    pub fn upload_image_rows(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        dst: &Image,
        data: &[u8],
    ) -> Result<Handle<crate::graph::Image>, shine_gpu::Error> {
        let [w, h] = dst.extent();
        let texel = format_texel_size(dst.format()).unwrap_or(0) as usize;
        let row = w as usize * texel;
        if row == 0
            || data.is_empty()
            || !data.len().is_multiple_of(row)
            || data.len() > row * h as usize
        {
            return Err(shine_gpu::Error::InvalidUsage(format!(
                "upload `{name}`: {} bytes are not whole rows of its {w}×{h} image ({row} bytes \
                 a row)",
                data.len()
            )));
        }
        let src = self.staged(rg, name, data, data.len() as u64)?;
        let mut handle = rg.import_gpu_image(dst, STORAGE_READ, STORAGE_READ);
        rg.copy_buffer_to_image(&format!("update {name}"), &src, &mut handle);
        Ok(handle)
    }

    /// Stages `data` in a buffer of `size` bytes and copies that whole buffer into `dst`.
    fn stage(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        dst: &Buffer,
        data: &[u8],
        size: u64,
    ) -> Result<Handle<crate::graph::Buffer>, shine_gpu::Error> {
        if data.len() as u64 > dst.size() || size > dst.size() {
            return Err(shine_gpu::Error::InvalidUsage(format!(
                "upload `{name}`: {} bytes do not fit its {}-byte buffer",
                data.len(),
                dst.size()
            )));
        }
        let src = self.staged(rg, name, data, size)?;
        let mut handle = rg.import_gpu_buffer(dst, BUFFER_READ, BUFFER_READ);
        rg.copy_buffer(&format!("update {name}"), &src, &mut handle);
        Ok(handle)
    }

    /// This frame's staging buffer `name` of `size` bytes (made or replaced when its size
    /// changes) holding `data` at its start, imported into `rg`.
    fn staged(
        &mut self,
        rg: &mut RenderGraph,
        name: &str,
        data: &[u8],
        size: u64,
    ) -> Result<Handle<crate::graph::Buffer>, shine_gpu::Error> {
        // A graph with another number of frames in flight (a new executor) starts over: the
        // old staging buffers are dropped, their destruction deferred past their last frame.
        if self.slots.len() != rg.frames_in_flight() {
            self.slots = (0..rg.frames_in_flight()).map(|_| Vec::new()).collect();
        }
        let slot = &mut self.slots[rg.slot()];
        let index = match slot.iter().position(|(n, _)| n == name) {
            Some(i) if slot[i].1.size() == size => i,
            found => {
                // A destination of a new size (a new scene): the old staging buffer's last
                // reader finished (see the module docs), so it can go.
                if let Some(i) = found {
                    slot.swap_remove(i);
                }
                let staging = Buffer::new(
                    &self.device,
                    &BufferDesc {
                        name: &format!("staging {name}"),
                        size,
                        usage: vk::BufferUsageFlags::TRANSFER_SRC,
                        location: MemoryLocation::CpuToGpu,
                    },
                )?;
                slot.push((name.to_owned(), staging));
                slot.len() - 1
            }
        };
        let staging = &mut slot[index].1;
        let mapped = staging.mapped_mut().ok_or_else(|| {
            shine_gpu::Error::InvalidUsage(format!("staging buffer `{name}` is not host-visible"))
        })?;
        mapped[..data.len()].copy_from_slice(data);
        Ok(rg.import_gpu_buffer(staging, ExternalState::UNDEFINED, ExternalState::UNDEFINED))
    }
}
