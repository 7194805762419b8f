//! The scene: the plain data of [`crate::types`] gathered into flat arrays ready to upload,
//! and what is computed from the whole of it (world matrices, instances, bounds, animated
//! transforms, proxies in world space).

use glam::{Mat4, Vec3};

use crate::animation::Animation;
use crate::environment::Environment;
use crate::proxies::{NodeProxies, ProxySphere};
use crate::types::{
    Aabb, Camera, Instance, Light, Material, Mesh, NO_SKIN, Node, Primitive, Skin, Texture,
    Transform,
};

/// A loaded scene.
#[derive(Clone, Debug, Default)]
pub struct Scene {
    /// Where the scene came from (file path or built-in name), used in messages.
    pub source: String,
    /// All nodes of the glTF scene, in file order (nodes not in the displayed scene are kept
    /// but have no instance).
    pub nodes: Vec<Node>,
    /// Root nodes of the displayed scene.
    pub roots: Vec<usize>,
    /// Meshes.
    pub meshes: Vec<Mesh>,
    /// Skins, referred to by [`Node::skin`] and [`Instance::skin`].
    pub skins: Vec<Skin>,
    /// Materials; the last one is the glTF default material when a primitive has none.
    pub materials: Vec<Material>,
    /// Material names, parallel to `materials`.
    pub material_names: Vec<String>,
    /// Decoded textures.
    pub textures: Vec<Texture>,
    /// Lights in world space at rest. Never empty when the scene has no environment: a default
    /// sun is added (see [`crate::load()`]).
    pub lights: Vec<Light>,
    /// Cameras; never empty (a default camera framing the scene is added when needed). The
    /// first one is the one to render with.
    pub cameras: Vec<Camera>,
    /// Animations.
    pub animations: Vec<Animation>,
    /// Environment lighting described in the root `extras` (`shine_environment`).
    pub environment: Option<Environment>,
    /// Proxy spheres of the dynamic (animated) nodes and of nodes with explicit proxies.
    pub proxies: Vec<NodeProxies>,
    /// Warnings collected while loading (`"<file>: <element>: <message>"`).
    pub warnings: Vec<String>,
}

impl Scene {
    /// World matrices of all nodes at rest (no animation).
    pub fn rest_world_transforms(&self) -> Vec<Mat4> {
        let locals: Vec<Mat4> = self.nodes.iter().map(|n| n.transform.matrix()).collect();
        self.world_from_locals(&locals)
    }

    /// World matrices from local matrices, one per node. Nodes outside the displayed scene get
    /// the identity; a node reached twice (only possible in a hand-built, cyclic `Scene`) is
    /// visited once.
    pub fn world_from_locals(&self, locals: &[Mat4]) -> Vec<Mat4> {
        let mut world = vec![Mat4::IDENTITY; self.nodes.len()];
        let mut stack: Vec<(usize, Mat4)> =
            self.roots.iter().map(|&r| (r, Mat4::IDENTITY)).collect();
        let mut visited = vec![false; self.nodes.len()];
        while let Some((n, parent)) = stack.pop() {
            match visited.get_mut(n) {
                Some(v) if !*v => *v = true,
                _ => continue,
            }
            let (Some(node), Some(local)) = (self.nodes.get(n), locals.get(n)) else {
                continue;
            };
            let w = parent * *local;
            if let Some(slot) = world.get_mut(n) {
                *slot = w;
            }
            stack.extend(node.children.iter().map(|&c| (c, w)));
        }
        world
    }

    /// For each node, whether it is in the displayed scene (reachable from [`Scene::roots`]).
    /// Lights, cameras and proxies of other nodes are not loaded.
    pub fn shown_nodes(&self) -> Vec<bool> {
        let mut shown = vec![false; self.nodes.len()];
        let mut stack = self.roots.clone();
        while let Some(n) = stack.pop() {
            match shown.get_mut(n) {
                Some(s) if !*s => *s = true,
                _ => continue,
            }
            if let Some(node) = self.nodes.get(n) {
                stack.extend(&node.children);
            }
        }
        shown
    }

