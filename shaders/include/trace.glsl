// Ray traversal of the scene's two-level BVH (src/gpu_scene/bvh.rs): closest hit and occlusion
// (any hit) with fixed-size stacks. Any compute pass can include it; before the #include define
// the binding numbers of the four images it declares (set 0, names fixed so the graph binds
// them by name):
//
//     #define TRACE_NODES_BINDING 7       // `bvh_nodes`: bottom-level nodes
//     #define TRACE_TRIANGLES_BINDING 8   // `bvh_triangles`: bottom-level triangles
//     #define TRACE_TOP_BINDING 9         // `bvh_top`: top-level nodes
//     #define TRACE_INSTANCES_BINDING 10  // `bvh_instances`: top-level instance records
//     #include "trace.glsl"
//
// Storage: each array is an RGBA32F image read row by row, its vec4 k at texel
// (k mod TRACE_ROW_TEXELS, k / TRACE_ROW_TEXELS) (shine::gpu_scene::bvh::TRACE_ROW_TEXELS), not
// a storage buffer: llvmpipe loads an image texel about 4x faster than a storage buffer's vec4
// (docs/performance.md). Layout: a bottom-level node is two texels holding its two children's
// boxes in half floats and their references (leaf or node: TRACE_LEAF below) —
// shine::gpu_scene::bvh::TraceNode. A top-level node is two vec4, (min, bits of
// left_or_first) and (max, bits of count) — shine_scene::bvh::BvhNode; a leaf has count > 0
// and holds instances left_or_first .. left_or_first + count; an interior node's left child
// is the next node, its right child left_or_first. A triangle is four vec4 in one row, (v0, bits
// of its index within its mesh), (v1 − v0, 0), (v2 − v0, 0), padding — GpuBvhTriangle, mesh
// space; two sibling leaves hold adjacent triangles. An instance is four vec4: rows 0–2 of its
// world-to-mesh matrix, then (bits of its bottom-level root's reference, bits of its first
// flattened triangle, 0, 0) — TraceInstance. Rays enter a bottom level transformed but not
// renormalised, so hit distances are world distances. Both faces of every triangle are hit.
#ifndef TRACE_GLSL
#define TRACE_GLSL

#if !defined(TRACE_NODES_BINDING) || !defined(TRACE_TRIANGLES_BINDING) || !defined(TRACE_TOP_BINDING) || !defined(TRACE_INSTANCES_BINDING)
#error "define TRACE_NODES_BINDING, TRACE_TRIANGLES_BINDING, TRACE_TOP_BINDING and TRACE_INSTANCES_BINDING before including trace.glsl"
#endif

layout(set = 0, binding = TRACE_NODES_BINDING, rgba32f) readonly uniform image2D bvh_nodes;
layout(set = 0, binding = TRACE_TRIANGLES_BINDING, rgba32f) readonly uniform image2D bvh_triangles;
layout(set = 0, binding = TRACE_TOP_BINDING, rgba32f) readonly uniform image2D bvh_top;
layout(set = 0, binding = TRACE_INSTANCES_BINDING, rgba32f) readonly uniform image2D bvh_instances;

// Texels per row of the BVH images: shine::gpu_scene::bvh::TRACE_ROW_TEXELS.
const uint TRACE_ROW_TEXELS = 4096u;

// The texel of vec4 k of a BVH image.
ivec2 trace_texel(uint k) {
    return ivec2(int(k % TRACE_ROW_TEXELS), int(k / TRACE_ROW_TEXELS));
}

// Deeper than any binned-SAH tree over a storage buffer's worth of triangles needs (the far
// child is pushed, so the stack holds at most one entry per level).
const uint TRACE_STACK_SIZE = 48u;
// The same for the top level (over instances).
const uint TRACE_TOP_STACK_SIZE = 32u;

