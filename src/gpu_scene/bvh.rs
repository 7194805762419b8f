//! The scene's two-level BVH on the GPU, for ray traversal in compute shaders
//! (`shaders/include/trace.glsl`).
//!
//! - **Bottom levels**: one binned-SAH [`Bvh`] per mesh, over its triangles in mesh space,
//!   built once when the scene is uploaded ([`BottomLevels::build`]); all of them live in one
//!   node buffer and one triangle buffer (absolute indices, so traversal needs no offsets). A
//!   node holds its two children's boxes in half floats and their references
//!   ([`TraceNode`]); a triangle carries its index within its mesh (primitives concatenated
//!   in order).
//! - **Deforming instances** (skinned or morphing) get a bottom level of their own in world
//!   space, first in the buffers, refitted every frame (src/gpu_scene/deformers.rs); their
//!   top-level record carries the identity.
//! - **Top level**: a binned-SAH tree over the instances' world boxes, rebuilt on the CPU
//!   every frame ([`TopLevel::build`]; tens to hundreds of boxes: microseconds, see
//!   docs/performance.md) and uploaded with the frame. An instance record holds the
//!   world-to-mesh transform (the ray is moved into mesh space, not renormalised, so hit
//!   distances stay world distances), its bottom level's root, and the index of its first
//!   triangle in the flattened scene index buffer of [`crate::gpu_scene::GpuScene`], so a hit
//!   is shaded with the interpolated world-space vertices and the material of the raster
//!   passes.

use glam::{Mat4, Vec3};
use shine_gpu::{Device, Image, ImageDesc, vk};
use shine_scene::bvh::{Bvh, BvhNode, BvhTriangle, build_over_boxes};
use shine_scene::{Aabb, Mesh, Scene};

use crate::gpu_scene::SceneUploadError;
use crate::graph::{ExternalState, Handle, RenderGraph};

/// Texels per row of the BVH images (`TRACE_ROW_TEXELS` of `trace.glsl`): vec4 `k` of an
/// array is texel `(k mod TRACE_ROW_TEXELS, k / TRACE_ROW_TEXELS)`. The arrays are RGBA32F
/// images, not storage buffers, because llvmpipe loads an image texel about 4× faster than a
/// storage buffer's vec4 (docs/performance.md); 4096 is the smallest `maxImageDimension2D`
/// Vulkan allows, so a row fits every device.
pub const TRACE_ROW_TEXELS: u32 = 4096;

/// Format of the BVH images: one vec4 per texel.
pub const TRACE_FORMAT: vk::Format = vk::Format::R32G32B32A32_SFLOAT;

/// Bytes of one texel of the BVH images.
const TEXEL_BYTES: usize = 16;

/// Width and height of a BVH image holding `texels` vec4s (at least one).
pub fn trace_extent(texels: usize) -> [u32; 2] {
    let (texels, row) = (texels.max(1), TRACE_ROW_TEXELS as usize);
    [texels.min(row) as u32, texels.div_ceil(row) as u32]
}

/// The first `data.len()` bytes of `full` (an image's whole contents) replaced by `data` and
/// cut after the last row `data` touches: what an upload that rewrites the start of an image
/// of width `width` stages (the copy fills whole rows; see
/// [`RenderGraph::copy_buffer_to_image`]).
pub fn leading_rows(data: &[u8], full: &[u8], width: u32) -> Vec<u8> {
    let row = width as usize * TEXEL_BYTES;
    let end = data.len().div_ceil(row).max(1) * row;
    let mut out = full[..end.min(full.len())].to_vec();
    out.resize(end, 0);
    out[..data.len()].copy_from_slice(data);
    out
}

/// `data` padded with zeros to fill an image of `extent`.
fn padded(data: &[u8], extent: [u32; 2]) -> Vec<u8> {
    let mut out = data.to_vec();
    out.resize(extent[0] as usize * extent[1] as usize * TEXEL_BYTES, 0);
    out
}

/// The BVH images imported into a frame graph, bound by the names `trace.glsl` declares.
#[derive(Debug, Clone, Copy)]
pub struct TraceImages {
    /// `bvh_nodes`: the bottom levels' nodes.
    pub nodes: Handle<crate::graph::Image>,
    /// `bvh_triangles`: the bottom levels' triangles.
    pub triangles: Handle<crate::graph::Image>,
    /// `bvh_top`: the top level's nodes.
    pub top: Handle<crate::graph::Image>,
    /// `bvh_instances`: the top level's instance records.
    pub instances: Handle<crate::graph::Image>,
}