    /// Instances (one per node with a mesh in the displayed scene) for the given world
    /// matrices, in depth-first order of the scene (roots and children in file order).
    ///
    /// A node with a skin gives a skinned instance: `skin` set and `world` the identity, as
    /// the joints alone place its vertices (glTF 2.0 §3.7.3).
    pub fn instances(&self, world: &[Mat4]) -> Vec<Instance> {
        let mut out = Vec::new();
        let mut visited = vec![false; self.nodes.len()];
        let mut stack: Vec<usize> = self.roots.iter().rev().copied().collect();
        while let Some(n) = stack.pop() {
            match visited.get_mut(n) {
                Some(v) if !*v => *v = true,
                _ => continue,
            }
            let Some(node) = self.nodes.get(n) else {
                continue;
            };
            if let (Some(mesh), Some(w)) = (node.mesh, world.get(n)) {
                let skin = node.skin.filter(|&s| s < self.skins.len());
                out.push(Instance {
                    world: if skin.is_some() { Mat4::IDENTITY } else { *w }.to_cols_array_2d(),
                    mesh: mesh as u32,
                    node: n as u32,
                    skin: skin.map_or(NO_SKIN, |s| s as u32),
                    _pad: 0,
                });
            }
            stack.extend(node.children.iter().rev().copied());
        }
        out
    }

    /// World-space bounds of all instances for the given world matrices, morph targets at
    /// their rest weights ([`Scene::pose_bounds`] for any pose).
    pub fn bounds(&self, world: &[Mat4]) -> Aabb {
        self.pose_bounds(&self.pose(world.to_vec(), self.rest_weights()))
    }

    /// Total number of triangles over all instances.
    pub fn triangle_count(&self) -> usize {
        self.instances(&self.rest_world_transforms())
            .iter()
            .filter_map(|i| self.meshes.get(i.mesh as usize))
            .map(|m| {
                m.primitives
                    .iter()
                    .map(Primitive::triangle_count)
                    .sum::<usize>()
            })
            .sum()
    }

    /// Lights moved to the given world matrices (lights on animated nodes follow them).
    pub fn lights_at(&self, world: &[Mat4]) -> Vec<Light> {
        self.lights
            .iter()
            .map(|l| {
                let mut l = *l;
                if let Some(w) = world.get(l.node as usize) {
                    l.position = w.transform_point3(Vec3::ZERO).to_array();
                    l.direction = w
                        .transform_vector3(Vec3::NEG_Z)
                        .normalize_or(Vec3::NEG_Z)
                        .to_array();
                }
                l
            })
            .collect()
    }

    /// Camera-to-world matrix of camera `index` for the given world matrices.
    pub fn camera_world(&self, index: usize, world: &[Mat4]) -> Option<Mat4> {
        let cam = self.cameras.get(index)?;
        Some(
            cam.node
                .and_then(|n| world.get(n).copied())
                .unwrap_or(cam.world),
        )
    }

    /// Local transforms of all nodes at time `t` with every animation applied (later
    /// animations win where two drive the same property).
    pub fn local_transforms_at(&self, t: f32) -> Vec<Transform> {
        let mut locals: Vec<Transform> = self.nodes.iter().map(|n| n.transform).collect();
        for a in &self.animations {
            a.apply(t, &mut locals);
        }
        locals
    }

    /// World matrices of all nodes at time `t` with every animation applied.
    pub fn world_transforms_at(&self, t: f32) -> Vec<Mat4> {
        let locals: Vec<Mat4> = self
            .local_transforms_at(t)
            .iter()
            .map(Transform::matrix)
            .collect();
        self.world_from_locals(&locals)
    }

    /// Whether `node` or one of its ancestors is driven by an animation.
    pub fn is_animated(&self, node: usize) -> bool {
        let mut n = Some(node);
        let mut steps = 0;
        while let Some(i) = n {
            if self.animations.iter().any(|a| a.targets(i)) {
                return true;
            }
            n = self.nodes.get(i).and_then(|x| x.parent);
            steps += 1;
            if steps > self.nodes.len() {
                break;
            }
        }
        false
    }

    /// All proxy spheres in world space for the given world matrices (e.g. from
    /// [`Scene::world_transforms_at`]). Radii scale by the node's largest axis scale.
    pub fn proxies_at(&self, world: &[Mat4]) -> Vec<ProxySphere> {
        let mut out = Vec::new();
        for p in &self.proxies {
            let Some(w) = world.get(p.node) else { continue };
            out.extend(p.spheres.iter().map(|s| s.transformed(w)));
        }
        out
    }
}
