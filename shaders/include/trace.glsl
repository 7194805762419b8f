// Ray traversal of the scene BVH (src/gpu_scene/bvh.rs): closest hit and occlusion (any hit) with a
// fixed-size stack. Any compute pass can include it; before the #include define the binding
// numbers of the two buffers it declares (set 0, names fixed so the graph binds them by name):
//
//     #define TRACE_NODES_BINDING 7       // `bvh_nodes`: GpuBvh::nodes
//     #define TRACE_TRIANGLES_BINDING 8   // `bvh_triangles`: GpuBvh::triangles
//     #include "trace.glsl"
//
// Layout: a node is two vec4, (min, bits of left_or_first) and (max, bits of count) —
// shine_scene::bvh::BvhNode; a leaf has count > 0 and holds triangles left_or_first ..
// left_or_first + count; an interior node's left child is the next node, its right child
// left_or_first. A triangle is three vec4, (v0, bits of its index in the flattened scene index
// buffer), (v1, 0), (v2, 0) — GpuBvhTriangle. Both faces of every triangle are hit.
#ifndef TRACE_GLSL
#define TRACE_GLSL

#if !defined(TRACE_NODES_BINDING) || !defined(TRACE_TRIANGLES_BINDING)
#error "define TRACE_NODES_BINDING and TRACE_TRIANGLES_BINDING before including trace.glsl"
#endif

layout(set = 0, binding = TRACE_NODES_BINDING, std430) readonly buffer BvhNodes {
    vec4 n[];
} bvh_nodes;
layout(set = 0, binding = TRACE_TRIANGLES_BINDING, std430) readonly buffer BvhTriangles {
    vec4 t[];
} bvh_triangles;

// Deeper than any binned-SAH tree over a storage buffer's worth of triangles needs (the far
// child is pushed, so the stack holds at most one entry per level).
const uint TRACE_STACK_SIZE = 48u;

struct TraceHit {
    // Ray parameter (in units of the direction's length).
    float t;
    // Barycentric coordinates of v1 and v2.
    float u;
    float v;
    // Index of the triangle in the flattened index buffer (vertices indices[3 * triangle + k]).
    uint triangle;
    // Index of the triangle in bvh_triangles (leaf order).
    uint leaf_triangle;
};

// Slab test; returns the entry distance or -1 on a miss.
float trace_box(uint node, vec3 origin, vec3 inv_dir, float t_min, float t_max) {
    vec3 lo = bvh_nodes.n[2u * node].xyz;
    vec3 hi = bvh_nodes.n[2u * node + 1u].xyz;
    vec3 t0 = (lo - origin) * inv_dir;
    vec3 t1 = (hi - origin) * inv_dir;
    vec3 a = min(t0, t1);
    vec3 b = max(t0, t1);
    float near = max(max(max(a.x, a.y), a.z), t_min);
    float far = min(min(min(b.x, b.y), b.z), t_max);
    return near <= far ? near : -1.0;
}

// Möller–Trumbore (both faces), as shine_scene::bvh::intersect_triangle: (t, u, v) when the
// hit lies in [t_min, t_max].
bool trace_triangle(uint tri, vec3 origin, vec3 dir, float t_min, float t_max, out vec3 tuv) {
    vec3 a = bvh_triangles.t[3u * tri].xyz;
    vec3 e1 = bvh_triangles.t[3u * tri + 1u].xyz - a;
    vec3 e2 = bvh_triangles.t[3u * tri + 2u].xyz - a;
    vec3 p = cross(dir, e2);
    float det = dot(e1, p);
    tuv = vec3(0.0);
    if (abs(det) < 1e-12) {
        return false;
    }
    float inv = 1.0 / det;
    vec3 s = origin - a;
    float u = dot(s, p) * inv;
    if (u < 0.0 || u > 1.0) {
        return false;
    }
    vec3 q = cross(s, e1);
    float v = dot(dir, q) * inv;
    if (v < 0.0 || u + v > 1.0) {
        return false;
    }
    float t = dot(e2, q) * inv;
    tuv = vec3(t, u, v);
    return t >= t_min && t <= t_max;
}

// 1 / dir with zero components replaced by a huge value of the right sign (no NaN in slabs).
vec3 trace_inverse(vec3 dir) {
    vec3 safe = mix(dir, vec3(1e-30), lessThan(abs(dir), vec3(1e-30)));
    return 1.0 / safe;
}

// Traverses the BVH; with `any_hit` returns at the first hit found (occlusion), otherwise
// keeps the closest.
bool trace_traverse(vec3 origin, vec3 dir, float t_min, float t_max, bool any_hit, out TraceHit hit) {
    hit.t = t_max;
    hit.u = 0.0;
    hit.v = 0.0;
    hit.triangle = 0xffffffffu;
    hit.leaf_triangle = 0xffffffffu;
    vec3 inv_dir = trace_inverse(dir);
    if (trace_box(0u, origin, inv_dir, t_min, t_max) < 0.0) {
        return false;
    }
    uint stack[TRACE_STACK_SIZE];
    uint sp = 0u;
    uint node = 0u;
    bool found = false;
    while (true) {
        vec4 lo = bvh_nodes.n[2u * node];
        vec4 hi = bvh_nodes.n[2u * node + 1u];
        uint count = floatBitsToUint(hi.w);
        uint first = floatBitsToUint(lo.w);
        if (count > 0u) {
            for (uint i = first; i < first + count; ++i) {
                vec3 tuv;
                if (trace_triangle(i, origin, dir, t_min, hit.t, tuv)) {
                    hit.t = tuv.x;
                    hit.u = tuv.y;
                    hit.v = tuv.z;
                    hit.leaf_triangle = i;
                    found = true;
                    if (any_hit) {
                        break;
                    }
                }
            }
            if (found && any_hit) {
                break;
            }
        } else {
            uint left = node + 1u;
            uint right = first;
            float tl = trace_box(left, origin, inv_dir, t_min, hit.t);
            float tr = trace_box(right, origin, inv_dir, t_min, hit.t);
            if (tl >= 0.0 && tr >= 0.0) {
                bool left_first = tl <= tr;
                if (sp < TRACE_STACK_SIZE) {
                    stack[sp] = left_first ? right : left;
                    sp += 1u;
                }
                node = left_first ? left : right;
                continue;
            }
            if (tl >= 0.0) {
                node = left;
                continue;
            }
            if (tr >= 0.0) {
                node = right;
                continue;
            }
        }
        if (sp == 0u) {
            break;
        }
        sp -= 1u;
        node = stack[sp];
    }
    if (found) {
        hit.triangle = floatBitsToUint(bvh_triangles.t[3u * hit.leaf_triangle].w);
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

// Geometric normal (unnormalised, by winding: front face is counter-clockwise) of a BVH
// triangle, by its leaf index.
vec3 trace_geometric_normal(uint leaf_triangle) {
    vec3 a = bvh_triangles.t[3u * leaf_triangle].xyz;
    vec3 b = bvh_triangles.t[3u * leaf_triangle + 1u].xyz;
    vec3 c = bvh_triangles.t[3u * leaf_triangle + 2u].xyz;
    return cross(b - a, c - a);
}

// A ray origin moved off a surface at p along its unit geometric normal n (towards the side
// the new ray leaves to), against self-intersection; scaled with the coordinates' magnitude.
vec3 trace_offset(vec3 p, vec3 n) {
    float scale = 1.0 + max(max(abs(p.x), abs(p.y)), abs(p.z));
    return p + n * (1e-4 * scale);
}

#endif
