//! Transient memory aliasing: placing resources whose lifetimes do not overlap in the same memory.
//!
//! Greedy by size: the largest resource is placed first, each at the lowest aligned offset of a
//! heap where it overlaps no resource that is alive at the same time. Buffers and images get
//! separate heaps (no buffer-image granularity to respect), and a resource only joins a heap
//! whose memory types it shares.

use shine_gpu::vk;

use crate::handle::ResourceId;
use crate::resource::{BufferDesc, ImageDesc};

/// Memory needs of one resource (as `vkGet*MemoryRequirements` reports them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct MemoryNeeds {
    /// Bytes.
    pub size: u64,
    /// Required alignment of the offset, in bytes (a power of two).
    pub alignment: u64,
    /// Memory types it can live in, one bit per type index.
    pub type_bits: u32,
}

impl From<vk::MemoryRequirements> for MemoryNeeds {
    fn from(r: vk::MemoryRequirements) -> Self {
        Self {
            size: r.size,
            alignment: r.alignment.max(1),
            type_bits: r.memory_type_bits,
        }
    }
}

/// Tells the compiler how much memory a resource of a description and usage needs. The GPU
/// executor asks the device; tests can answer with any arithmetic.
pub trait MemoryRequirements {
    /// Needs of an optimally tiled image.
    fn image(&self, desc: &ImageDesc, usage: vk::ImageUsageFlags) -> MemoryNeeds;
    /// Needs of a buffer.
    fn buffer(&self, desc: &BufferDesc, usage: vk::BufferUsageFlags) -> MemoryNeeds;
}

/// Whether an aliasing heap holds buffers or images.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum HeapClass {
    /// Buffers only.
    Buffers,
    /// Optimally tiled images only.
    Images,
}

/// One block of device memory shared by transients.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Heap {
    /// What it holds.
    pub class: HeapClass,
    /// Bytes.
    pub size: u64,
    /// Largest alignment of its residents.
    pub alignment: u64,
    /// Memory types every resident accepts.
    pub type_bits: u32,
}

/// Where a transient resource lives.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Placement {
    /// The resource.
    pub resource: ResourceId,
    /// Index into [`MemoryPlan::heaps`].
    pub heap: usize,
    /// Byte offset in the heap.
    pub offset: u64,
    /// Bytes it occupies.
    pub size: u64,
    /// First and last position (in execution order) of the passes that use it.
    pub lifetime: (usize, usize),
}

impl Placement {
    /// Whether two placements share bytes of the same heap.
    pub fn overlaps_memory(&self, other: &Placement) -> bool {
        self.heap == other.heap
            && self.offset < other.offset + other.size
            && other.offset < self.offset + self.size
    }

    /// Whether two placements are alive during a common pass.
    pub fn overlaps_lifetime(&self, other: &Placement) -> bool {
        self.lifetime.0 <= other.lifetime.1 && other.lifetime.0 <= self.lifetime.1
    }
}

/// Transient memory of a compiled graph.
#[derive(Clone, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct MemoryPlan {
    /// Blocks to allocate.
    pub heaps: Vec<Heap>,
    /// Where each transient lives, in resource order.
    pub placements: Vec<Placement>,
    /// Bytes the transients would need without aliasing.
    pub requested_bytes: u64,
    /// Bytes of the heaps.
    pub allocated_bytes: u64,
}

impl MemoryPlan {
    /// Bytes aliasing saves: requested minus allocated, or 0 when alignment padding makes the
    /// heaps larger than the sum of their residents.
    pub fn saved_bytes(&self) -> u64 {
        self.requested_bytes.saturating_sub(self.allocated_bytes)
    }

    /// The placement of a resource, if it is an allocated transient.
    pub fn placement(&self, resource: ResourceId) -> Option<&Placement> {
        self.placements.iter().find(|p| p.resource == resource)
    }
}

/// A transient to place.
#[derive(Clone, Copy, Debug)]
pub(crate) struct AliasRequest {
    pub resource: ResourceId,
    pub class: HeapClass,
    pub needs: MemoryNeeds,
    pub lifetime: (usize, usize),
}

fn align_up(value: u64, alignment: u64) -> u64 {
    value.div_ceil(alignment) * alignment
}

