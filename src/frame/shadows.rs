//! The shadow atlas's persistent state: the device buffers of the shadow records, kept while
//! the scene and the tile size are unchanged, and rewritten every frame (lights move) through
//! a staging ring.

use shine_gpu::{Buffer, Device};
use shine_graph::RenderGraph;

use super::error::RenderError;
use crate::gpu_scene::upload_ring::UploadRing;
use crate::gpu_scene::{FrameState, SceneHandles};
use crate::passes::shadows::{self, ShadowAtlas, ShadowLayout};

/// The atlas layout of the current frame for one `(tile size, PCF radius)` and the record
/// buffers on the device.
pub struct ShadowState {
    key: (u32, u32),
    layout: ShadowLayout,
    views: Buffer,
    lights: Buffer,
    ring: UploadRing,
}

impl ShadowState {
    /// The state for `frame` with tiles of `size` texels and a PCF kernel of `pcf_radius`:
    /// the layout is made anew (lights move), the buffers are `cached`'s when the key
    /// matches, new ones otherwise (the old ones' destruction is deferred past the frames
    /// that read them). [`ShadowState::declare`] fills them.
    pub fn prepare(
        device: &Device,
        cached: Option<Self>,
        frame: &FrameState,
        size: u32,
        pcf_radius: u32,
    ) -> Result<Self, RenderError> {
        let key = (size, pcf_radius);
        let max_dimension = device.limits().max_image_dimension2_d;
        let layout = ShadowLayout::new(frame, size, pcf_radius, max_dimension)?;
        if let Some(state) = cached.filter(|s| s.key == key) {
            return Ok(Self { layout, ..state });
        }
        let records = |name, bytes: usize| Buffer::storage_for_uploads(device, name, bytes as u64);
        let views = records(
            "shadow views",
            std::mem::size_of_val(layout.view_records().as_slice()),
        )?;
        let lights = records(
            "shadow lights",
            std::mem::size_of_val(layout.light_records().as_slice()),
        )?;
        Ok(Self {
            key,
            layout,
            views,
            lights,
            ring: UploadRing::new(device),
        })
    }

    /// Bytes of device memory: `(records, staging)`.
    pub fn allocated_bytes(&self) -> (u64, u64) {
        (
            self.views.allocated_bytes() + self.lights.allocated_bytes(),
            self.ring.allocated_bytes(),
        )
    }

    /// What the layout had to compromise on (tiles shrunk to fit the device), if anything.
    pub fn warning(&self) -> Option<&str> {
        self.layout.warning.as_deref()
    }

    /// Uploads this frame's records and adds the atlas's raster passes.
    pub fn declare(
        &mut self,
        rg: &mut RenderGraph,
        scene: &SceneHandles,
    ) -> Result<ShadowAtlas, RenderError> {
        let views = self.ring.upload(
            rg,
            "shadow views",
            &self.views,
            bytemuck::cast_slice(&self.layout.view_records()),
        )?;
        let lights = self.ring.upload(
            rg,
            "shadow lights",
            &self.lights,
            bytemuck::cast_slice(&self.layout.light_records()),
        )?;
        Ok(shadows::shadow_atlas(
            rg,
            scene,
            &self.layout,
            views,
            lights,
        ))
    }
}