impl TraceImages {
    /// Binds the four images to `pass` by the names `trace.glsl` declares.
    pub fn bind(&self, pass: &mut crate::graph::ComputePass<'_>) {
        pass.read("bvh_nodes", &self.nodes)
            .read("bvh_triangles", &self.triangles)
            .read("bvh_top", &self.top)
            .read("bvh_instances", &self.instances);
    }
}

/// A bottom-level triangle as `trace.glsl` reads it (64 bytes, four texels in one row): its
/// first vertex and two edges in mesh space (the ray test's operands, subtracted once here
/// rather than at every test) and the triangle's index within its mesh. The fourth texel is
/// padding: with three a triangle's texels could straddle a row, and llvmpipe computed each
/// load's row offset and bounds apart; in one row the test's three loads share them (cornell-box
/// path tracer 484.2 → 469.7 ns per sample, docs/performance.md).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuBvhTriangle {
    /// First vertex (mesh space).
    pub v0: [f32; 3],
    /// Triangle index within the mesh; the instance's `triangle_base` is added at a hit.
    pub index: u32,
    /// Second vertex minus the first.
    pub e1: [f32; 3],
    /// Padding.
    pub _pad0: u32,
    /// Third vertex minus the first.
    pub e2: [f32; 3],
    /// Padding.
    pub _pad1: u32,
    /// Padding: the fourth texel.
    pub _pad2: [u32; 4],
}

/// A bottom-level interior node as `trace.glsl` reads it (32 bytes, two texels): both
/// children's boxes in half floats rounded outwards, then the two children's references
/// ([`trace_ref`]). A traversal step loads one node and tests both children without loading
/// them: on lavapipe a texel costs about 45 instructions per SIMD group, and the earlier
/// layout (each node its own box in fp32) loaded six texels a step.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TraceNode {
    /// Half-float pairs: left min (x, y), (z, left max x), left max (y, z), right min (x, y),
    /// (z, right max x), right max (y, z).
    pub boxes: [u32; 6],
    /// Reference of the left child.
    pub left: u32,
    /// Reference of the right child.
    pub right: u32,
}

/// A child reference with this bit is a leaf: bits 27–30 hold its triangle count minus one and
/// bits 0–26 its first triangle (`TRACE_LEAF` of `trace.glsl`); without it, the index of an
/// interior node. Every triangle image a device holds (at most 65 536 rows of 4096 texels,
/// four texels a triangle) indexes below 2²⁷.
pub const TRACE_LEAF: u32 = 1 << 31;
/// The shift of a leaf reference's triangle count (minus one): leaves hold up to 16.
const TRACE_LEAF_COUNT_SHIFT: u32 = 27;

/// The reference `trace.glsl` follows to BVH node `node` (absolute indices).
pub fn trace_ref(node: &BvhNode, index: u32) -> u32 {
    if node.count == 0 {
        index
    } else {
        TRACE_LEAF
            | (node.count.saturating_sub(1).min(15) << TRACE_LEAF_COUNT_SHIFT)
            | node.left_or_first
    }
}

/// `x` as a half float no greater (`up` false) or no smaller (`up` true) than `x`: a box
/// rounded outwards only grows, so traversal misses nothing (beyond ±65 504 it is infinite).
fn half_outwards(x: f32, up: bool) -> u16 {
    let h = half::f16::from_f32(x);
    let v = h.to_f32();
    let bits = h.to_bits();
    let outside = if up { v >= x } else { v <= x };
    if outside {
        return bits;
    }
    // One step outwards: away from zero on the side of the rounding, towards zero otherwise.
    let negative = bits & 0x8000 != 0;
    match (up, negative) {
        (true, false) | (false, true) => bits + 1,
        (true, true) if bits == 0x8000 => 0x0001,
        (false, false) if bits == 0 => 0x8001,
        _ => bits - 1,
    }
}