struct TraceHit {
    // Ray parameter (in units of the direction's length).
    float t;
    // Barycentric coordinates of v1 and v2.
    float u;
    float v;
    // Index of the triangle in the flattened index buffer (vertices indices[3 * triangle + k]).
    uint triangle;
    // World-space geometric normal (unnormalised; front face counter-clockwise).
    vec3 normal;
};

// A ray as the slab tests use it: 1 / dir, origin / dir and, per axis, whether the ray runs
// towards smaller coordinates (the box's far plane is then its minimum).
struct TraceSlabRay {
    vec3 inv_dir;
    vec3 origin_inv;
    bvec3 negative;
};

// The larger and smaller of two floats as a compare and a select: GLSL's max and min also
// handle NaN, which llvmpipe pays for with two more instructions each, and no NaN reaches a
// slab test (trace_inverse keeps 1 / dir finite).
float trace_larger(float a, float b) {
    return a > b ? a : b;
}
float trace_smaller(float a, float b) {
    return a < b ? a : b;
}

// Slab test of the box (lo, hi); returns the entry distance or -1 on a miss. Each axis's near
// plane is chosen by the ray's direction, so no per-axis min/max sorts the two distances.
float trace_slab(vec3 lo, vec3 hi, TraceSlabRay ray, float t_min, float t_max) {
    vec3 t_near = fma(mix(lo, hi, ray.negative), ray.inv_dir, -ray.origin_inv);
    vec3 t_far = fma(mix(hi, lo, ray.negative), ray.inv_dir, -ray.origin_inv);
    float near = trace_larger(trace_larger(t_near.x, t_near.y), trace_larger(t_near.z, t_min));
    float far = trace_smaller(trace_smaller(t_far.x, t_far.y), trace_smaller(t_far.z, t_max));
    return near <= far ? near : -1.0;
}

// Möller–Trumbore (both faces), as shine_scene::bvh::intersect_triangle: (t, u, v) when the
// hit lies in [t_min, t_max]. The decision compares u, v and t scaled by the determinant's
// magnitude, so the one division (for tuv) is off its path: lavapipe runs the test for every
// lane and the division's latency stalled the chain behind it.
bool trace_triangle(uint tri, vec3 origin, vec3 dir, float t_min, float t_max, out vec3 tuv) {
    // A triangle's texels share a row: the three loads share its offset and bounds check.
    ivec2 texel = trace_texel(4u * tri);
    vec3 a = imageLoad(bvh_triangles, texel).xyz;
    vec3 e1 = imageLoad(bvh_triangles, texel + ivec2(1, 0)).xyz;
    vec3 e2 = imageLoad(bvh_triangles, texel + ivec2(2, 0)).xyz;
    vec3 p = cross(dir, e2);
    float det = dot(e1, p);
    vec3 s = origin - a;
    vec3 q = cross(s, e1);
    float sign_det = det < 0.0 ? -1.0 : 1.0;
    float size = abs(det);
    float u = dot(s, p) * sign_det;
    float v = dot(dir, q) * sign_det;
    float t = dot(e2, q) * sign_det;
    tuv = vec3(t, u, v) * (1.0 / size);
    return size >= 1e-12 && u >= 0.0 && v >= 0.0 && u + v <= size && t >= t_min * size && t <= t_max * size;
}

// 1 / dir with zero components replaced by a huge value of the right sign (no NaN in slabs).
vec3 trace_inverse(vec3 dir) {
    vec3 safe = mix(dir, vec3(1e-30), lessThan(abs(dir), vec3(1e-30)));
    return 1.0 / safe;
}

// The slab tests' view of the ray origin + t·dir.
TraceSlabRay trace_slab_ray(vec3 origin, vec3 dir) {
    vec3 inv_dir = trace_inverse(dir);
    return TraceSlabRay(inv_dir, origin * inv_dir, lessThan(inv_dir, vec3(0.0)));
}

// A child reference with this bit is a leaf (shine::gpu_scene::bvh::TRACE_LEAF): bits 27-30
// hold its triangle count minus one, bits 0-26 its first triangle; without it, an interior
// node's index in bvh_nodes.
const uint TRACE_LEAF = 0x80000000u;

