//! The compiler kept across frames: caches plans by graph shape and carries temporal state.

use std::collections::HashMap;
use std::sync::Arc;

use crate::alias::MemoryRequirements;
use crate::compile;
use crate::error::GraphError;
use crate::graph::{RenderGraph, ResourceDecl};
use crate::handle::ResourceId;
use crate::pass::PassDecl;
use crate::plan::Plan;
use crate::resource::{AnyDesc, Lifetime};
use crate::temporal::{TemporalState, TemporalStore};

/// Everything a plan depends on; two graphs with equal shapes get the same plan.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct Shape {
    resources: Vec<ResourceDecl>,
    passes: Vec<PassDecl>,
    pairs: Vec<(ResourceId, ResourceId)>,
    active: Vec<bool>,
    temporal: Vec<Option<TemporalState>>,
}

/// Plans kept at most; periodic passes and history pairs make a few shapes alternate.
const CACHE_CAPACITY: usize = 32;

/// Compiles render graphs, caching the plan while the graph's shape is unchanged, and keeps
/// the state of temporal resources from one frame to the next.
#[derive(Debug, Default)]
pub struct Compiler {
    cache: HashMap<Shape, Arc<Plan>>,
    temporal: TemporalStore,
    compilations: u64,
}

impl Compiler {
    /// A compiler with an empty cache and no temporal history.
    pub fn new() -> Self {
        Self::default()
    }

    fn shape(&self, graph: &RenderGraph) -> Shape {
        Shape {
            resources: graph.resources.clone(),
            passes: graph.passes.clone(),
            pairs: graph.pairs.clone(),
            active: graph
                .passes
                .iter()
                .map(|p| p.rate.runs_on(graph.frame))
                .collect(),
            temporal: graph
                .resources
                .iter()
                .map(|r| match &r.lifetime {
                    Lifetime::Temporal(key) => self.temporal.latest(key).cloned(),
                    _ => None,
                })
                .collect(),
        }
    }

    /// The plan of `graph`: from the cache when a graph of the same shape was compiled before,
    /// compiled otherwise. `memory` answers the memory needs of transients (for aliasing).
    ///
    /// The cache key is the graph's shape only: it assumes `memory` answers alike on every call.
    /// Use one compiler per device (each [`crate::Executor`] has its own); a compiler asked with
    /// another device's requirements would return plans whose memory layout fits the first.
    pub fn compile(
        &mut self,
        graph: &RenderGraph,
        memory: &dyn MemoryRequirements,
    ) -> Result<Arc<Plan>, GraphError> {
        let shape = self.shape(graph);
        if let Some(plan) = self.cache.get(&shape) {
            return Ok(Arc::clone(plan));
        }
        let plan = Arc::new(compile::compile(graph, &self.temporal, memory)?);
        self.compilations += 1;
        if self.cache.len() >= CACHE_CAPACITY {
            self.cache.clear();
        }
        self.cache.insert(shape, Arc::clone(&plan));
        Ok(plan)
    }

    /// Record that `plan` was executed: its temporal resources carry their end state into the
    /// next frame.
    pub fn finish_frame(&mut self, plan: &Plan) {
        self.temporal.commit(&plan.temporal_end);
    }

    /// Whether the temporal resource under `key`, described by `desc`, holds contents that a
    /// pass of an earlier executed frame wrote. False before its first write (a periodic writer
    /// that has not run yet), and after a change of description (a resize), which recreates it
    /// with undefined contents. A change of usage flags (different passes declared on it) also
    /// recreates it; its first frame then reads undefined contents, so keep the passes declared
    /// on a temporal resource the same from frame to frame.
    pub fn has_history(&self, key: &str, desc: impl Into<AnyDesc>) -> bool {
        self.temporal.written(key, &desc.into())
    }

    /// How many graphs were compiled rather than taken from the cache.
    pub fn compilations(&self) -> u64 {
        self.compilations
    }
}
