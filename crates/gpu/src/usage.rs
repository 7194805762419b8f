//! shine's own device-memory accounting: what it allocated and freed, counted apart from a
//! host's allocations in a shared allocator.

use crate::device::{Device, lock};
use gpu_allocator::vulkan::Allocator;
use std::sync::MutexGuard;

impl Device {
    /// Device memory shine holds right now (buffers, images, the render graph's heaps): what
    /// a long run must keep flat. Counted by shine, so a host's allocations in a shared
    /// allocator are not in it.
    pub fn memory_usage(&self) -> MemoryUsage {
        let (allocated_bytes, allocations) = *lock(&self.inner.usage);
        MemoryUsage {
            allocated_bytes,
            capacity_bytes: self.allocator().generate_report().total_capacity_bytes,
            allocations,
        }
    }

    pub(crate) fn allocator(&self) -> MutexGuard<'_, Allocator> {
        lock(&self.inner.allocator)
    }

    /// Counts an allocation of `bytes` shine made.
    pub(crate) fn allocated(&self, bytes: u64) {
        let mut usage = lock(&self.inner.usage);
        usage.0 += bytes;
        usage.1 += 1;
    }

    /// Counts `(bytes, allocations)` shine freed.
    pub(crate) fn freed(&self, (bytes, count): (u64, usize)) {
        let mut usage = lock(&self.inner.usage);
        usage.0 = usage.0.saturating_sub(bytes);
        usage.1 = usage.1.saturating_sub(count);
    }
}

/// A snapshot of the device memory shine holds ([`Device::memory_usage`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MemoryUsage {
    /// Bytes in live allocations.
    pub allocated_bytes: u64,
    /// Bytes of the memory blocks of the allocator shine uses (allocated or free; the host's
    /// blocks too when it shares its allocator).
    pub capacity_bytes: u64,
    /// Number of live allocations.
    pub allocations: usize,
}
