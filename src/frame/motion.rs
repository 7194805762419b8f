//! The camera half of motion vectors: the previous frame's unjittered world-to-clip matrix,
//! kept across frames and uploaded with this frame's as a [`MotionView`] (the vertex half is
//! the scene's previous vertices, `GpuScene::prev_vertices`).

use glam::Mat4;
use shine_gpu::{Buffer, Device};
use shine_graph::{Handle, RenderGraph};

use super::error::RenderError;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::passes::gbuffer::MotionView;

/// The last frame's camera and the device buffer of the frame's [`MotionView`].
pub struct MotionState {
    /// Extent and unjittered world-to-clip of the last frame declared.
    previous: Option<([u32; 2], Mat4)>,
    buffer: Buffer,
    ring: UploadRing,
}

impl MotionState {
    /// No previous frame yet.
    pub fn new(device: &Device) -> Result<Self, RenderError> {
        Ok(Self {
            previous: None,
            buffer: Buffer::storage_for_uploads(
                device,
                "motion view",
                std::mem::size_of::<MotionView>() as u64,
            )?,
            ring: UploadRing::new(device),
        })
    }

    /// Bytes of device memory: `(the motion view, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        (self.buffer.allocated_bytes(), self.ring.allocated_bytes())
    }

    /// Forgets the last frame (a new scene: its first frame has no motion).
    pub fn reset(&mut self) {
        self.previous = None;
    }

    /// Uploads this frame's [`MotionView`] (`current`: the unjittered camera of a frame of
    /// `extent`; the previous frame's when it had the same extent, else `current` again) and
    /// remembers `current` for the next frame.
    pub fn declare(
        &mut self,
        rg: &mut RenderGraph,
        current: Mat4,
        extent: [u32; 2],
    ) -> Result<Handle<shine_graph::Buffer>, RenderError> {
        let previous = match self.previous {
            Some((e, m)) if e == extent => m,
            _ => current,
        };
        self.previous = Some((extent, current));
        let view = MotionView {
            previous: previous.to_cols_array_2d(),
            current: current.to_cols_array_2d(),
        };
        Ok(self
            .ring
            .upload(rg, "motion view", &self.buffer, bytemuck::bytes_of(&view))?)
    }
}