// Bottom-level node `node`'s children's boxes (half floats rounded outwards, as
// shine::gpu_scene::bvh::TraceNode) and references.
void trace_node(uint node, out vec3 left_lo, out vec3 left_hi, out vec3 right_lo, out vec3 right_hi, out uint left, out uint right) {
    uvec4 a = floatBitsToUint(imageLoad(bvh_nodes, trace_texel(2u * node)));
    uvec4 b = floatBitsToUint(imageLoad(bvh_nodes, trace_texel(2u * node + 1u)));
    vec2 h0 = unpackHalf2x16(a.x);
    vec2 h1 = unpackHalf2x16(a.y);
    vec2 h2 = unpackHalf2x16(a.z);
    vec2 h3 = unpackHalf2x16(a.w);
    vec2 h4 = unpackHalf2x16(b.x);
    vec2 h5 = unpackHalf2x16(b.y);
    left_lo = vec3(h0, h1.x);
    left_hi = vec3(h1.y, h2);
    right_lo = vec3(h3, h4.x);
    right_hi = vec3(h4.y, h5);
    left = b.z;
    right = b.w;
}

// The triangles of leaf reference `ref`: first and one past the last.
uvec2 trace_leaf_range(uint ref) {
    uint first = ref & 0x07ffffffu;
    return uvec2(first, first + ((ref >> 27u) & 15u) + 1u);
}

// Traverses one bottom level from the reference `root` with a mesh-space ray; on a hit closer
// than hit.t updates hit.t/u/v, sets `leaf` to the triangle's index in bvh_triangles and
// returns true. With `any_hit` returns at the first hit found.
//
// lavapipe runs every part of the loop's body at every step, the leaf's triangle loop at least
// once, so a step is shaped to use both: it tests the boxes of a node's two children, then the
// triangles of the children that are leaves the ray meets (two sibling leaves hold adjacent
// triangles: one range), and walks on into the interior ones, nearer first. The stack's push
// and pop sit outside every branch: llvmpipe stores to a private array lane by lane, each lane
// behind a branch on its execution mask, and under a mask as random as "this lane is at an
// interior node" those branches mispredicted (a tenth of the path tracer's time). Out here
// the mask is the loop's, nearly always full; a lane with nothing to push writes above its
// top of stack, which nothing reads.
bool trace_bottom(uint root, vec3 origin, vec3 dir, float t_min, bool any_hit, inout TraceHit hit, out uint leaf) {
    leaf = 0xffffffffu;
    TraceSlabRay slab_ray = trace_slab_ray(origin, dir);
    uint stack[TRACE_STACK_SIZE];
    uint sp = 0u;
    uint ref = root;
    bool found = false;
    while (true) {
        // A leaf root's lanes step node 0 and ignore the result.
        bool at_leaf = (ref & TRACE_LEAF) != 0u;
        vec3 left_lo, left_hi, right_lo, right_hi;
        uint left, right;
        trace_node(at_leaf ? 0u : ref, left_lo, left_hi, right_lo, right_hi, left, right);
        float tl = trace_slab(left_lo, left_hi, slab_ray, t_min, hit.t);
        float tr = trace_slab(right_lo, right_hi, slab_ray, t_min, hit.t);
        bool met_left = !at_leaf && tl >= 0.0;
        bool met_right = !at_leaf && tr >= 0.0;
        bool leaf_left = (left & TRACE_LEAF) != 0u;
        bool leaf_right = (right & TRACE_LEAF) != 0u;
        uvec2 range_left = met_left && leaf_left ? trace_leaf_range(left) : uvec2(0xffffffffu, 0u);
        uvec2 range_right = met_right && leaf_right ? trace_leaf_range(right) : uvec2(0xffffffffu, 0u);
        uvec2 range = at_leaf ? trace_leaf_range(ref) : uvec2(min(range_left.x, range_right.x), max(range_left.y, range_right.y));
        for (uint i = range.x; i < range.y; ++i) {
            vec3 tuv;
            if (trace_triangle(i, origin, dir, t_min, hit.t, tuv)) {
                hit.t = tuv.x;
                hit.u = tuv.y;
                hit.v = tuv.z;
                leaf = i;
                found = true;
                if (any_hit) {
                    return true;
                }
            }
        }
        // Into the interior children met, nearer first; the other waits on the stack.
        bool into_left = met_left && !leaf_left;
        bool into_right = met_right && !leaf_right;
        bool go_left = into_left && (!into_right || tl <= tr);
        bool descend = into_left || into_right;
        bool push = into_left && into_right && sp < TRACE_STACK_SIZE;
        stack[min(sp, TRACE_STACK_SIZE - 1u)] = go_left ? right : left;
        sp += push ? 1u : 0u;
        if (!descend && sp == 0u) {
            break;
        }
        sp -= descend ? 0u : 1u;
        uint popped = stack[min(sp, TRACE_STACK_SIZE - 1u)];
        ref = descend ? (go_left ? left : right) : popped;
    }
    return found;
}

