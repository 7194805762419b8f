//! The device's `VkPipelineCache`: every pipeline shine creates goes through it. A host lends
//! its own (and saves it with `vkGetPipelineCacheData`); otherwise shine makes an empty one
//! whose contents [`Device::pipeline_cache_data`] hands out for the next run's
//! [`crate::DeviceDesc::pipeline_cache_data`].

use crate::device::Device;
use crate::error::{Result, VkContext};
use ash::vk;
use std::sync::atomic::{AtomicU64, Ordering};

/// The cache pipelines are created through, and how many were created.
pub(crate) struct PipelineCache {
    raw: vk::PipelineCache,
    /// Whether shine created `raw` (and destroys it).
    owned: bool,
    /// Pipelines created on the device so far (compute and graphics).
    created: AtomicU64,
}

impl PipelineCache {
    /// `host`'s cache when it is not null, else a new one seeded with `initial` (a previous
    /// run's [`Device::pipeline_cache_data`]; the driver ignores data it did not write).
    pub(crate) fn new(
        device: &ash::Device,
        host: vk::PipelineCache,
        initial: &[u8],
    ) -> Result<Self> {
        if host != vk::PipelineCache::null() {
            return Ok(Self {
                raw: host,
                owned: false,
                created: AtomicU64::new(0),
            });
        }
        let info = vk::PipelineCacheCreateInfo::default().initial_data(initial);
        // SAFETY: a live device; the data is only read.
        let raw = unsafe { device.create_pipeline_cache(&info, None) }
            .ctx("creating the pipeline cache")?;
        Ok(Self {
            raw,
            owned: true,
            created: AtomicU64::new(0),
        })
    }

    /// The cache to pass to `vkCreate*Pipelines`, counting the pipeline about to be made.
    pub(crate) fn for_creation(&self) -> vk::PipelineCache {
        self.created.fetch_add(1, Ordering::Relaxed);
        self.raw
    }

    /// Destroys the cache when shine made it (before its device goes).
    pub(crate) fn destroy(&mut self, device: &ash::Device) {
        if self.owned {
            // SAFETY: no pipeline creation is in flight (the device is being dropped).
            unsafe { device.destroy_pipeline_cache(self.raw, None) };
            self.owned = false;
        }
    }
}

impl Device {
    /// The pipeline cache's contents, to save and hand to the next run (a host that lent its
    /// own cache may save it itself).
    pub fn pipeline_cache_data(&self) -> Result<Vec<u8>> {
        // SAFETY: the cache belongs to this device; reading is internally synchronised.
        unsafe {
            self.raw()
                .get_pipeline_cache_data(self.inner.pipeline_cache.raw)
        }
        .ctx("reading the pipeline cache")
    }

    /// How many pipelines shine has created on this device: a frame that creates none has no
    /// compile hitch (what `GiContext::warm_up` guarantees for the frames after it).
    pub fn pipelines_created(&self) -> u64 {
        self.inner.pipeline_cache.created.load(Ordering::Relaxed)
    }

    /// The cache for a pipeline about to be created.
    pub(crate) fn pipeline_cache(&self) -> vk::PipelineCache {
        self.inner.pipeline_cache.for_creation()
    }
}
