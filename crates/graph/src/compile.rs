//! Compilation: validation, culling, ordering, usage derivation, aliasing and barriers.

use std::cmp::Reverse;
use std::collections::{BinaryHeap, HashSet};

use shine_gpu::vk;

use crate::alias::{self, AliasRequest, HeapClass, MemoryRequirements};
use crate::barrier::{Scope, Track};
use crate::error::GraphError;
use crate::graph::{RenderGraph, ResourceDecl};
use crate::handle::ResourceId;
use crate::pass::{Direction, PassDecl, PassId};
use crate::plan::{PassResource, Plan, PlannedPass, PlannedResource, ResourceKind, Usage};
use crate::resource::{AnyDesc, Lifetime};
use crate::temporal::{TemporalState, TemporalStore};

/// Which pass writes each version of each resource.
struct Versions {
    /// `writers[resource][version]`: the pass that writes that version (none for version 0).
    writers: Vec<Vec<Option<usize>>>,
}

impl Versions {
    fn new(graph: &RenderGraph) -> Self {
        let mut writers: Vec<Vec<Option<usize>>> = graph
            .resources
            .iter()
            .map(|r| vec![None; r.latest as usize + 1])
            .collect();
        for (p, pass) in graph.passes.iter().enumerate() {
            for a in pass
                .accesses
                .iter()
                .filter(|a| a.direction == Direction::Write)
            {
                writers[a.resource.0 as usize][a.version as usize + 1] = Some(p);
            }
        }
        Self { writers }
    }

    /// The newest version at or below `version` written by a pass that runs (0 if none): what a
    /// reader of `version` actually sees when periodic writers are skipped.
    fn effective(&self, resource: ResourceId, version: u32, active: &[bool]) -> u32 {
        let w = &self.writers[resource.0 as usize];
        let mut v = version as usize;
        while v > 0 && !w[v].is_some_and(|p| active[p]) {
            v -= 1;
        }
        v as u32
    }

    fn writer(&self, resource: ResourceId, version: u32) -> Option<usize> {
        self.writers[resource.0 as usize][version as usize]
    }

    /// The first running writer after `version`.
    fn next_writer(&self, resource: ResourceId, version: u32, active: &[bool]) -> Option<usize> {
        self.writers[resource.0 as usize][version as usize + 1..]
            .iter()
            .flatten()
            .copied()
            .find(|&p| active[p])
    }
}

fn resource_name(graph: &RenderGraph, id: ResourceId) -> String {
    graph.resources[id.0 as usize].name.clone()
}

/// Checks that need only the declarations.
fn validate(graph: &RenderGraph) -> Result<(), GraphError> {
    if let Some(e) = graph.errors.first() {
        return Err(e.clone());
    }
    for r in &graph.resources {
        if let Some(problem) = r.desc.problem() {
            return Err(GraphError::InvalidDescription {
                resource: r.name.clone(),
                problem,
            });
        }
    }
    let mut names = HashSet::new();
    for pass in &graph.passes {
        if !names.insert(pass.name.as_str()) {
            return Err(GraphError::DuplicatePassName {
                pass: pass.name.clone(),
            });
        }
        if pass.rate.period == 0 {
            return Err(GraphError::ZeroPeriod {
                pass: pass.name.clone(),
            });
        }
        for a in &pass.accesses {
            let Some(res) = graph.resources.get(a.resource.0 as usize) else {
                return Err(GraphError::UnknownResource {
                    resource: a.resource,
                });
            };
            if a.version > res.latest {
                return Err(GraphError::UnknownResource {
                    resource: a.resource,
                });
            }
            let is_image = matches!(res.desc, AnyDesc::Image(_));
            if is_image != matches!(a.access, crate::AnyAccess::Image(_)) {
                return Err(GraphError::KindMismatch {
                    pass: pass.name.clone(),
                    resource: res.name.clone(),
                });
            }
            match a.direction {
                Direction::Read if a.version == 0 && res.lifetime == Lifetime::Transient => {
                    return Err(GraphError::ReadOfUnwritten {
                        pass: pass.name.clone(),
                        resource: res.name.clone(),
                        version: 0,
                    });
                }
                Direction::Write => match &res.lifetime {
                    Lifetime::Imported(i) if i.read_only => {
                        return Err(GraphError::WriteToReadOnly {
                            pass: pass.name.clone(),
                            resource: res.name.clone(),
                        });
                    }
                    Lifetime::Transient if pass.rate.period > 1 => {
                        return Err(GraphError::PeriodicPassWritesTransient {
                            pass: pass.name.clone(),
                            resource: res.name.clone(),
                            period: pass.rate.period,
                        });
                    }
                    _ => {}
                },
                Direction::Read => {}
            }
        }
    }
    Ok(())
}