// Tests a ray against top-level instance `k` (its bottom level in mesh space); on a closer hit
// sets `leaf` as trace_bottom. The hit's normal and triangle are found once, after the whole
// traversal (trace_hit_triangle): lavapipe would load them here for every instance.
bool trace_instance(uint k, vec3 origin, vec3 dir, float t_min, bool any_hit, inout TraceHit hit, inout uint leaf) {
    vec4 r0 = imageLoad(bvh_instances, trace_texel(4u * k));
    vec4 r1 = imageLoad(bvh_instances, trace_texel(4u * k + 1u));
    vec4 r2 = imageLoad(bvh_instances, trace_texel(4u * k + 2u));
    uint root = floatBitsToUint(imageLoad(bvh_instances, trace_texel(4u * k + 3u)).x);
    vec4 o = vec4(origin, 1.0);
    vec3 mesh_origin = vec3(dot(r0, o), dot(r1, o), dot(r2, o));
    vec3 mesh_dir = vec3(dot(r0.xyz, dir), dot(r1.xyz, dir), dot(r2.xyz, dir));
    uint found;
    bool hit_here = trace_bottom(root, mesh_origin, mesh_dir, t_min, any_hit, hit, found);
    leaf = hit_here ? found : leaf;
    return hit_here;
}

// Fills hit.normal and hit.triangle for a hit on bvh_triangles' triangle `leaf` of instance `k`.
void trace_hit_triangle(uint k, uint leaf, inout TraceHit hit) {
    vec4 r0 = imageLoad(bvh_instances, trace_texel(4u * k));
    vec4 r1 = imageLoad(bvh_instances, trace_texel(4u * k + 1u));
    vec4 r2 = imageLoad(bvh_instances, trace_texel(4u * k + 2u));
    uint triangle_base = floatBitsToUint(imageLoad(bvh_instances, trace_texel(4u * k + 3u)).y);
    vec3 e1 = imageLoad(bvh_triangles, trace_texel(4u * leaf + 1u)).xyz;
    vec3 e2 = imageLoad(bvh_triangles, trace_texel(4u * leaf + 2u)).xyz;
    // Normals move with the inverse transpose: the transpose of world-to-mesh.
    vec3 n = cross(e1, e2);
    hit.normal = r0.xyz * n.x + r1.xyz * n.y + r2.xyz * n.z;
    uint index = floatBitsToUint(imageLoad(bvh_triangles, trace_texel(4u * leaf)).w);
    hit.triangle = triangle_base + index;
}

