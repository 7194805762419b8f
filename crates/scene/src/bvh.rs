//! A bounding volume hierarchy over all triangles of a scene, in world space.
//!
//! Built top-down with the binned surface area heuristic (16 bins per axis, all three axes),
//! flattened depth-first for GPU traversal: an interior node's left child is the next node
//! and its right child is `left_or_first`; a leaf (`count > 0`) holds triangles
//! `left_or_first .. left_or_first + count` of [`Bvh::triangles`], which are stored in leaf
//! order with their world-space vertices. [`Bvh::refit`] moves the triangles of instances
//! whose world matrix changed (animation) and recomputes all bounds bottom-up without
//! changing the topology.

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Vec3};

use crate::scene::Scene;
use crate::types::{Aabb, Instance};

const BINS: usize = 16;
const MAX_LEAF: usize = 8;
/// Cost of a traversal step (a node's two box tests) relative to a ray-triangle test, in SAH
/// units. 2.5, not 1: on lavapipe a step of the traversal loop (boxes, ordering, the stack in
/// memory) costs more than a triangle of a leaf's inner loop, and the larger leaves this
/// gives made the path tracer 4–25% faster (median 13%, four alternating runs of
/// cornell-box 128², 48 spp; docs/performance.md). 4 did no better.
const TRAVERSAL_COST: f32 = 2.5;

/// A flattened BVH node, laid out for a GPU buffer (32 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    /// Box minimum.
    pub min: [f32; 3],
    /// Interior: index of the right child (the left child is this node + 1).
    /// Leaf: index of the first triangle.
    pub left_or_first: u32,
    /// Box maximum.
    pub max: [f32; 3],
    /// Number of triangles; 0 for an interior node.
    pub count: u32,
}

impl BvhNode {
    fn aabb(&self) -> Aabb {
        Aabb {
            min: Vec3::from(self.min),
            max: Vec3::from(self.max),
        }
    }

    fn set_aabb(&mut self, b: &Aabb) {
        self.min = b.min.to_array();
        self.max = b.max.to_array();
    }
}

/// A world-space triangle with where it came from, laid out for a GPU buffer (48 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct BvhTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// Index into the instance list the BVH was built from ([`Bvh::instances`]).
    pub instance: u32,
    /// Second vertex.
    pub v1: [f32; 3],
    /// Primitive index within the instance's mesh.
    pub primitive: u32,
    /// Third vertex.
    pub v2: [f32; 3],
    /// Triangle index within the primitive.
    pub triangle: u32,
}

impl BvhTriangle {
    fn vertices(&self) -> [Vec3; 3] {
        [
            Vec3::from(self.v0),
            Vec3::from(self.v1),
            Vec3::from(self.v2),
        ]
    }

    fn aabb(&self) -> Aabb {
        let [a, b, c] = self.vertices();
        Aabb {
            min: a.min(b).min(c),
            max: a.max(b).max(c),
        }
    }
}

/// A ray `origin + t * dir` for `t` in `[t_min, t_max]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Direction (need not be unit; `t` is in its units).
    pub dir: Vec3,
    /// Smallest accepted `t`.
    pub t_min: f32,
    /// Largest accepted `t`.
    pub t_max: f32,
}

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Barycentric coordinate of `v1`.
    pub u: f32,
    /// Barycentric coordinate of `v2`.
    pub v: f32,
    /// Index into [`Bvh::triangles`].
    pub triangle: usize,
}

/// Möller–Trumbore ray-triangle intersection (both faces); `(t, u, v)` within the ray's range.
pub fn intersect_triangle(ray: &Ray, [a, b, c]: [Vec3; 3]) -> Option<(f32, f32, f32)> {
    let e1 = b - a;
    let e2 = c - a;
    let p = ray.dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = ray.origin - a;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = ray.dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t >= ray.t_min && t <= ray.t_max).then_some((t, u, v))
}

fn ray_box(origin: Vec3, inv_dir: Vec3, t_min: f32, t_max: f32, node: &BvhNode) -> Option<f32> {
    let t0 = (Vec3::from(node.min) - origin) * inv_dir;
    let t1 = (Vec3::from(node.max) - origin) * inv_dir;
    let near = t0.min(t1).max_element().max(t_min);
    let far = t0.max(t1).min_element().min(t_max);
    (near <= far).then_some(near)
}