/// Passes that run and reach an output (a write to an imported or temporal resource).
fn cull(graph: &RenderGraph, versions: &Versions, active: &[bool]) -> Vec<bool> {
    let mut live = vec![false; graph.passes.len()];
    let mut stack: Vec<usize> = graph
        .passes
        .iter()
        .enumerate()
        .filter(|(p, pass)| {
            active[*p]
                && pass.accesses.iter().any(|a| {
                    a.direction == Direction::Write
                        && graph.resources[a.resource.0 as usize].lifetime != Lifetime::Transient
                })
        })
        .map(|(p, _)| p)
        .collect();
    while let Some(p) = stack.pop() {
        if std::mem::replace(&mut live[p], true) {
            continue;
        }
        for a in &graph.passes[p].accesses {
            let v = versions.effective(a.resource, a.version, active);
            if let Some(w) = versions
                .writer(a.resource, v)
                .filter(|&w| w != p && !live[w])
            {
                stack.push(w);
            }
        }
    }
    live
}

/// Live passes in declaration order, except where a dependency needs a later pass first.
fn order(
    graph: &RenderGraph,
    versions: &Versions,
    active: &[bool],
    live: &[bool],
) -> Result<Vec<usize>, GraphError> {
    let n = graph.passes.len();
    let mut successors: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut indegree = vec![0usize; n];
    let mut edge = |from: usize, to: usize| {
        if from != to && live[from] && live[to] && !successors[from].contains(&to) {
            successors[from].push(to);
            indegree[to] += 1;
        }
    };
    for p in (0..n).filter(|&p| live[p]) {
        for a in &graph.passes[p].accesses {
            let v = versions.effective(a.resource, a.version, active);
            if let Some(w) = versions.writer(a.resource, v) {
                edge(w, p);
            }
            if a.direction == Direction::Read
                && let Some(w) = versions.next_writer(a.resource, v, active)
            {
                edge(p, w);
            }
        }
    }
    let mut ready: BinaryHeap<Reverse<usize>> = (0..n)
        .filter(|&p| live[p] && indegree[p] == 0)
        .map(Reverse)
        .collect();
    let mut out = Vec::new();
    while let Some(Reverse(p)) = ready.pop() {
        out.push(p);
        for &s in &successors[p] {
            indegree[s] -= 1;
            if indegree[s] == 0 {
                ready.push(Reverse(s));
            }
        }
    }
    let total = live.iter().filter(|&&l| l).count();
    if out.len() < total {
        let passes = (0..n)
            .filter(|&p| live[p] && indegree[p] > 0)
            .map(|p| graph.passes[p].name.clone())
            .collect();
        return Err(GraphError::Cycle { passes });
    }
    Ok(out)
}

/// The one layout that serves two uses of an image in the same pass, if there is one: their
/// common layout, or DEPTH_STENCIL_READ_ONLY_OPTIMAL for a depth attachment that is only tested
/// while shaders sample it (both uses read-only).
fn shared_layout(first: vk::ImageLayout, second: vk::ImageLayout) -> Option<vk::ImageLayout> {
    use vk::ImageLayout as L;
    match (first, second) {
        _ if first == second => Some(first),
        (L::DEPTH_STENCIL_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL)
        | (L::SHADER_READ_ONLY_OPTIMAL, L::DEPTH_STENCIL_READ_ONLY_OPTIMAL) => {
            Some(L::DEPTH_STENCIL_READ_ONLY_OPTIMAL)
        }
        _ => None,
    }
}

/// The pass's accesses merged per resource, in first-use order.
fn merge(graph: &RenderGraph, pass: &PassDecl) -> Result<Vec<PassResource>, GraphError> {
    let mut out: Vec<PassResource> = Vec::new();
    for a in &pass.accesses {
        let info = a.access.info();
        match out.iter_mut().find(|r| r.resource == a.resource) {
            None => out.push(PassResource {
                resource: a.resource,
                info,
            }),
            Some(r) => {
                let Some(layout) = shared_layout(r.info.layout, info.layout) else {
                    return Err(GraphError::LayoutConflict {
                        pass: pass.name.clone(),
                        resource: resource_name(graph, a.resource),
                        first: format!("{:?}", r.info.layout),
                        second: format!("{:?}", info.layout),
                    });
                };
                r.info.layout = layout;
                r.info.stage |= info.stage;
                r.info.access |= info.access;
                r.info.usage |= info.usage;
            }
        }
    }
    Ok(out)
}

