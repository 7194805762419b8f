//! The compiled plan as Graphviz DOT and as JSON: order, barriers, resources and memory.

use std::fmt::Write as _;

use serde_json::{Value, json};

use crate::barrier::Barrier;
use crate::plan::{Plan, PlannedResource, ResourceKind, Usage};
use crate::resource::AnyDesc;

/// A plan written out for people and tools.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PlanDump {
    /// Graphviz DOT: passes as boxes in order, resources as ellipses, reads and writes as edges
    /// (labelled with the barrier before the pass where there is one).
    pub dot: String,
    /// JSON with `passes` (order, barriers, resource uses), `culled`, `skipped`, `resources`,
    /// `final_barriers` and `memory` (heaps, placements, bytes requested/allocated/saved).
    pub json: String,
}

fn desc_words(desc: &AnyDesc) -> String {
    match desc {
        AnyDesc::Image(d) => format!(
            "{:?} {}x{}x{} mips {} layers {}",
            d.format, d.extent.width, d.extent.height, d.extent.depth, d.mips, d.layers
        ),
        AnyDesc::Buffer(d) => format!("{} bytes", d.size),
    }
}

fn usage_words(usage: &Usage) -> String {
    match usage {
        Usage::Image(u) => format!("{u:?}"),
        Usage::Buffer(u) => format!("{u:?}"),
    }
}

fn kind_words(kind: &ResourceKind) -> String {
    match kind {
        ResourceKind::Transient => "transient".into(),
        ResourceKind::Imported => "imported".into(),
        ResourceKind::Temporal(key) => format!("temporal:{key}"),
    }
}

/// Vulkan flags in words; an empty mask reads NONE.
fn flags(mask: impl std::fmt::Debug) -> String {
    let words = format!("{mask:?}");
    if words.is_empty() {
        "NONE".into()
    } else {
        words
    }
}

fn barrier_json(plan: &Plan, b: &Barrier) -> Value {
    json!({
        "resource": b.resource.0,
        "resource_name": plan.resource(b.resource).map(|r| r.name.as_str()),
        "src_stage": flags(b.src.stage),
        "src_access": flags(b.src.access),
        "dst_stage": flags(b.dst.stage),
        "dst_access": flags(b.dst.access),
        "old_layout": format!("{:?}", b.old_layout),
        "new_layout": format!("{:?}", b.new_layout),
    })
}

fn resource_json(r: &PlannedResource) -> Value {
    json!({
        "id": r.id.0,
        "name": r.name,
        "kind": kind_words(&r.kind),
        "desc": desc_words(&r.desc),
        "usage": usage_words(&r.usage),
        "used": r.used,
    })
}

fn escape(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
}

impl Plan {
    /// The plan as JSON.
    pub fn to_json(&self) -> String {
        let passes: Vec<Value> = self
            .passes
            .iter()
            .enumerate()
            .map(|(position, p)| {
                json!({
                    "position": position,
                    "id": p.id.0,
                    "name": p.name,
                    "kind": p.kind,
                    "barriers": p.barriers.iter().map(|b| barrier_json(self, b)).collect::<Vec<_>>(),
                    "resources": p.resources.iter().map(|r| json!({
                        "resource": r.resource.0,
                        "stage": flags(r.info.stage),
                        "access": flags(r.info.access),
                        "layout": format!("{:?}", r.info.layout),
                    })).collect::<Vec<_>>(),
                })
            })
            .collect();
        let doc = json!({
            "passes": passes,
            "culled": self.culled,
            "skipped": self.skipped,
            "resources": self.resources.iter().map(resource_json).collect::<Vec<_>>(),
            "final_barriers": self.final_barriers.iter().map(|b| barrier_json(self, b)).collect::<Vec<_>>(),
            "memory": {
                "heaps": self.memory.heaps,
                "placements": self.memory.placements,
                "requested_bytes": self.memory.requested_bytes,
                "allocated_bytes": self.memory.allocated_bytes,
                "saved_bytes": self.memory.saved_bytes(),
            },
        });
        serde_json::to_string_pretty(&doc).unwrap_or_default()
    }

    /// The plan as Graphviz DOT.
    pub fn to_dot(&self) -> String {
        let mut s =
            String::from("digraph plan {\n  rankdir=LR;\n  node [fontname=\"monospace\"];\n");
        for r in self.resources.iter().filter(|r| r.used) {
            let style = match r.kind {
                ResourceKind::Transient => "dashed",
                ResourceKind::Imported => "bold",
                ResourceKind::Temporal(_) => "filled",
            };
            let memory = self
                .memory
                .placement(r.id)
                .map(|p| format!("\\nheap {} @ {} ({} B)", p.heap, p.offset, p.size))
                .unwrap_or_default();
            let _ = writeln!(
                s,
                "  r{} [shape=ellipse style={style} label=\"{}\\n{}{memory}\"];",
                r.id.0,
                escape(&r.name),
                escape(&desc_words(&r.desc)),
            );
        }
        for (position, p) in self.passes.iter().enumerate() {
            let _ = writeln!(
                s,
                "  p{} [shape=box label=\"{position}: {}\\n{:?}\"];",
                p.id.0,
                escape(&p.name),
                p.kind
            );
            for r in &p.resources {
                let barrier = p
                    .barriers
                    .iter()
                    .find(|b| b.resource == r.resource)
                    .map(|b| {
                        format!(
                            " label=\"{}/{} -> {}/{}\\n{:?} -> {:?}\"",
                            flags(b.src.stage),
                            flags(b.src.access),
                            flags(b.dst.stage),
                            flags(b.dst.access),
                            b.old_layout,
                            b.new_layout
                        )
                    })
                    .unwrap_or_default();
                if r.info.is_write() {
                    let _ = writeln!(
                        s,
                        "  p{} -> r{} [color=red{barrier}];",
                        p.id.0, r.resource.0
                    );
                } else {
                    let _ = writeln!(s, "  r{} -> p{} [{barrier}];", r.resource.0, p.id.0);
                }
            }
        }
        for name in &self.culled {
            let _ = writeln!(
                s,
                "  \"culled: {}\" [shape=box style=dotted color=gray];",
                escape(name)
            );
        }
        s.push_str("}\n");
        s
    }

    /// Both dumps at once.
    pub fn dump(&self) -> PlanDump {
        PlanDump {
            dot: self.to_dot(),
            json: self.to_json(),
        }
    }
}
