//! The shadow atlas's persistent state: the layout of the current scene's shadow tiles and
//! its records on the device, kept while the scene and the tile size are unchanged.

use shine_gpu::{Buffer, Device};
use shine_graph::RenderGraph;

use super::error::RenderError;
use crate::gpu_scene::{BUFFER_READ, GpuScene};
use crate::passes::gbuffer::SceneHandles;
use crate::passes::shadows::{self, ShadowAtlas, ShadowLayout};

/// The atlas layout for one `(tile size, PCF radius)` and its GPU records.
pub struct ShadowState {
    key: (u32, u32),
    layout: ShadowLayout,
    views: Buffer,
    lights: Buffer,
}

impl ShadowState {
    /// The state for `scene` with tiles of `size` texels and a PCF kernel of `pcf_radius`:
    /// `cached` when it matches, a new layout otherwise (after the queue idles, since frames a
    /// host recorded may still read the old records and shine cannot see host submissions).
    pub fn prepare(
        device: &Device,
        cached: Option<Self>,
        scene: &GpuScene,
        size: u32,
        pcf_radius: u32,
    ) -> Result<Self, RenderError> {
        let key = (size, pcf_radius);
        if let Some(state) = cached {
            if state.key == key {
                return Ok(state);
            }
            device.wait_idle()?;
        }
        let max_dimension = device.limits().max_image_dimension2_d;
        let layout = ShadowLayout::new(scene, size, pcf_radius, max_dimension)?;
        let views = Buffer::storage_with_data(
            device,
            "shadow views",
            bytemuck::cast_slice(&layout.view_records()),
        )?;
        let lights = Buffer::storage_with_data(
            device,
            "shadow lights",
            bytemuck::cast_slice(&layout.light_records()),
        )?;
        Ok(Self {
            key,
            layout,
            views,
            lights,
        })
    }

    /// What the layout had to compromise on (tiles shrunk to fit the device), if anything.
    pub fn warning(&self) -> Option<&str> {
        self.layout.warning.as_deref()
    }

    /// Imports the records and adds the atlas's raster passes.
    pub fn declare(&self, rg: &mut RenderGraph, scene: &SceneHandles) -> ShadowAtlas {
        let views = rg.import_gpu_buffer(&self.views, BUFFER_READ, BUFFER_READ);
        let lights = rg.import_gpu_buffer(&self.lights, BUFFER_READ, BUFFER_READ);
        shadows::shadow_atlas(rg, scene, &self.layout, views, lights)
    }
}