/// The interior node over children `l` and `r` (their references `left` and `right`).
fn trace_node(l: &BvhNode, r: &BvhNode, left: u32, right: u32) -> TraceNode {
    let pair = |a: u16, b: u16| u32::from(a) | (u32::from(b) << 16);
    let lo = |n: &BvhNode| n.min.map(|x| half_outwards(x, false));
    let hi = |n: &BvhNode| n.max.map(|x| half_outwards(x, true));
    let (ll, lh, rl, rh) = (lo(l), hi(l), lo(r), hi(r));
    TraceNode {
        boxes: [
            pair(ll[0], ll[1]),
            pair(ll[2], lh[0]),
            pair(lh[1], lh[2]),
            pair(rl[0], rl[1]),
            pair(rl[2], rh[0]),
            pair(rh[1], rh[2]),
        ],
        left,
        right,
    }
}

/// A top-level instance record as `trace.glsl` reads it (64 bytes).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TraceInstance {
    /// Rows 0–2 of the world-to-mesh matrix (an affine 3×4).
    pub world_to_mesh: [[f32; 4]; 3],
    /// Reference of the root of the instance's bottom level ([`trace_ref`]).
    pub root: u32,
    /// Flattened index of the instance's first triangle.
    pub triangle_base: u32,
    /// Padding.
    pub _pad: [u32; 2],
}

/// One instance as the top level is built from it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TopInstance {
    /// Mesh-to-world matrix.
    pub world: Mat4,
    /// Bottom-level root ([`BottomLevels::roots`]).
    pub root: u32,
    /// Bounds of the bottom level in mesh space ([`BottomLevels::bounds`]).
    pub bounds: Aabb,
    /// Flattened index of the instance's first triangle.
    pub triangle_base: u32,
}

/// Every mesh's bottom level, concatenated (CPU side).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct BottomLevels {
    /// Interior nodes of all bottom levels (absolute references; a leaf's slot is unused).
    pub nodes: Vec<TraceNode>,
    /// Triangles of all bottom levels, in leaf order.
    pub triangles: Vec<GpuBvhTriangle>,
    /// Per mesh: the reference of its root ([`trace_ref`]), `u32::MAX` for a mesh without
    /// triangles.
    pub roots: Vec<u32>,
    /// Per mesh: the bounds of its triangles in mesh space.
    pub bounds: Vec<Aabb>,
}

impl BottomLevels {
    /// One bottom level per mesh of `scene`, over its primitives in mesh space.
    pub fn build(scene: &Scene) -> Self {
        let mut out = Self::default();
        out.add_meshes(scene);
        out
    }

    /// Appends one bottom level per mesh of `scene` (setting [`BottomLevels::roots`] and
    /// [`BottomLevels::bounds`]).
    pub fn add_meshes(&mut self, scene: &Scene) {
        let out = self;
        for mesh in &scene.meshes {
            let mut soup = Vec::new();
            for (p, primitive) in mesh.primitives.iter().enumerate() {
                push_triangles(&primitive.positions, &primitive.indices, p, &mut soup);
            }
            let starts = triangle_starts(mesh);
            let (root, bounds) = out.append(&Bvh::build(soup), |t| local_index(&starts, t));
            out.roots.push(root);
            out.bounds.push(bounds);
        }
    }

    /// Appends `bvh` with each triangle's index given by `index`; returns the reference of its
    /// root (`u32::MAX` when empty) and its bounds.
    pub fn append(&mut self, bvh: &Bvh, index: impl Fn(&BvhTriangle) -> u32) -> (u32, Aabb) {
        let Some(root) = bvh.nodes.first() else {
            return (u32::MAX, Aabb::EMPTY);
        };
        let node_base = self.nodes.len() as u32;
        let triangle_base = self.triangles.len() as u32;
        let absolute = |i: usize| {
            bvh.nodes.get(i).map(|n| {
                let first = if n.count == 0 {
                    node_base
                } else {
                    triangle_base
                };
                let node = BvhNode {
                    left_or_first: n.left_or_first + first,
                    ..*n
                };
                (node, trace_ref(&node, node_base + i as u32))
            })
        };
        self.nodes.extend((0..bvh.nodes.len()).map(|i| {
            let node = bvh.nodes.get(i).copied().unwrap_or(*root);
            let children = (node.count == 0)
                .then(|| absolute(i + 1).zip(absolute(node.left_or_first as usize)))
                .flatten();
            children.map_or(TraceNode::default(), |((l, lr), (r, rr))| {
                trace_node(&l, &r, lr, rr)
            })
        }));
        let root_ref = absolute(0).map_or(u32::MAX, |(_, r)| r);
        self.triangles
            .extend(bvh.triangles.iter().map(|t| GpuBvhTriangle {
                v0: t.v0,
                index: index(t),
                e1: (Vec3::from(t.v1) - Vec3::from(t.v0)).to_array(),
                e2: (Vec3::from(t.v2) - Vec3::from(t.v0)).to_array(),
                ..GpuBvhTriangle::default()
            }));
        let bounds = Aabb {
            min: Vec3::from(root.min),
            max: Vec3::from(root.max),
        };
        (root_ref, bounds)
    }
}