/// The hierarchy, its triangles in leaf order, and the instances they came from.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bvh {
    /// Nodes, root first, depth-first order.
    pub nodes: Vec<BvhNode>,
    /// World-space triangles in leaf order.
    pub triangles: Vec<BvhTriangle>,
    /// The instances the triangles were taken from, with the world matrices last used.
    pub instances: Vec<Instance>,
}

/// World-space triangles of one instance.
fn instance_triangles(scene: &Scene, index: u32, inst: &Instance, out: &mut Vec<BvhTriangle>) {
    let Some(mesh) = scene.meshes.get(inst.mesh as usize) else {
        return;
    };
    let m = Mat4::from_cols_array_2d(&inst.world);
    for (pi, prim) in mesh.primitives.iter().enumerate() {
        let world: Vec<Vec3> = prim
            .positions
            .iter()
            .map(|p| m.transform_point3(*p))
            .collect();
        for (ti, t) in prim.indices.chunks_exact(3).enumerate() {
            let get = |i: u32| {
                world
                    .get(i as usize)
                    .copied()
                    .unwrap_or_default()
                    .to_array()
            };
            out.push(BvhTriangle {
                v0: get(t[0]),
                instance: index,
                v1: get(t[1]),
                primitive: pi as u32,
                v2: get(t[2]),
                triangle: ti as u32,
            });
        }
    }
}

impl Bvh {
    /// Builds the BVH over every instance of `scene` placed with `world` (one matrix per node,
    /// e.g. [`Scene::rest_world_transforms`] or [`Scene::world_transforms_at`]).
    pub fn from_scene(scene: &Scene, world: &[Mat4]) -> Bvh {
        let instances = scene.instances(world);
        let mut tris = Vec::new();
        for (i, inst) in instances.iter().enumerate() {
            instance_triangles(scene, i as u32, inst, &mut tris);
        }
        let mut bvh = Bvh::build(tris);
        bvh.instances = instances;
        bvh
    }

