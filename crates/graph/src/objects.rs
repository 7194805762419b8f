//! The Vulkan objects the executor keeps across frames: a set of transients per frame slot and
//! transient layout (bound into the plan's aliased memory, least recently used evicted; plans
//! that differ only in their imports share one) and the temporal
//! resources by key; and the table mapping one frame's resource ids to the objects behind them.

use std::collections::HashMap;
use std::sync::Arc;

use shine_gpu::{Device, MemoryBlock};

use crate::alias::{HeapClass, MemoryNeeds, MemoryRequirements};
use crate::error::ExecuteError;
use crate::gpu_resources::{DeviceMemory, GpuResource, RawObject, allocate, release};
use crate::graph::External;
use crate::handle::ResourceId;
use crate::plan::{Plan, ResourceKind, Usage};
use crate::resource::AnyDesc;

/// Transient sets kept per frame slot for plans seen recently; older ones are destroyed once
/// the frames that used them have completed (deferred by the device, no wait).
const KEPT_TRANSIENT_SETS: usize = 8;

/// The transients of one plan for one frame slot: memory blocks and the objects bound into them.
/// Frames in flight use different slots, so they never share transient memory; a slot is reused
/// only once its previous frame has completed (the [`crate::Executor`] contract).
struct TransientSet {
    /// The plan whose placements the set follows (or one with the same transients).
    plan: Arc<Plan>,
    /// The frame slot using the set.
    slot: usize,
    /// Keeps the blocks allocated while the objects live.
    _heaps: Vec<MemoryBlock>,
    /// The transient resources of the plan, each bound at its placement.
    objects: Vec<(ResourceId, RawObject)>,
}

/// Whether a transient set made for `kept` serves `plan`: the same plan, or one with the same
/// heaps and, at each placement, a resource of the same id, description and usage. Plans that
/// differ only in what they import (a host's image formats, a warm-up's placeholders) then
/// share their transient memory instead of allocating a set each.
fn same_transients(kept: &Plan, plan: &Plan) -> bool {
    if std::ptr::eq(kept, plan) {
        return true;
    }
    let (a, b) = (&kept.memory, &plan.memory);
    a.heaps == b.heaps
        && a.placements == b.placements
        && a.placements.iter().all(|p| {
            match (kept.resource(p.resource), plan.resource(p.resource)) {
                (Some(x), Some(y)) => x.desc == y.desc && x.usage == y.usage,
                _ => false,
            }
        })
}

/// A temporal resource on the GPU.
struct TemporalObject {
    /// The description it was created for: a change recreates it.
    desc: AnyDesc,
    /// The usage it was created with: a change recreates it.
    usage: Usage,
    object: RawObject,
    /// Keeps the block allocated while the object lives.
    _memory: MemoryBlock,
}

/// The graph's own objects: transient sets, most recently used last, and temporal resources.
#[derive(Default)]
pub(crate) struct GraphObjects {
    /// At most [`KEPT_TRANSIENT_SETS`] per frame slot, least recently used first.
    transients: Vec<TransientSet>,
    /// By the key of the temporal resource ([`ResourceKind::Temporal`]).
    temporal: HashMap<String, TemporalObject>,
}

/// Which transient set a frame uses, as returned by [`GraphObjects::transients_for`].
#[derive(Clone, Copy, Debug)]
pub(crate) struct TransientSetId(usize);