/// Appends the triangles of primitive `primitive` (its `positions` indexed by `indices`) to
/// `out`, for a BVH build.
pub fn push_triangles(
    positions: &[Vec3],
    indices: &[u32],
    primitive: usize,
    out: &mut Vec<BvhTriangle>,
) {
    let get = |i: u32| {
        positions
            .get(i as usize)
            .copied()
            .unwrap_or_default()
            .to_array()
    };
    for (t, tri) in indices.chunks_exact(3).enumerate() {
        out.push(BvhTriangle {
            v0: get(tri[0]),
            instance: 0,
            v1: get(tri[1]),
            primitive: primitive as u32,
            v2: get(tri[2]),
            triangle: t as u32,
        });
    }
}

/// Per primitive of `mesh`, the index of its first triangle within the mesh (primitives
/// concatenated in order): how flattened triangle indices are made.
pub fn triangle_starts(mesh: &Mesh) -> Vec<u32> {
    mesh.primitives
        .iter()
        .scan(0u32, |next, p| {
            let start = *next;
            *next += p.triangle_count() as u32;
            Some(start)
        })
        .collect()
}

/// A bottom-level triangle's index within its mesh.
pub fn local_index(starts: &[u32], t: &BvhTriangle) -> u32 {
    starts.get(t.primitive as usize).copied().unwrap_or(0) + t.triangle
}

/// The top level of one frame (CPU side).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TopLevel {
    /// Nodes; a leaf's `left_or_first .. + count` index `instances`.
    pub nodes: Vec<BvhNode>,
    /// Instance records in leaf order.
    pub instances: Vec<TraceInstance>,
}

impl TopLevel {
    /// The top level over `instances` (those without triangles are left out).
    pub fn build(instances: &[TopInstance]) -> Self {
        let live: Vec<&TopInstance> = instances
            .iter()
            .filter(|i| i.root != u32::MAX && !i.bounds.is_empty())
            .collect();
        let boxes: Vec<Aabb> = live
            .iter()
            .map(|i| i.bounds.transformed(&i.world))
            .collect();
        let (nodes, order) = build_over_boxes(&boxes);
        let instances = order
            .iter()
            .filter_map(|&k| live.get(k as usize))
            .map(|i| {
                let inverse = i.world.inverse();
                TraceInstance {
                    world_to_mesh: [
                        inverse.row(0).to_array(),
                        inverse.row(1).to_array(),
                        inverse.row(2).to_array(),
                    ],
                    root: i.root,
                    triangle_base: i.triangle_base,
                    _pad: [0; 2],
                }
            })
            .collect();
        Self { nodes, instances }
    }
}

/// The two levels on the GPU, as RGBA32F images ([`TRACE_ROW_TEXELS`]) in `GENERAL` layout:
/// the bottom levels, uploaded once, and the top level's images, sized for every instance and
/// rewritten every frame.
pub struct GpuBvh {
    /// Bottom-level nodes ([`TraceNode`], two texels each).
    pub nodes: Image,
    /// Bottom-level triangles ([`GpuBvhTriangle`], four texels each).
    pub triangles: Image,
    /// Top-level nodes (room for `2n - 1` nodes of `n` instances).
    pub top: Image,
    /// Top-level instance records ([`TraceInstance`], four texels each).
    pub instances: Image,
    /// The bottom levels on the CPU (their roots and bounds place instances in the top level).
    pub bottom: BottomLevels,
}