    /// Builds the BVH over a triangle soup.
    pub fn build(triangles: Vec<BvhTriangle>) -> Bvh {
        let n = triangles.len();
        if n == 0 {
            return Bvh::default();
        }
        // Triangles as contiguous items, partitioned in place: no indirection while binning.
        let mut items: Vec<Item> = triangles
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let bounds = t.aabb();
                Item {
                    bounds,
                    centroid: bounds.center(),
                    index: i as u32,
                }
            })
            .collect();
        let nodes = build_items(&mut items);
        let triangles = items
            .iter()
            .filter_map(|item| triangles.get(item.index as usize).copied())
            .collect();
        Bvh {
            nodes,
            triangles,
            instances: Vec::new(),
        }
    }

    /// Moves the triangles of every instance whose world matrix differs from the one in
    /// [`Bvh::instances`] to `world`, then recomputes all node bounds bottom-up. The topology
    /// is kept: quality degrades with large motion; rebuild then.
    pub fn refit(&mut self, scene: &Scene, world: &[Mat4]) {
        let mut moved = vec![false; self.instances.len()];
        for (inst, m) in self.instances.iter_mut().zip(moved.iter_mut()) {
            if let Some(w) = world.get(inst.node as usize) {
                let w = w.to_cols_array_2d();
                if w != inst.world {
                    inst.world = w;
                    *m = true;
                }
            }
        }
        if !moved.contains(&true) {
            return;
        }
        let mut cache: Vec<Option<Vec<Vec<Vec3>>>> = vec![None; self.instances.len()];
        for tri in &mut self.triangles {
            let i = tri.instance as usize;
            if !moved.get(i).copied().unwrap_or(false) {
                continue;
            }
            let (Some(inst), Some(slot)) = (self.instances.get(i), cache.get_mut(i)) else {
                continue;
            };
            let prims = slot.get_or_insert_with(|| {
                let m = Mat4::from_cols_array_2d(&inst.world);
                scene
                    .meshes
                    .get(inst.mesh as usize)
                    .map(|mesh| {
                        mesh.primitives
                            .iter()
                            .map(|p| p.positions.iter().map(|v| m.transform_point3(*v)).collect())
                            .collect()
                    })
                    .unwrap_or_default()
            });
            let Some(prim) = scene
                .meshes
                .get(inst.mesh as usize)
                .and_then(|m| m.primitives.get(tri.primitive as usize))
            else {
                continue;
            };
            let Some(world_pos) = prims.get(tri.primitive as usize) else {
                continue;
            };
            let base = tri.triangle as usize * 3;
            let get = |k: usize| {
                prim.indices
                    .get(base + k)
                    .and_then(|&i| world_pos.get(i as usize))
                    .copied()
                    .unwrap_or_default()
                    .to_array()
            };
            tri.v0 = get(0);
            tri.v1 = get(1);
            tri.v2 = get(2);
        }
        self.refit_bounds();
    }

    /// Recomputes every node's box from its triangles or children (children come after their
    /// parent in depth-first order, so a reverse sweep sees them first).
    pub fn refit_bounds(&mut self) {
        for i in (0..self.nodes.len()).rev() {
            let Some(node) = self.nodes.get(i).copied() else {
                continue;
            };
            let b = if node.count > 0 {
                let first = node.left_or_first as usize;
                self.triangles
                    .get(first..first + node.count as usize)
                    .unwrap_or_default()
                    .iter()
                    .fold(Aabb::EMPTY, |b, t| b.union(&t.aabb()))
            } else {
                let l = self
                    .nodes
                    .get(i + 1)
                    .map(BvhNode::aabb)
                    .unwrap_or(Aabb::EMPTY);
                let r = self
                    .nodes
                    .get(node.left_or_first as usize)
                    .map(BvhNode::aabb)
                    .unwrap_or(Aabb::EMPTY);
                l.union(&r)
            };
            if let Some(n) = self.nodes.get_mut(i) {
                n.set_aabb(&b);
            }
        }
    }

    /// The closest hit along `ray`, if any.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let inv = Vec3::ONE / ray.dir;
        let mut best: Option<Hit> = None;
        let mut t_max = ray.t_max;
        let mut stack: Vec<u32> = Vec::with_capacity(64);
        if let Some(root) = self.nodes.first()
            && ray_box(ray.origin, inv, ray.t_min, t_max, root).is_some()
        {
            stack.push(0);
        }
        while let Some(i) = stack.pop() {
            let Some(node) = self.nodes.get(i as usize) else {
                continue;
            };
            if node.count > 0 {
                let first = node.left_or_first as usize;
                for (k, tri) in self
                    .triangles
                    .get(first..first + node.count as usize)
                    .unwrap_or_default()
                    .iter()
                    .enumerate()
                {
                    let r = Ray { t_max, ..*ray };
                    if let Some((t, u, v)) = intersect_triangle(&r, tri.vertices()) {
                        t_max = t;
                        best = Some(Hit {
                            t,
                            u,
                            v,
                            triangle: first + k,
                        });
                    }
                }
                continue;
            }
            let (l, r) = (i + 1, node.left_or_first);
            let hit = |c: u32| {
                self.nodes
                    .get(c as usize)
                    .and_then(|n| ray_box(ray.origin, inv, ray.t_min, t_max, n))
            };
            match (hit(l), hit(r)) {
                (Some(tl), Some(tr)) => {
                    // Visit the nearer child first.
                    if tl <= tr {
                        stack.extend([r, l]);
                    } else {
                        stack.extend([l, r]);
                    }
                }
                (Some(_), None) => stack.push(l),
                (None, Some(_)) => stack.push(r),
                (None, None) => {}
            }
        }
        best
    }

    /// Depth of the tree (1 for a single leaf, 0 when empty).
    pub fn depth(&self) -> usize {
        let mut max = 0;
        let mut stack = if self.nodes.is_empty() {
            vec![]
        } else {
            vec![(0usize, 1usize)]
        };
        while let Some((i, d)) = stack.pop() {
            max = max.max(d);
            if let Some(n) = self.nodes.get(i)
                && n.count == 0
            {
                stack.push((i + 1, d + 1));
                stack.push((n.left_or_first as usize, d + 1));
            }
        }
        max
    }
}

/// A binned-SAH hierarchy over boxes (e.g. the world bounds of instances, for a two-level
/// BVH's top level): the nodes, whose leaves index `order`, and `order`, the box indices in
/// leaf order. Empty for no boxes.
pub fn build_over_boxes(boxes: &[Aabb]) -> (Vec<BvhNode>, Vec<u32>) {
    let mut items: Vec<Item> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| Item {
            bounds: *b,
            centroid: b.center(),
            index: i as u32,
        })
        .collect();
    if items.is_empty() {
        return (Vec::new(), Vec::new());
    }
    let nodes = build_items(&mut items);
    (nodes, items.iter().map(|item| item.index).collect())
}