// Traverses the top level, each instance's bottom level in turn; with `any_hit` returns at
// the first hit found (occlusion), otherwise keeps the closest.
bool trace_traverse(vec3 origin, vec3 dir, float t_min, float t_max, bool any_hit, out TraceHit hit) {
    hit.t = t_max;
    hit.u = 0.0;
    hit.v = 0.0;
    hit.triangle = 0xffffffffu;
    hit.normal = vec3(0.0);
    TraceSlabRay slab_ray = trace_slab_ray(origin, dir);
    // As trace_bottom: the box tests load what the visits need.
    vec4 lo = imageLoad(bvh_top, trace_texel(0u));
    vec4 hi = imageLoad(bvh_top, trace_texel(1u));
    if (trace_slab(lo.xyz, hi.xyz, slab_ray, t_min, t_max) < 0.0) {
        return false;
    }
    uint stack[TRACE_TOP_STACK_SIZE];
    uint sp = 0u;
    uint node = 0u;
    uint first = floatBitsToUint(lo.w);
    uint count = floatBitsToUint(hi.w);
    bool found = false;
    uint instance = 0u;
    uint leaf = 0u;
    while (true) {
        bool at_leaf = count > 0u;
        if (at_leaf) {
            for (uint k = first; k < first + count; ++k) {
                if (trace_instance(k, origin, dir, t_min, any_hit, hit, leaf)) {
                    instance = k;
                    found = true;
                    if (any_hit) {
                        return true;
                    }
                }
            }
        }
        // As trace_bottom: the stack outside every branch; a leaf's lanes test the root's box
        // twice and ignore the result. An interior node's left child is the next node, its
        // right child `first`.
        uint left = at_leaf ? 0u : node + 1u;
        uint right = at_leaf ? 0u : first;
        vec4 left_lo = imageLoad(bvh_top, trace_texel(2u * left));
        vec4 left_hi = imageLoad(bvh_top, trace_texel(2u * left + 1u));
        vec4 right_lo = imageLoad(bvh_top, trace_texel(2u * right));
        vec4 right_hi = imageLoad(bvh_top, trace_texel(2u * right + 1u));
        float tl = trace_slab(left_lo.xyz, left_hi.xyz, slab_ray, t_min, hit.t);
        float tr = trace_slab(right_lo.xyz, right_hi.xyz, slab_ray, t_min, hit.t);
        bool go_left = tl >= 0.0 && (tr < 0.0 || tl <= tr);
        bool descend = !at_leaf && (tl >= 0.0 || tr >= 0.0);
        bool push = descend && tl >= 0.0 && tr >= 0.0 && sp < TRACE_TOP_STACK_SIZE;
        stack[min(sp, TRACE_TOP_STACK_SIZE - 1u)] = go_left ? right : left;
        sp += push ? 1u : 0u;
        if (!descend && sp == 0u) {
            break;
        }
        sp -= descend ? 0u : 1u;
        uint popped = stack[min(sp, TRACE_TOP_STACK_SIZE - 1u)];
        node = descend ? (go_left ? left : right) : popped;
        first = floatBitsToUint(descend ? (go_left ? left_lo.w : right_lo.w) : imageLoad(bvh_top, trace_texel(2u * node)).w);
        count = floatBitsToUint(descend ? (go_left ? left_hi.w : right_hi.w) : imageLoad(bvh_top, trace_texel(2u * node + 1u)).w);
    }
    if (found && !any_hit) {
        trace_hit_triangle(instance, leaf, hit);
    }
    return found;
}

// The closest hit of origin + t·dir, t in [t_min, t_max].
bool trace_closest(vec3 origin, vec3 dir, float t_min, float t_max, out TraceHit hit) {
    return trace_traverse(origin, dir, t_min, t_max, false, hit);
}

// Whether anything lies on origin + t·dir, t in [t_min, t_max] (shadow and visibility rays).
bool trace_occluded(vec3 origin, vec3 dir, float t_min, float t_max) {
    TraceHit hit;
    return trace_traverse(origin, dir, t_min, t_max, true, hit);
}

// A ray origin moved off a surface at p along its unit geometric normal n (towards the side
// the new ray leaves to), against self-intersection; scaled with the coordinates' magnitude.
vec3 trace_offset(vec3 p, vec3 n) {
    float scale = 1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z));
    return p + n * (1e-4 * scale);
}

#endif
