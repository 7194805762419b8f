// Automatic exposure (issue 21, item 5; src/passes/exposure.rs): the frame's log-average
// luminance L_avg = exp(mean of log(delta + L)) over every rendered pixel (Reinhard et al.
// 2002, eq. 1) and the exposure key / L_avg that maps it to middle grey, clamped, and adapted
// in log space towards that target by `adaptation` per frame when the previous frame's exposure
// is there. CPU twin: shine::passes::exposure::{log_average, target_exposure, adapt}.
//
// `reduce` (16x16 pixels per workgroup): each workgroup's sum of log(delta + L) and pixel count.
// `resolve` (one workgroup): the sums of every workgroup, then the exposure.
//! variant reduce_direct EXPOSURE_REDUCE=1 INDIRECT=0
//! variant reduce_indirect EXPOSURE_REDUCE=1 INDIRECT=1
//! variant resolve EXPOSURE_RESOLVE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "color.glsl"

layout(local_size_x = 16, local_size_y = 16) in;

// shine::passes::exposure::ExposurePush (32 bytes).
layout(push_constant) uniform Push {
    // rendered size (reduce)
    uvec2 extent;
    // workgroups of the reduce pass (resolve)
    uint partial_count;
    // 1: `previous` holds the last frame's exposure (resolve)
    uint has_history;
    // key (middle grey), adaptation per frame, smallest and largest exposure
    float key;
    float adaptation;
    float min_exposure;
    float max_exposure;
} push;

// shine::passes::exposure::LUMINANCE_FLOOR: delta of Reinhard's log average
const float EXPOSURE_LUMINANCE_FLOOR = 1e-4;

#ifdef EXPOSURE_REDUCE
layout(set = 0, binding = 0, rgba16f) readonly uniform image2D direct;
#if INDIRECT
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D indirect_full;
#endif
// x: sum of log(delta + L), y: pixels, per workgroup
layout(set = 0, binding = 2, std430) buffer Partials {
    vec2 p[];
} partials;
#else
layout(set = 0, binding = 2, std430) readonly buffer Partials {
    vec2 p[];
} partials;
// [0]: exposure, [1]: log-average luminance
layout(set = 0, binding = 3, std430) readonly buffer Previous {
    float e[];
} previous;
layout(set = 0, binding = 4, std430) buffer Exposure {
    float e[];
} exposure;
#endif

shared vec2 sums[256];

// Sums `v` over the workgroup; the total is in sums[0] afterwards.
void workgroup_sum(vec2 v) {
    uint i = gl_LocalInvocationIndex;
    sums[i] = v;
    barrier();
    for (uint stride = 128u; stride > 0u; stride >>= 1u) {
        if (i < stride) {
            sums[i] += sums[i + stride];
        }
        barrier();
    }
}

void main() {
#ifdef EXPOSURE_REDUCE
    uvec2 pixel = gl_GlobalInvocationID.xy;
    vec2 v = vec2(0.0);
    if (all(lessThan(pixel, push.extent))) {
        vec3 radiance = imageLoad(direct, ivec2(pixel)).rgb;
#if INDIRECT
        radiance += imageLoad(indirect_full, ivec2(pixel)).rgb;
#endif
        float l = luminance(radiance);
        if (!isnan(l) && !isinf(l)) {
            v = vec2(log(EXPOSURE_LUMINANCE_FLOOR + max(l, 0.0)), 1.0);
        }
    }
    workgroup_sum(v);
    if (gl_LocalInvocationIndex == 0u) {
        partials.p[gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0];
    }
#else
    vec2 v = vec2(0.0);
    for (uint k = gl_LocalInvocationIndex; k < push.partial_count; k += 256u) {
        v += partials.p[k];
    }
    workgroup_sum(v);
    if (gl_LocalInvocationIndex == 0u) {
        float log_average = sums[0].y > 0.0 ? sums[0].x / sums[0].y : log(push.key);
        float target = clamp(push.key / exp(log_average), push.min_exposure, push.max_exposure);
        float e = target;
        if (push.has_history != 0u && previous.e[0] > 0.0) {
            e = exp(mix(log(previous.e[0]), log(target), push.adaptation));
        }
        exposure.e[0] = e;
        exposure.e[1] = exp(log_average);
    }
#endif
}