fn usage_words(desc: &AnyDesc, bits: u32) -> String {
    match desc {
        AnyDesc::Image(_) => format!("{:?}", vk::ImageUsageFlags::from_raw(bits)),
        AnyDesc::Buffer(_) => format!("{:?}", vk::BufferUsageFlags::from_raw(bits)),
    }
}

/// Usage bits per resource: from the running passes, and for temporal resources from every
/// declared pass (both halves of a history pair alike) so the resource is not recreated on
/// frames where a periodic pass skips or the pair swaps.
fn derive_usage(
    graph: &RenderGraph,
    merged: &[(usize, Vec<PassResource>)],
) -> Result<Vec<u32>, GraphError> {
    let mut usage = vec![0u32; graph.resources.len()];
    for (p, resources) in merged {
        for r in resources {
            let decl = &graph.resources[r.resource.0 as usize];
            if let Lifetime::Imported(import) = &decl.lifetime
                && r.info.usage & !import.usage != 0
            {
                return Err(GraphError::UsageMismatch {
                    pass: graph.passes[*p].name.clone(),
                    resource: decl.name.clone(),
                    access: format!("{:?} / {:?}", r.info.stage, r.info.access),
                    needed: usage_words(&decl.desc, r.info.usage),
                    available: usage_words(&decl.desc, import.usage),
                });
            }
            usage[r.resource.0 as usize] |= r.info.usage;
        }
    }
    for pass in &graph.passes {
        for a in &pass.accesses {
            if let Lifetime::Temporal(_) = graph.resources[a.resource.0 as usize].lifetime {
                usage[a.resource.0 as usize] |= a.access.info().usage;
            }
        }
    }
    for &(a, b) in &graph.pairs {
        let both = usage[a.0 as usize] | usage[b.0 as usize];
        usage[a.0 as usize] = both;
        usage[b.0 as usize] = both;
    }
    for (decl, u) in graph.resources.iter().zip(usage.iter_mut()) {
        if let Lifetime::Imported(import) = &decl.lifetime {
            *u = import.usage;
        }
    }
    Ok(usage)
}

fn plan_memory(
    graph: &RenderGraph,
    merged: &[(usize, Vec<PassResource>)],
    usage: &[u32],
    memory: &dyn MemoryRequirements,
) -> alias::MemoryPlan {
    let mut lifetimes: Vec<Option<(usize, usize)>> = vec![None; graph.resources.len()];
    for (pos, (_, resources)) in merged.iter().enumerate() {
        for r in resources {
            let l = &mut lifetimes[r.resource.0 as usize];
            *l = Some(l.map_or((pos, pos), |(first, _)| (first, pos)));
        }
    }
    let requests: Vec<AliasRequest> = graph
        .resources
        .iter()
        .enumerate()
        .filter(|(_, decl)| decl.lifetime == Lifetime::Transient)
        .filter_map(|(i, decl)| {
            let lifetime = lifetimes[i]?;
            let (class, needs) = match &decl.desc {
                AnyDesc::Image(d) => (
                    HeapClass::Images,
                    memory.image(d, vk::ImageUsageFlags::from_raw(usage[i])),
                ),
                AnyDesc::Buffer(d) => (
                    HeapClass::Buffers,
                    memory.buffer(d, vk::BufferUsageFlags::from_raw(usage[i])),
                ),
            };
            Some(AliasRequest {
                resource: ResourceId(i as u32),
                class,
                needs,
                lifetime,
            })
        })
        .collect();
    alias::plan(&requests)
}

/// The state a resource is in when the frame first touches it.
fn initial_track(decl: &ResourceDecl, usage: u32, temporal: &TemporalStore) -> Track {
    match &decl.lifetime {
        Lifetime::Transient => Track::fresh(),
        Lifetime::Imported(i) => Track::from_external(i.initial),
        Lifetime::Temporal(key) => temporal
            .get(key, &decl.desc, usage)
            .map_or_else(Track::fresh, |s| s.track.clone()),
    }
}