/// Builds the nodes over `items` (non-empty), on as many threads as the machine has when
/// there are enough items to share (asking the OS costs tens of microseconds: more than a
/// top level over tens of instances takes to build, every frame).
fn build_items(items: &mut [Item]) -> Vec<BvhNode> {
    let threads = if items.len() >= PARALLEL_MIN {
        std::thread::available_parallelism().map_or(1, |t| t.get())
    } else {
        1
    };
    build_subtree(items, 0, threads)
}

/// Subtrees smaller than this are not worth a thread.
const PARALLEL_MIN: usize = 32 * 1024;

/// Bounds of `items` and, when it should be split, where (relative to `items`) after
/// partitioning them. The node's `left_or_first`/`count` describe a leaf of `items` starting
/// at triangle `base`.
fn split_node(items: &mut [Item], base: usize) -> (BvhNode, Option<usize>) {
    let mut bounds = Aabb::EMPTY;
    let mut cbounds = Aabb::EMPTY;
    for item in items.iter() {
        bounds = bounds.union(&item.bounds);
        cbounds.grow(item.centroid);
    }
    let mut node = BvhNode {
        min: [0.0; 3],
        left_or_first: base as u32,
        max: [0.0; 3],
        count: items.len() as u32,
    };
    node.set_aabb(&bounds);
    let split = if items.len() <= 2 {
        None
    } else {
        sah_split(items, &cbounds, bounds.area())
    };
    let partitioned = split.and_then(|(axis, pos)| {
        let mut left = 0;
        for k in 0..items.len() {
            if items.get(k).is_some_and(|item| item.centroid[axis] < pos) {
                items.swap(left, k);
                left += 1;
            }
        }
        (left > 0 && left < items.len()).then_some(left)
    });
    // Too many triangles for a leaf but no useful split (e.g. identical centroids): halve the
    // range so leaves stay small.
    let mid = partitioned.or_else(|| (items.len() > MAX_LEAF).then_some(items.len() / 2));
    (node, mid)
}

/// Builds the depth-first nodes over `items` (triangles `base..base + items.len()`), with
/// interior nodes' right-child indices relative to the returned vector. With `threads > 1`
/// large subtrees are built on separate threads.
fn build_subtree(items: &mut [Item], base: usize, threads: usize) -> Vec<BvhNode> {
    if threads > 1 && items.len() >= PARALLEL_MIN {
        let (mut root, mid) = split_node(items, base);
        let Some(mid) = mid else { return vec![root] };
        let (l, r) = items.split_at_mut(mid);
        let (left, right) = std::thread::scope(|scope| {
            let left = scope.spawn(|| build_subtree(l, base, threads / 2));
            let right = build_subtree(r, base + mid, threads - threads / 2);
            (left.join(), right)
        });
        // Building never panics on any input; if it did, the panic carries on here.
        let left = left.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
        let shift = |n: BvhNode, by: usize| {
            if n.count == 0 {
                BvhNode {
                    left_or_first: n.left_or_first + by as u32,
                    ..n
                }
            } else {
                n
            }
        };
        root.count = 0;
        root.left_or_first = (1 + left.len()) as u32;
        let mut nodes = Vec::with_capacity(1 + left.len() + right.len());
        nodes.push(root);
        let right_base = 1 + left.len();
        nodes.extend(left.into_iter().map(|n| shift(n, 1)));
        nodes.extend(right.into_iter().map(|n| shift(n, right_base)));
        return nodes;
    }
    let mut nodes: Vec<BvhNode> = Vec::with_capacity(2 * items.len() / MAX_LEAF + 1);
    // (start, end, parent whose right child this is), relative to `items`
    let mut stack: Vec<(usize, usize, Option<usize>)> = vec![(0, items.len(), None)];
    while let Some((start, end, right_of)) = stack.pop() {
        let index = nodes.len();
        if let Some(parent) = right_of.and_then(|p| nodes.get_mut(p)) {
            parent.left_or_first = index as u32;
        }
        let (mut node, mid) =
            split_node(items.get_mut(start..end).unwrap_or_default(), base + start);
        match mid {
            Some(mid) => {
                node.count = 0;
                nodes.push(node);
                stack.push((start + mid, end, Some(index)));
                stack.push((start, start + mid, None));
            }
            None => nodes.push(node),
        }
    }
    nodes
}

/// A triangle while building: its box, centroid and index in the input.
#[derive(Clone, Copy)]
struct Item {
    bounds: Aabb,
    centroid: Vec3,
    index: u32,
}

