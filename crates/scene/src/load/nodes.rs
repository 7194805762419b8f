//! The node hierarchy: local transforms, parent links checked to form a forest, and the
//! roots of the displayed scene.

use glam::{Quat, Vec3};

use super::ctx::Ctx;
use crate::error::Result;
use crate::types::{Node, Transform};

/// All nodes of `doc` with their parents linked, and the roots of the displayed scene (the
/// default scene, else the first, else every parentless node with a warning).
pub(super) fn load_nodes(ctx: &mut Ctx, doc: &gltf::Document) -> Result<(Vec<Node>, Vec<usize>)> {
    let mut nodes = Vec::new();
    for node in doc.nodes() {
        nodes.push(load_node(ctx, &node)?);
    }
    link_parents(ctx, &mut nodes)?;
    check_acyclic(ctx, &nodes)?;
    let roots = scene_roots(ctx, doc, &nodes)?;
    Ok((nodes, roots))
}

/// One node without its parent: name, finite transform with a unit rotation, mesh, skin,
/// finite morph weights and children.
fn load_node(ctx: &mut Ctx, node: &gltf::Node<'_>) -> Result<Node> {
    let name = node
        .name()
        .map_or_else(|| format!("node{}", node.index()), str::to_string);
    let element = format!("nodes[{}] {name:?}", node.index());
    let (t, r, s) = node.transform().decomposed();
    let transform = Transform {
        translation: Vec3::from(t),
        rotation: Quat::from_array(r),
        scale: Vec3::from(s),
    };
    if !(transform.translation.is_finite()
        && transform.rotation.is_finite()
        && transform.scale.is_finite())
    {
        return Err(ctx.invalid(&element, "transform has NaN or infinite values (or a matrix that is not translation·rotation·scale)"));
    }
    let transform = Transform {
        rotation: if transform.rotation.length_squared() > 1e-12 {
            transform.rotation.normalize()
        } else {
            ctx.warn(&element, "rotation is a zero quaternion; identity is used");
            Quat::IDENTITY
        },
        ..transform
    };
    let weights = node.weights().map(<[f32]>::to_vec);
    if weights
        .as_ref()
        .is_some_and(|w| w.iter().any(|x| !x.is_finite()))
    {
        return Err(ctx.invalid(format!("{element} weights"), "has a NaN or infinite weight"));
    }
    Ok(Node {
        name,
        parent: None,
        children: node.children().map(|c| c.index()).collect(),
        transform,
        mesh: node.mesh().map(|m| m.index()),
        camera: None,
        lights: Vec::new(),
        skin: node.skin().map(|s| s.index()),
        weights,
    })
}

/// Sets each node's parent from the children lists, failing on a child that does not
/// exist, a node with two parents, or a node that is its own child.
fn link_parents(ctx: &Ctx, nodes: &mut [Node]) -> Result<()> {
    for i in 0..nodes.len() {
        let children = nodes.get(i).map(|n| n.children.clone()).unwrap_or_default();
        for c in children {
            let Some(child) = nodes.get_mut(c) else {
                return Err(ctx.invalid(
                    format!("nodes[{i}].children"),
                    format!("node {c} does not exist"),
                ));
            };
            if child.parent.is_some() || c == i {
                return Err(ctx.invalid(
                    format!("nodes[{c}] {:?}", child.name),
                    "has more than one parent or is its own ancestor; the node hierarchy must be a forest",
                ));
            }
            child.parent = Some(i);
        }
    }
    Ok(())
}

/// Fails unless every chain of parents ends at a root (no cycles).
fn check_acyclic(ctx: &Ctx, nodes: &[Node]) -> Result<()> {
    for (i, node) in nodes.iter().enumerate() {
        let mut p = node.parent;
        let mut steps = 0;
        while let Some(j) = p {
            steps += 1;
            if steps > nodes.len() {
                return Err(ctx.invalid(
                    format!("nodes[{i}] {:?}", node.name),
                    "is part of a cycle in the node hierarchy",
                ));
            }
            p = nodes.get(j).and_then(|n| n.parent);
        }
    }
    Ok(())
}

/// Roots of the displayed scene: those of the default (else first) glTF scene, which must
/// have no parent; without any scene, every parentless node (with a warning).
fn scene_roots(ctx: &mut Ctx, doc: &gltf::Document, nodes: &[Node]) -> Result<Vec<usize>> {
    match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => {
            let roots: Vec<usize> = scene.nodes().map(|n| n.index()).collect();
            if let Some(&bad) = roots
                .iter()
                .find(|&&r| nodes.get(r).is_some_and(|n| n.parent.is_some()))
            {
                return Err(ctx.invalid(
                    format!("scenes[{}].nodes", scene.index()),
                    format!("node {bad} is listed as a root but has a parent"),
                ));
            }
            Ok(roots)
        }
        None => {
            if !nodes.is_empty() {
                ctx.warn(
                    "scenes",
                    "the file has no scene; every parentless node is shown",
                );
            }
            Ok((0..nodes.len())
                .filter(|&i| nodes.get(i).is_some_and(|n| n.parent.is_none()))
                .collect())
        }
    }
}
