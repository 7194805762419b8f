//! [`MemoryReport`]: the device memory a renderer or GI context holds, by what it is for.

/// Bytes of device memory by category, summed from the objects that own them (so that a
/// host sharing its allocator can tell shine's memory from its own, and what each part costs).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MemoryReport {
    /// The scene: geometry, materials, textures, lights, the BVH, deformer data, the baked
    /// environment.
    pub scene: u64,
    /// The techniques' persistent tables and caches (BRDF SH tables, proxy tables, the
    /// environment's SH, the proxies).
    pub gi_caches: u64,
    /// Per-frame records kept on the device (shadow records, motion view, host frame
    /// constants, readback buffers).
    pub frame_data: u64,
    /// Host-visible staging rings of the per-frame uploads.
    pub staging: u64,
    /// The render graph's aliased transient heaps (one set per transient layout and frame
    /// slot).
    pub transients: u64,
    /// Resources kept across frames by the graph: histories and temporal images.
    pub history: u64,
    /// Objects dropped and waiting for the GPU to finish with them.
    pub pending_release: u64,
}

impl MemoryReport {
    /// Every category summed: equals `Device::memory_usage().allocated_bytes` when nothing
    /// else allocates on the device.
    pub fn total(&self) -> u64 {
        self.scene
            + self.gi_caches
            + self.frame_data
            + self.staging
            + self.transients
            + self.history
            + self.pending_release
    }
}