impl GpuBvh {
    /// Uploads `bottom` and allocates top-level images for up to `instance_count` instances
    /// (zeroed). A level with more texels than the device's images hold rows for is refused.
    pub fn new(
        device: &Device,
        bottom: BottomLevels,
        instance_count: usize,
    ) -> Result<Self, SceneUploadError> {
        if bottom.triangles.is_empty() {
            return Err(SceneUploadError::Empty);
        }
        let n = instance_count.max(1);
        let node = std::mem::size_of::<BvhNode>();
        Ok(Self {
            nodes: trace_image(device, "bvh nodes", bytemuck::cast_slice(&bottom.nodes))?,
            triangles: trace_image(
                device,
                "bvh triangles",
                bytemuck::cast_slice(&bottom.triangles),
            )?,
            top: trace_image(device, "bvh top", &vec![0; (2 * n - 1) * node])?,
            instances: trace_image(
                device,
                "bvh instances",
                &vec![0; n * std::mem::size_of::<TraceInstance>()],
            )?,
            bottom,
        })
    }

    /// A BVH over a world-space triangle soup (tests and tools): one identity instance whose
    /// triangles keep `bvh`'s `triangle` field as their flattened index, with its top level
    /// already uploaded. Import it with [`GpuBvh::import`].
    pub fn from_world(device: &Device, bvh: &Bvh) -> Result<Self, SceneUploadError> {
        let mut bottom = BottomLevels::default();
        let (root, bounds) = bottom.append(bvh, |t| t.triangle);
        let top = TopLevel::build(&[TopInstance {
            world: Mat4::IDENTITY,
            root,
            bounds,
            triangle_base: 0,
        }]);
        let gpu = Self::new(device, bottom, 1)?;
        for (image, data) in [
            (&gpu.top, bytemuck::cast_slice(&top.nodes)),
            (&gpu.instances, bytemuck::cast_slice(&top.instances)),
        ] {
            let data = padded(data, image.extent());
            device.upload_image(image, &data, vk::ImageLayout::GENERAL)?;
        }
        Ok(gpu)
    }

    /// Imports all four images into `rg`, read-only, in `state` before and after the frame
    /// (for a BVH whose top level is already on the device, e.g. [`GpuBvh::from_world`]).
    pub fn import(&self, rg: &mut RenderGraph, state: ExternalState) -> TraceImages {
        TraceImages {
            nodes: rg.import_gpu_image(&self.nodes, state, state),
            triangles: rg.import_gpu_image(&self.triangles, state, state),
            top: rg.import_gpu_image(&self.top, state, state),
            instances: rg.import_gpu_image(&self.instances, state, state),
        }
    }

    /// Bytes of device memory the four images hold.
    pub fn allocated_bytes(&self) -> u64 {
        [&self.nodes, &self.triangles, &self.top, &self.instances]
            .iter()
            .map(|i| i.allocated_bytes())
            .sum()
    }
}

/// A BVH image named `name` holding `data` (whole vec4s, zero-padded to whole rows), in
/// `GENERAL` layout.
fn trace_image(device: &Device, name: &str, data: &[u8]) -> Result<Image, SceneUploadError> {
    let texels = data.len().div_ceil(TEXEL_BYTES);
    let image = rows_image(device, name, texels, TRACE_FORMAT)?;
    device.upload_image(
        &image,
        &padded(data, image.extent()),
        vk::ImageLayout::GENERAL,
    )?;
    Ok(image)
}

/// A storage image named `name` of `format` with room for `texels` texels in rows of
/// [`TRACE_ROW_TEXELS`] (texel `k` at `(k mod TRACE_ROW_TEXELS, k / TRACE_ROW_TEXELS)`), that
/// transfers can fill; refused when the device's images hold too few rows.
pub fn rows_image(
    device: &Device,
    name: &str,
    texels: usize,
    format: vk::Format,
) -> Result<Image, SceneUploadError> {
    let extent = trace_extent(texels);
    let rows = device.limits().max_image_dimension2_d;
    if extent[1] > rows {
        return Err(SceneUploadError::TooLarge(format!(
            "{name}: {texels} texels need {} rows of {TRACE_ROW_TEXELS}, the device's images \
             hold {rows}",
            extent[1]
        )));
    }
    let usage = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_DST;
    Ok(Image::new(
        device,
        &ImageDesc::new_2d(name, extent, format, usage),
    )?)
}