impl GraphObjects {
    /// The transients of `plan` for frame slot `slot` (of `frames_in_flight`), created and bound
    /// into aliased memory on first use.
    pub fn transients_for(
        &mut self,
        device: &Device,
        plan: &Arc<Plan>,
        slot: usize,
        frames_in_flight: usize,
    ) -> Result<TransientSetId, ExecuteError> {
        if let Some(i) = self
            .transients
            .iter()
            .position(|t| t.slot == slot && same_transients(&t.plan, plan))
        {
            // Most recently used last, so eviction takes the least recently used.
            let set = self.transients.remove(i);
            self.transients.push(set);
            return Ok(TransientSetId(self.transients.len() - 1));
        }
        if self.transients.len() >= KEPT_TRANSIENT_SETS * frames_in_flight {
            let old = self.transients.remove(0);
            // The objects go first, then (when `old` drops) the memory they were bound to.
            release(device, old.objects.into_iter().map(|(_, o)| o).collect());
        }
        let heaps = plan
            .memory
            .heaps
            .iter()
            .enumerate()
            .map(|(i, h)| {
                allocate(
                    device,
                    &format!("graph heap {i}"),
                    MemoryNeeds {
                        size: h.size,
                        alignment: h.alignment,
                        type_bits: h.type_bits,
                    },
                    h.class == HeapClass::Buffers,
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut objects = Vec::new();
        for p in &plan.memory.placements {
            let Some(r) = plan.resource(p.resource) else {
                continue;
            };
            let usage = match r.usage {
                Usage::Image(u) => u.as_raw(),
                Usage::Buffer(u) => u.as_raw(),
            };
            match RawObject::create(device, &r.name, &r.desc, usage, &heaps[p.heap], p.offset) {
                Ok(o) => objects.push((p.resource, o)),
                Err(e) => {
                    release(device, objects.into_iter().map(|(_, o)| o).collect());
                    return Err(e.into());
                }
            }
        }
        self.transients.push(TransientSet {
            plan: Arc::clone(plan),
            slot,
            _heaps: heaps,
            objects,
        });
        Ok(TransientSetId(self.transients.len() - 1))
    }

    /// Temporal resources of `plan`, (re)created when new or when their description changed.
    pub fn ensure_temporal(&mut self, device: &Device, plan: &Plan) -> Result<(), ExecuteError> {
        for r in &plan.resources {
            let ResourceKind::Temporal(key) = &r.kind else {
                continue;
            };
            // No declared pass touches it: nothing to create (usage 0 is invalid in Vulkan), and
            // whatever is kept under the key stays.
            let untouched = match r.usage {
                Usage::Image(u) => u.is_empty(),
                Usage::Buffer(u) => u.is_empty(),
            };
            if untouched
                || self
                    .temporal
                    .get(key)
                    .is_some_and(|t| t.desc == r.desc && t.usage == r.usage)
            {
                continue;
            }
            let (usage, needs) = match (r.desc, r.usage) {
                (AnyDesc::Image(d), Usage::Image(u)) => {
                    (u.as_raw(), DeviceMemory(device).image(&d, u))
                }
                (AnyDesc::Buffer(d), Usage::Buffer(u)) => {
                    (u.as_raw(), DeviceMemory(device).buffer(&d, u))
                }
                _ => continue,
            };
            let memory = allocate(device, key, needs, matches!(r.desc, AnyDesc::Buffer(_)))?;
            let object = RawObject::create(device, key, &r.desc, usage, &memory, 0)?;
            let new = TemporalObject {
                desc: r.desc,
                usage: r.usage,
                object,
                _memory: memory,
            };
            if let Some(old) = self.temporal.insert(key.clone(), new) {
                // The object goes first, then (when `old` drops) its memory.
                release(device, vec![old.object]);
            }
        }
        Ok(())
    }

    /// The object behind each resource of `plan` (indexed by resource id) for a frame using the
    /// transient set `set` and the imported objects `externals` (indexed likewise). Fails when a
    /// used import has no object.
    pub fn table(
        &self,
        plan: &Plan,
        set: TransientSetId,
        externals: &[Option<External>],
    ) -> Result<Vec<Option<GpuResource>>, ExecuteError> {
        let mut objects: Vec<Option<GpuResource>> = vec![None; plan.resources.len()];
        for (id, o) in &self.transients[set.0].objects {
            objects[id.0 as usize] = Some(o.0);
        }
        for r in &plan.resources {
            let slot = &mut objects[r.id.0 as usize];
            match &r.kind {
                ResourceKind::Transient => {}
                ResourceKind::Temporal(key) => {
                    *slot = self
                        .temporal
                        .get(key)
                        .filter(|t| t.desc == r.desc && t.usage == r.usage)
                        .map(|t| t.object.0)
                }
                ResourceKind::Imported => {
                    *slot = externals[r.id.0 as usize].map(|e| match e {
                        External::Image { image, view } => GpuResource::Image { image, view },
                        External::Buffer(b) => GpuResource::Buffer(b),
                    });
                    if slot.is_none() && r.used {
                        return Err(ExecuteError::MissingObject(r.name.clone()));
                    }
                }
            }
        }
        Ok(objects)
    }

    /// Bytes of device memory held by the transient sets and by the temporal resources.
    pub fn memory(&self) -> (u64, u64) {
        let transients = self
            .transients
            .iter()
            .flat_map(|t| &t._heaps)
            .map(MemoryBlock::size)
            .sum();
        let temporal = self.temporal.values().map(|t| t._memory.size()).sum();
        (transients, temporal)
    }

    /// Destroys every object, each before the memory it is bound to. The GPU must be done with
    /// all of them.
    pub fn destroy(&mut self, device: &Device) {
        for set in self.transients.drain(..) {
            for (_, o) in set.objects {
                o.destroy(device);
            }
            // The set's memory blocks are freed here, after the objects bound to them.
        }
        for (_, t) in self.temporal.drain() {
            t.object.destroy(device);
        }
    }
}