/// Lowest aligned offset of `size` bytes that avoids every `(offset, end)` interval.
fn lowest_free(mut taken: Vec<(u64, u64)>, size: u64, alignment: u64) -> u64 {
    taken.sort_unstable();
    let mut candidate = 0;
    for (start, end) in taken {
        if align_up(candidate, alignment) + size <= start {
            break;
        }
        candidate = candidate.max(end);
    }
    align_up(candidate, alignment)
}

/// Place every request; see the module documentation.
pub(crate) fn plan(requests: &[AliasRequest]) -> MemoryPlan {
    let mut order: Vec<&AliasRequest> = requests.iter().collect();
    order.sort_by_key(|r| (std::cmp::Reverse(r.needs.size), r.lifetime.0, r.resource));
    let mut heaps: Vec<Heap> = Vec::new();
    let mut placements: Vec<Placement> = Vec::new();
    for req in order {
        let heap = match heaps
            .iter()
            .position(|h| h.class == req.class && h.type_bits & req.needs.type_bits != 0)
        {
            Some(i) => i,
            None => {
                heaps.push(Heap {
                    class: req.class,
                    size: 0,
                    alignment: 1,
                    type_bits: req.needs.type_bits,
                });
                heaps.len() - 1
            }
        };
        let mut placed = Placement {
            resource: req.resource,
            heap,
            offset: 0,
            size: req.needs.size,
            lifetime: req.lifetime,
        };
        let taken = placements
            .iter()
            .filter(|p| p.heap == heap && p.overlaps_lifetime(&placed))
            .map(|p| (p.offset, p.offset + p.size))
            .collect();
        placed.offset = lowest_free(taken, req.needs.size, req.needs.alignment);
        let h = &mut heaps[heap];
        h.size = h.size.max(placed.offset + placed.size);
        h.alignment = h.alignment.max(req.needs.alignment);
        h.type_bits &= req.needs.type_bits;
        placements.push(placed);
    }
    placements.sort_by_key(|p| p.resource);
    MemoryPlan {
        requested_bytes: requests.iter().map(|r| r.needs.size).sum(),
        allocated_bytes: heaps.iter().map(|h| h.size).sum(),
        heaps,
        placements,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn req(id: u32, size: u64, lifetime: (usize, usize)) -> AliasRequest {
        AliasRequest {
            resource: ResourceId(id),
            class: HeapClass::Images,
            needs: MemoryNeeds {
                size,
                alignment: 256,
                type_bits: 0b11,
            },
            lifetime,
        }
    }

    #[test]
    fn disjoint_lifetimes_share_memory() {
        let plan = plan(&[
            req(0, 1024, (0, 1)),
            req(1, 1024, (2, 3)),
            req(2, 512, (1, 2)),
        ]);
        assert_eq!(plan.heaps.len(), 1);
        assert_eq!(plan.placement(ResourceId(0)).unwrap().offset, 0);
        assert_eq!(plan.placement(ResourceId(1)).unwrap().offset, 0);
        assert_eq!(plan.placement(ResourceId(2)).unwrap().offset, 1024);
        assert_eq!(plan.requested_bytes, 2560);
        assert_eq!(plan.allocated_bytes, 1536);
        assert_eq!(plan.saved_bytes(), 1024);
    }

    #[test]
    fn gaps_are_reused_with_alignment() {
        // 0 and 1 live together; 2 fits in the hole left by 3 once 3 is dead.
        let plan = plan(&[
            req(0, 1000, (0, 4)),
            req(1, 1000, (0, 4)),
            req(2, 300, (3, 4)),
            req(3, 600, (0, 1)),
        ]);
        let p = |i| *plan.placement(ResourceId(i)).unwrap();
        assert_eq!(p(0).offset, 0);
        assert_eq!(p(1).offset, 1024);
        assert_eq!(p(3).offset, 2048);
        assert_eq!(p(2).offset, 2048);
        assert_eq!(plan.allocated_bytes, 2648);
    }

    #[test]
    fn incompatible_memory_types_get_their_own_heap() {
        let mut other = req(1, 64, (5, 6));
        other.needs.type_bits = 0b100;
        let plan = plan(&[req(0, 64, (0, 1)), other]);
        assert_eq!(plan.heaps.len(), 2);
        assert_eq!(plan.saved_bytes(), 0);
    }
}