/// The best SAH split of `items` as `(axis, position)`, or `None` when a leaf is cheaper.
/// All three axes are binned in one pass.
fn sah_split(items: &[Item], cbounds: &Aabb, parent_area: f32) -> Option<(usize, f32)> {
    let extent = cbounds.extent();
    let scale = Vec3::select(
        extent.cmpgt(Vec3::ZERO),
        Vec3::splat(BINS as f32) / extent,
        Vec3::ZERO,
    );
    let mut bins = [[(Aabb::EMPTY, 0u32); BINS]; 3];
    for item in items {
        let k = ((item.centroid - cbounds.min) * scale)
            .as_uvec3()
            .min(glam::UVec3::splat(BINS as u32 - 1));
        for (axis, axis_bins) in bins.iter_mut().enumerate() {
            let bin = &mut axis_bins[k[axis] as usize];
            bin.0 = bin.0.union(&item.bounds);
            bin.1 += 1;
        }
    }
    let leaf_cost = items.len() as f32;
    let mut best: Option<(f32, usize, f32)> = None;
    for (axis, bins) in bins.iter().enumerate() {
        if extent[axis] <= 0.0 {
            continue;
        }
        // Sweep from the right to get the cost of every right side, then from the left.
        let mut right_cost = [0.0f32; BINS];
        let (mut rb, mut rn) = (Aabb::EMPTY, 0u32);
        for k in (1..BINS).rev() {
            rb = rb.union(&bins[k].0);
            rn += bins[k].1;
            right_cost[k] = if rn > 0 { rb.area() * rn as f32 } else { 0.0 };
        }
        let (mut lb, mut ln) = (Aabb::EMPTY, 0u32);
        for k in 1..BINS {
            lb = lb.union(&bins[k - 1].0);
            ln += bins[k - 1].1;
            if ln == 0 || ln as usize == items.len() {
                continue;
            }
            let cost = lb.area() * ln as f32 + right_cost[k];
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, cbounds.min[axis] + k as f32 / scale[axis]));
            }
        }
    }
    let (cost, axis, pos) = best?;
    let split_cost = TRAVERSAL_COST + cost / parent_area.max(f32::MIN_POSITIVE);
    (split_cost < leaf_cost || items.len() > MAX_LEAF).then_some((axis, pos))
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
        fn v(&mut self) -> Vec3 {
            Vec3::new(self.f(), self.f(), self.f()) * 2.0 - 1.0
        }
    }

    fn brute(tris: &[BvhTriangle], ray: &Ray) -> Option<f32> {
        tris.iter()
            .filter_map(|t| intersect_triangle(ray, t.vertices()).map(|h| h.0))
            .fold(None, |a, t| Some(a.map_or(t, |a: f32| a.min(t))))
    }

    fn soup(rng: &mut Rng, n: usize) -> Vec<BvhTriangle> {
        (0..n)
            .map(|i| {
                let c = rng.v() * 10.0;
                let size = 0.05 + rng.f();
                BvhTriangle {
                    v0: (c + rng.v() * size).to_array(),
                    instance: 0,
                    v1: (c + rng.v() * size).to_array(),
                    primitive: 0,
                    v2: (c + rng.v() * size).to_array(),
                    triangle: i as u32,
                }
            })
            .collect()
    }

    /// Every node's box contains its triangles or children; every triangle is in one leaf.
    fn check_structure(bvh: &Bvh) {
        let mut seen = vec![0u32; bvh.triangles.len()];
        for (i, n) in bvh.nodes.iter().enumerate() {
            let b = n.aabb();
            let inside = |c: &Aabb| {
                (c.min - b.min).min_element() >= -1e-5 && (b.max - c.max).min_element() >= -1e-5
            };
            if n.count > 0 {
                for k in n.left_or_first..n.left_or_first + n.count {
                    seen[k as usize] += 1;
                    assert!(inside(&bvh.triangles[k as usize].aabb()));
                }
            } else {
                assert!(inside(&bvh.nodes[i + 1].aabb()));
                assert!((n.left_or_first as usize) > i + 1);
                assert!(inside(&bvh.nodes[n.left_or_first as usize].aabb()));
            }
        }
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn matches_brute_force_on_random_rays() {
        let mut rng = Rng(0x1234_5678_9ABC_DEF1);
        let tris = soup(&mut rng, 3000);
        let bvh = Bvh::build(tris.clone());
        check_structure(&bvh);
        assert!(bvh.depth() < 40, "depth {}", bvh.depth());
        let mut hits = 0;
        for _ in 0..2000 {
            let ray = Ray {
                origin: rng.v() * 14.0,
                dir: rng.v(),
                t_min: 0.0,
                t_max: f32::INFINITY,
            };
            let expect = brute(&tris, &ray);
            let got = bvh.intersect(&ray);
            assert_eq!(expect.is_some(), got.is_some(), "{ray:?}");
            if let (Some(e), Some(g)) = (expect, got) {
                hits += 1;
                assert!((e - g.t).abs() <= 1e-4 * e.max(1.0), "{e} vs {}", g.t);
                let t = bvh.triangles[g.triangle];
                assert!(intersect_triangle(&ray, t.vertices()).is_some());
            }
        }
        assert!(
            hits > 200,
            "only {hits} rays hit; the test rays are too sparse"
        );
    }

    #[test]
    fn parallel_build_equals_sequential_build() {
        let mut rng = Rng(0x0F0F_1234_ABCD_9876);
        let tris = soup(&mut rng, 3 * PARALLEL_MIN);
        let items = |tris: &[BvhTriangle]| -> Vec<Item> {
            tris.iter()
                .enumerate()
                .map(|(i, t)| Item {
                    bounds: t.aabb(),
                    centroid: t.aabb().center(),
                    index: i as u32,
                })
                .collect()
        };
        let (mut a, mut b) = (items(&tris), items(&tris));
        let sequential = build_subtree(&mut a, 0, 1);
        let parallel = build_subtree(&mut b, 0, 4);
        assert_eq!(sequential, parallel);
        assert!(a.iter().zip(&b).all(|(x, y)| x.index == y.index));
        let bvh = Bvh::build(tris);
        check_structure(&bvh);
        for _ in 0..50 {
            let ray = Ray {
                origin: rng.v() * 14.0,
                dir: rng.v(),
                t_min: 0.0,
                t_max: f32::INFINITY,
            };
            let e = brute(&bvh.triangles, &ray);
            let g = bvh.intersect(&ray).map(|h| h.t);
            assert_eq!(e.is_some(), g.is_some());
            if let (Some(e), Some(g)) = (e, g) {
                assert!((e - g).abs() <= 1e-4 * e.max(1.0));
            }
        }
    }

    #[test]
    fn degenerate_inputs_build() {
        assert_eq!(Bvh::build(Vec::new()).nodes.len(), 0);
        // All triangles identical: no SAH split exists, leaves are still bounded in size.
        let t = BvhTriangle {
            v0: [0.0; 3],
            instance: 0,
            v1: [1.0, 0.0, 0.0],
            primitive: 0,
            v2: [0.0, 1.0, 0.0],
            triangle: 0,
        };
        let bvh = Bvh::build(vec![t; 100]);
        check_structure(&bvh);
        assert!(bvh.nodes.iter().all(|n| n.count as usize <= MAX_LEAF));
        let ray = Ray {
            origin: Vec3::new(0.2, 0.2, 1.0),
            dir: -Vec3::Z,
            t_min: 0.0,
            t_max: 10.0,
        };
        assert!((bvh.intersect(&ray).unwrap().t - 1.0).abs() < 1e-6);
    }

    #[test]
    fn refit_after_moving_triangles_matches_brute_force() {
        let mut rng = Rng(0xDEAD_BEEF_0BAD_F00D);
        let tris = soup(&mut rng, 1000);
        let mut bvh = Bvh::build(tris);
        for t in &mut bvh.triangles {
            for v in [&mut t.v0, &mut t.v1, &mut t.v2] {
                *v = (Vec3::from(*v) * 0.5 + Vec3::new(3.0, -1.0, 0.5)).to_array();
            }
        }
        bvh.refit_bounds();
        check_structure(&bvh);
        for _ in 0..500 {
            let ray = Ray {
                origin: rng.v() * 8.0,
                dir: rng.v(),
                t_min: 0.0,
                t_max: f32::INFINITY,
            };
            let e = brute(&bvh.triangles, &ray);
            let g = bvh.intersect(&ray).map(|h| h.t);
            assert_eq!(e.is_some(), g.is_some());
            if let (Some(e), Some(g)) = (e, g) {
                assert!((e - g).abs() <= 1e-4 * e.max(1.0));
            }
        }
    }
}
