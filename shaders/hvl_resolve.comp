// `hvl_resolve` (paper 001 §"GI need not update every frame"; src/passes/hvl/resolve.rs): the
// HVL gather refreshed one receiver of every 2×2 cell per frame, the others carried over from
// the previous frame's resolved light, reprojected with the G-buffer's motion vectors. History
// is rejected where the receiver was not visible then (disocclusion: linear depth off by more
// than RESOLVE_DEPTH_TOLERANCE, or normals apart by more than acos RESOLVE_NORMAL_COS); such a
// receiver takes its cell's fresh value. Refreshed receivers blend the fresh value into the history with
// weight RESOLVE_ALPHA; the others keep their history. CPU twin:
// shine::reference::resolve::resolve_cpu.
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "hvl_resolve.glsl"

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
// This frame's gather: valid at the refreshed receivers only.
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D fresh;
// Full-resolution motion (uv now minus uv then).
layout(set = 0, binding = 3, rg16f) readonly uniform image2D gb_motion;
// The previous frame's resolved light and its receivers' (normal, linear depth).
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D history_light;
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D history_geometry;
// This frame's resolved light and geometry (next frame's history).
layout(set = 0, binding = 6, rgba16f) uniform image2D resolved;
layout(set = 0, binding = 7, rgba16f) uniform image2D resolved_geometry;

// shine::passes::hvl::resolve::ResolvePush
layout(push_constant) uniform Push {
    // receiver buffer size
    uvec2 extent;
    // full-resolution size (gb_motion)
    uvec2 full_extent;
    // 1 + k: the refreshed receiver of every cell is at (k & 1, k >> 1); 0: every receiver
    // was gathered this frame (no history yet): the fresh light passes through
    uint slice;
    // 1 when the history holds the previous frame
    uint has_history;
    uint pad0;
    uint pad1;
} push;

// The refreshed receiver of p's cell.
ivec2 cell_pixel(ivec2 p) {
    uint k = push.slice - 1u;
    ivec2 q = (p / 2) * 2 + ivec2(k & 1u, k >> 1u);
    return min(q, ivec2(push.extent) - 1);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), push.extent))) {
        return;
    }
    vec4 position = imageLoad(recv_position, p);
    if (position.w == 0.0) {
        imageStore(resolved, p, vec4(0.0));
        imageStore(resolved_geometry, p, vec4(0.0));
        return;
    }
    vec3 n = normalize(imageLoad(recv_normal, p).xyz);
    if (push.slice == 0u) {
        imageStore(resolved, p, imageLoad(fresh, p));
        imageStore(resolved_geometry, p, vec4(n, position.w));
        return;
    }
    uint k = push.slice - 1u;
    bool refreshed = (uint(p.x) & 1u) == (k & 1u) && (uint(p.y) & 1u) == (k >> 1u);
    // The full-resolution pixel under the receiver's centre.
    ivec2 full = ivec2((vec2(p) + 0.5) * vec2(push.full_extent) / vec2(push.extent));
    full = min(full, ivec2(push.full_extent) - 1);
    vec2 uv = (vec2(p) + 0.5) / vec2(push.extent);
    vec2 then_uv = uv - imageLoad(gb_motion, full).xy;
    ivec2 q = ivec2(floor(then_uv * vec2(push.extent)));
    bool valid = push.has_history != 0u && all(greaterThanEqual(q, ivec2(0)))
        && all(lessThan(q, ivec2(push.extent)));
    vec4 history = vec4(0.0);
    if (valid) {
        vec4 g = imageLoad(history_geometry, q);
        valid = resolve_same_surface(position.w, n, g.w, g.xyz);
        history = imageLoad(history_light, q);
    }
    vec4 light;
    if (refreshed) {
        light = valid ? mix(history, imageLoad(fresh, p), RESOLVE_ALPHA) : imageLoad(fresh, p);
    } else if (valid) {
        light = history;
    } else {
        light = imageLoad(fresh, cell_pixel(p));
    }
    imageStore(resolved, p, light);
    imageStore(resolved_geometry, p, vec4(n, position.w));
}
