// Test of trace.glsl (tests/path_trace.rs): one ray per invocation, closest hit and occlusion.
#version 460
#extension GL_GOOGLE_include_directive : require
#define TRACE_NODES_BINDING 0
#define TRACE_TRIANGLES_BINDING 1
#define TRACE_TOP_BINDING 4
#define TRACE_INSTANCES_BINDING 5
#include "trace.glsl"

layout(local_size_x = 64) in;

// Two vec4 per ray: (origin, t_min), (direction, t_max).
layout(set = 0, binding = 2, std430) readonly buffer Rays {
    vec4 r[];
} rays;
// Per ray: (t, u, v, bits of the flat triangle index; t = -1 on a miss), then (occluded, 0, 0, 0).
layout(set = 0, binding = 3, std430) buffer Hits {
    vec4 h[];
} hits;

layout(push_constant) uniform Push {
    uvec4 count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count.x) {
        return;
    }
    vec4 o = rays.r[2u * i];
    vec4 d = rays.r[2u * i + 1u];
    TraceHit hit;
    bool found = trace_closest(o.xyz, d.xyz, o.w, d.w, hit);
    hits.h[2u * i] = found ? vec4(hit.t, hit.u, hit.v, uintBitsToFloat(hit.triangle))
                           : vec4(-1.0, 0.0, 0.0, 0.0);
    hits.h[2u * i + 1u] = vec4(trace_occluded(o.xyz, d.xyz, o.w, d.w) ? 1.0 : 0.0, 0.0, 0.0, 0.0);
}