/// A one-level world-space BVH of `scene` placed with `world`, and for every triangle of it
/// its index in the flattened index buffer (instances in [`Scene::instances`] order, then
/// primitives, then triangles: the order `GpuScene` concatenates them). The CPU reference the
/// two-level GPU traversal is tested against.
pub fn world_bvh(scene: &Scene, world: &[Mat4]) -> Result<(Bvh, Vec<u32>), SceneUploadError> {
    let bvh = Bvh::from_scene(scene, world);
    if bvh.triangles.is_empty() {
        return Err(SceneUploadError::Empty);
    }
    // First flat triangle of every (instance, primitive).
    let mut first: Vec<Vec<u64>> = Vec::with_capacity(bvh.instances.len());
    let mut next = 0u64;
    for instance in &bvh.instances {
        let mut starts = Vec::new();
        if let Some(mesh) = scene.meshes.get(instance.mesh as usize) {
            for primitive in &mesh.primitives {
                starts.push(next);
                next += (primitive.indices.len() / 3) as u64;
            }
        }
        first.push(starts);
    }
    let flat_index = bvh
        .triangles
        .iter()
        .map(|t| {
            let start = first
                .get(t.instance as usize)
                .and_then(|s| s.get(t.primitive as usize))
                .copied()
                .unwrap_or(0);
            u32::try_from(start + u64::from(t.triangle))
                .map_err(|_| SceneUploadError::TooLarge("over 4G triangles".into()))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((bvh, flat_index))
}

/// `BvhNode` as `trace.glsl` reads it: two vec4 (min, left_or_first bits; max, count bits).
const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);
const _: () = assert!(std::mem::size_of::<TraceNode>() == 32);
const _: () = assert!(std::mem::size_of::<GpuBvhTriangle>() == 64);
/// A triangle's four texels lie in one row (`trace_triangle` offsets the first texel's x).
const _: () = assert!(
    (TRACE_ROW_TEXELS as usize).is_multiple_of(std::mem::size_of::<GpuBvhTriangle>() / TEXEL_BYTES)
);
const _: () = assert!(std::mem::size_of::<TraceInstance>() == 64);

#[cfg(test)]
mod tests {
    use super::*;

    /// Half floats rounded outwards bound the value from the asked side, by at most one step,
    /// on both signs, at zero and past the half range.
    #[test]
    fn half_outwards_never_rounds_inwards() {
        for x in [
            0.0f32, -0.0, 1.0, -1.0, 0.1, -0.1, 0.278, -0.2796, 1.0e-6, -1.0e-6, 3.3e-8, 1234.5,
            -65_000.0, 70_000.0, -70_000.0,
        ] {
            let down = half::f16::from_bits(half_outwards(x, false)).to_f32();
            let up = half::f16::from_bits(half_outwards(x, true)).to_f32();
            assert!(down <= x && x <= up, "{x}: [{down}, {up}]");
            if x.abs() < 60_000.0 {
                assert!(up - down <= 1e-3 * x.abs().max(1e-4), "{x}: [{down}, {up}]");
            }
        }
    }

    /// A packed node holds its children's boxes (grown by the rounding only) and references:
    /// interior children by absolute index, leaves by first triangle and count.
    #[test]
    fn packed_nodes_bound_their_children() {
        let tri = |x: f32| BvhTriangle {
            v0: [x, 0.0, 0.0],
            v1: [x + 0.3, 1.0, 0.0],
            v2: [x, 0.0, 0.7],
            ..bytemuck::Zeroable::zeroed()
        };
        let bvh = Bvh::build((0..40).map(|i| tri(i as f32 * 0.37)).collect());
        let mut levels = BottomLevels::default();
        levels.append(&Bvh::build(vec![tri(0.0)]), |_| 0);
        let (root, _) = levels.append(&bvh, |t| t.triangle);
        let (node_base, triangle_base) = (1u32, 1u32);
        assert_eq!(
            root, node_base,
            "a tree of 40 triangles has an interior root"
        );
        let unpack = |w: u32| {
            let h = |b: u32| half::f16::from_bits(b as u16).to_f32();
            [h(w & 0xffff), h(w >> 16)]
        };
        for (i, n) in bvh.nodes.iter().enumerate().filter(|(_, n)| n.count == 0) {
            let packed = levels.nodes[node_base as usize + i];
            let f: Vec<f32> = packed.boxes.iter().flat_map(|&w| unpack(w)).collect();
            for (child, lo, hi, reference) in [
                (i + 1, &f[0..3], &f[3..6], packed.left),
                (n.left_or_first as usize, &f[6..9], &f[9..12], packed.right),
            ] {
                let c = bvh.nodes[child];
                for k in 0..3 {
                    assert!(
                        lo[k] <= c.min[k] && c.max[k] <= hi[k],
                        "node {i} child {child}"
                    );
                }
                let expected = if c.count == 0 {
                    node_base + child as u32
                } else {
                    TRACE_LEAF
                        | ((c.count - 1) << TRACE_LEAF_COUNT_SHIFT)
                        | (triangle_base + c.left_or_first)
                };
                assert_eq!(reference, expected, "node {i} child {child}");
            }
        }
    }

    /// A subtree's triangles are contiguous, the left child's before the right's, so two
    /// sibling leaves hold adjacent ranges: `trace.glsl` tests both as one range
    /// (`trace_bottom`), which would test others' triangles between them otherwise.
    #[test]
    fn sibling_leaves_hold_adjacent_triangles() {
        let mut rng = 0x2545_f491_u32;
        let mut f = || {
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            (rng >> 8) as f32 / (1 << 24) as f32
        };
        let soup: Vec<BvhTriangle> = (0..500)
            .map(|_| {
                let c = [f() * 10.0, f() * 10.0, f() * 10.0];
                BvhTriangle {
                    v0: c,
                    v1: [c[0] + f(), c[1], c[2] + f()],
                    v2: [c[0], c[1] + f(), c[2]],
                    ..bytemuck::Zeroable::zeroed()
                }
            })
            .collect();
        let bvh = Bvh::build(soup);
        // The triangle range under every node, children before parents.
        let mut span = vec![(0u32, 0u32); bvh.nodes.len()];
        for (i, n) in bvh.nodes.iter().enumerate().rev() {
            span[i] = if n.count > 0 {
                (n.left_or_first, n.left_or_first + n.count)
            } else {
                let (l, r) = (span[i + 1], span[n.left_or_first as usize]);
                assert_eq!(
                    l.1, r.0,
                    "node {i}: its children's triangles are not adjacent"
                );
                (l.0, r.1)
            };
        }
        assert_eq!(span[0], (0, bvh.triangles.len() as u32));
        assert!(bvh.nodes.iter().filter(|n| n.count == 0).count() > 50);
    }

    #[test]
    fn trace_extent_fills_rows_of_trace_row_texels() {
        assert_eq!(trace_extent(0), [1, 1]);
        assert_eq!(trace_extent(5), [5, 1]);
        let row = TRACE_ROW_TEXELS as usize;
        assert_eq!(trace_extent(row), [TRACE_ROW_TEXELS, 1]);
        assert_eq!(trace_extent(row + 1), [TRACE_ROW_TEXELS, 2]);
        assert_eq!(trace_extent(3 * row), [TRACE_ROW_TEXELS, 3]);
    }

    /// The staged rows hold the new prefix, then the rest of its last row from the whole
    /// image's contents (zeros past its end), and nothing past that row.
    #[test]
    fn leading_rows_keep_the_rest_of_the_last_row() {
        let texel = |v: u8| [v; TEXEL_BYTES];
        let full: Vec<u8> = (0..10u8).flat_map(texel).collect();
        let prefix: Vec<u8> = [100u8, 101, 102].into_iter().flat_map(texel).collect();
        let out = leading_rows(&prefix, &full, 4);
        let expected: Vec<u8> = [100u8, 101, 102, 3].into_iter().flat_map(texel).collect();
        assert_eq!(out, expected);
        let out = leading_rows(&full[..5 * TEXEL_BYTES], &full, 4);
        assert_eq!(out.len(), 8 * TEXEL_BYTES);
        assert_eq!(&out[..], &full[..8 * TEXEL_BYTES]);
        let out = leading_rows(&prefix, &[], 4);
        assert_eq!(&out[..3 * TEXEL_BYTES], &prefix[..]);
        assert_eq!(&out[3 * TEXEL_BYTES..], &[0; TEXEL_BYTES]);
    }
}
