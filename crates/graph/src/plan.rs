//! The compiled plan of a graph: pass order, barriers, resource usage and memory.

use shine_gpu::vk;

use crate::access::AccessInfo;
use crate::alias::MemoryPlan;
use crate::barrier::Barrier;
use crate::handle::ResourceId;
use crate::pass::{PassCost, PassId, PassKind};
use crate::resource::AnyDesc;
use crate::temporal::TemporalState;

/// Usage flags derived for a resource from its accesses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Usage {
    /// Image usage.
    Image(vk::ImageUsageFlags),
    /// Buffer usage.
    Buffer(vk::BufferUsageFlags),
}

/// Who owns a resource of the plan.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum ResourceKind {
    /// Created by the graph for the frame.
    Transient,
    /// Owned by the caller.
    Imported,
    /// Kept across frames under the key.
    Temporal(String),
}

/// A resource of the plan.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct PlannedResource {
    /// Its id (index in declaration order).
    pub id: ResourceId,
    /// Its name (the key for temporal resources).
    pub name: String,
    /// Who owns it.
    pub kind: ResourceKind,
    /// What it is.
    pub desc: AnyDesc,
    /// Usage flags it must be created with.
    pub usage: Usage,
    /// Whether a pass that runs uses it.
    pub used: bool,
}

/// One resource use of a planned pass, all of the pass's accesses to it merged.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PassResource {
    /// The resource.
    pub resource: ResourceId,
    /// Union of the pass's accesses to it (stage, access, layout, usage).
    pub info: AccessInfo,
}

/// A pass that runs, in execution order.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct PlannedPass {
    /// Its declaration index.
    pub id: PassId,
    /// Its name.
    pub name: String,
    /// What it records.
    pub kind: PassKind,
    /// Barriers recorded just before it, in one `vkCmdPipelineBarrier2`.
    pub barriers: Vec<Barrier>,
    /// The resources it uses.
    pub resources: Vec<PassResource>,
    /// Its declared work, if any.
    pub cost: Option<PassCost>,
}

/// A compiled graph.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Plan {
    /// Passes that run, in order.
    pub passes: Vec<PlannedPass>,
    /// Passes removed because they reach no output.
    pub culled: Vec<String>,
    /// Periodic passes that do not run this frame.
    pub skipped: Vec<String>,
    /// Every declared resource.
    pub resources: Vec<PlannedResource>,
    /// Barriers after the last pass that leave imported resources as the caller asked.
    pub final_barriers: Vec<Barrier>,
    /// Transient memory: heaps, placements and the bytes aliasing saves.
    pub memory: MemoryPlan,
    /// State of each temporal resource at the end of the frame.
    pub(crate) temporal_end: Vec<(String, TemporalState)>,
}

impl Plan {
    /// The planned pass with this name, if it runs.
    pub fn pass(&self, name: &str) -> Option<&PlannedPass> {
        self.passes.iter().find(|p| p.name == name)
    }

    /// Names of the passes that run, in order.
    pub fn order(&self) -> Vec<&str> {
        self.passes.iter().map(|p| p.name.as_str()).collect()
    }

    /// Barriers recorded before the named pass (empty if it does not run).
    pub fn barriers_before(&self, name: &str) -> &[Barrier] {
        self.pass(name).map_or(&[], |p| p.barriers.as_slice())
    }

    /// The resource with this id.
    pub fn resource(&self, id: ResourceId) -> Option<&PlannedResource> {
        self.resources.get(id.0 as usize)
    }
}