/// The state of a resource at its first use in the frame. A transient placed in memory that
/// earlier transients used must also wait for their last uses.
fn first_track(
    graph: &RenderGraph,
    id: ResourceId,
    usage: u32,
    temporal: &TemporalStore,
    memory: &alias::MemoryPlan,
    tracks: &[Option<Track>],
) -> Track {
    let mut track = initial_track(&graph.resources[id.0 as usize], usage, temporal);
    if let Some(me) = memory.placement(id) {
        for prev in memory
            .placements
            .iter()
            .filter(|q| q.overlaps_memory(me) && q.lifetime.1 < me.lifetime.0)
        {
            let src = tracks[prev.resource.0 as usize]
                .as_ref()
                .map_or(Scope::NONE, Track::hazard_source);
            track.write.stage |= src.stage;
            track.write.access |= src.access;
        }
    }
    track
}

/// Compile a graph against the temporal states of earlier frames.
pub(crate) fn compile(
    graph: &RenderGraph,
    temporal: &TemporalStore,
    memory: &dyn MemoryRequirements,
) -> Result<Plan, GraphError> {
    validate(graph)?;
    let active: Vec<bool> = graph
        .passes
        .iter()
        .map(|p| p.rate.runs_on(graph.frame))
        .collect();
    let versions = Versions::new(graph);
    let live = cull(graph, &versions, &active);
    let order = order(graph, &versions, &active, &live)?;
    let merged = order
        .iter()
        .map(|&p| Ok((p, merge(graph, &graph.passes[p])?)))
        .collect::<Result<Vec<_>, GraphError>>()?;
    let usage = derive_usage(graph, &merged)?;
    let memory_plan = plan_memory(graph, &merged, &usage, memory);

    let is_image =
        |id: ResourceId| matches!(graph.resources[id.0 as usize].desc, AnyDesc::Image(_));
    let mut tracks: Vec<Option<Track>> = vec![None; graph.resources.len()];
    let mut passes = Vec::with_capacity(merged.len());
    for (p, resources) in &merged {
        let mut barriers = Vec::new();
        for r in resources {
            let i = r.resource.0 as usize;
            let mut track = match tracks[i].take() {
                Some(t) => t,
                None => first_track(graph, r.resource, usage[i], temporal, &memory_plan, &tracks),
            };
            barriers.extend(track.access(r.resource, is_image(r.resource), &r.info));
            tracks[i] = Some(track);
        }
        let decl = &graph.passes[*p];
        passes.push(PlannedPass {
            id: PassId(*p as u32),
            name: decl.name.clone(),
            kind: decl.kind,
            barriers,
            resources: resources.clone(),
            cost: decl.cost,
        });
    }

    let mut final_barriers = Vec::new();
    let mut temporal_end = Vec::new();
    let mut resources = Vec::with_capacity(graph.resources.len());
    for (i, decl) in graph.resources.iter().enumerate() {
        let id = ResourceId(i as u32);
        let used = tracks[i].is_some();
        let end = tracks[i]
            .clone()
            .unwrap_or_else(|| initial_track(decl, usage[i], temporal));
        let kind = match &decl.lifetime {
            Lifetime::Transient => ResourceKind::Transient,
            Lifetime::Imported(import) => {
                final_barriers.extend(end.release(id, is_image(id), import.final_state));
                ResourceKind::Imported
            }
            Lifetime::Temporal(key) => {
                // A temporal no declared pass touches has no usage and is not created; what is
                // kept under its key stays as it was.
                if usage[i] != 0 {
                    let before = temporal
                        .get(key, &decl.desc, usage[i])
                        .is_some_and(|s| s.written);
                    let now = merged
                        .iter()
                        .flat_map(|(_, rs)| rs)
                        .any(|r| r.resource == id && r.info.is_write());
                    temporal_end.push((
                        key.clone(),
                        TemporalState {
                            desc: decl.desc,
                            usage: usage[i],
                            track: end.next_frame(),
                            written: before || now,
                        },
                    ));
                }
                ResourceKind::Temporal(key.clone())
            }
        };
        resources.push(PlannedResource {
            id,
            name: decl.name.clone(),
            kind,
            desc: decl.desc,
            usage: match decl.desc {
                AnyDesc::Image(_) => Usage::Image(vk::ImageUsageFlags::from_raw(usage[i])),
                AnyDesc::Buffer(_) => Usage::Buffer(vk::BufferUsageFlags::from_raw(usage[i])),
            },
            used,
        });
    }

    let names = |pred: &dyn Fn(usize) -> bool| {
        (0..graph.passes.len())
            .filter(|&p| pred(p))
            .map(|p| graph.passes[p].name.clone())
            .collect()
    };
    Ok(Plan {
        passes,
        culled: names(&|p| active[p] && !live[p]),
        skipped: names(&|p| !active[p]),
        resources,
        final_barriers,
        memory: memory_plan,
        temporal_end,
    })
}
