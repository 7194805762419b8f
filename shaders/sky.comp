// Sky light for the frames without proxies, gi = none included (issue 16, item 7; issue 18, item 2;
// src/passes/sky.rs). At every receiver, `rays` cosine-weighted directions about the shading
// normal (k x k strata, k = floor(sqrt(rays)), the rest uniform; a new rotation per receiver
// and frame) traced through the BVH up to `range` (0: unbounded). Their unoccluded share A is
// the cosine-weighted sky visibility (ambient occlusion), their mean direction b the bent
// normal; the pass writes the demodulated light A * max(L~ . Y(b), 0) / pi, L~ the
// environment's SH irradiance (paper 002 §3, src/gpu_scene/environment_sh.rs), which
// shaders/sky_filter.comp filters and multiplies by the receiver's kd. In a uniform environment
// this is exactly the path tracer's sky light; elsewhere the bent normal stands for where the
// open sky lies. Writes RGBA16F, a = 0, 0 on background. No CPU twin: tests/sky.rs checks it
// against the path tracer.
//
// Variant `cavity` (paper 001's cavity shading, issue 18): the same rays, up to a short range,
// multiply the receiver's `light` (HVL's unshadowed indirect light) by A instead.
//! variant sky
//! variant cavity CAVITY=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 3
#include "sh.glsl"
#include "brdf.glsl"
#include "random.glsl"
#define TRACE_NODES_BINDING 6
#define TRACE_TRIANGLES_BINDING 7
#define TRACE_TOP_BINDING 8
#define TRACE_INSTANCES_BINDING 9
#include "trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
#ifndef CAVITY
// EnvironmentSh::gpu_data at 3 bands: L r, g, b, then L~ r, g, b (9 floats each).
layout(set = 0, binding = 4, std430) readonly buffer Environment {
    float e[];
} environment;
#endif
layout(set = 0, binding = 5, rgba16f) writeonly uniform image2D sky;
#ifdef CAVITY
layout(set = 0, binding = 10, rgba16f) readonly uniform image2D light;
#endif

// shine::passes::sky::SkyPush (32 bytes).
layout(push_constant) uniform Push {
    // receiver buffer size
    uvec2 extent;
    // rays per receiver
    uint rays;
    // seed (varies per frame with a history)
    uint seed;
    // 1: the irradiance at the bent normal; 0: at the shading normal
    uint bent_normal;
    // the rays' range (0: unbounded)
    float range;
    uint pad0;
    uint pad1;
} push;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    vec4 position = imageLoad(recv_position, ixy);
    vec3 n = imageLoad(recv_normal, ixy).xyz;
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        imageStore(sky, ixy, vec4(0.0));
        return;
    }
    n = normalize(n);
    vec3 origin = trace_offset(position.xyz, n);
    float range = push.range > 0.0 ? push.range : 1e30;
    uint strata = uint(floor(sqrt(float(push.rays))));
#ifdef CAVITY
    // rays independent of the sky pass's at the same receiver
    rng_state = pcg(pcg(xy.x ^ pcg(push.seed ^ 0x9e3779b9u)) + xy.y);
#else
    rng_state = pcg(pcg(xy.x ^ pcg(push.seed)) + xy.y);
#endif
    vec2 rotation = vec2(rand(), rand());
    vec3 bent = vec3(0.0);
    float open = 0.0;
    for (uint s = 0u; s < push.rays; ++s) {
        vec2 xi = vec2(rand(), rand());
        if (s < strata * strata) {
            xi = (vec2(float(s % strata), float(s / strata)) + xi) / float(strata);
        }
        vec3 d = sample_cosine(n, fract(xi + rotation));
        if (!trace_occluded(origin, d, 0.0, range)) {
            open += 1.0;
            bent += d;
        }
    }
    float visibility = open / float(push.rays);
#ifdef CAVITY
    imageStore(sky, ixy, vec4(imageLoad(light, ixy).rgb * visibility, 0.0));
#else
    vec3 b = push.bent_normal != 0u && dot(bent, bent) > 0.0 ? normalize(bent) : n;
    float y[SH_COEFFS];
    sh_basis(b, y);
    vec3 irradiance = vec3(0.0);
    for (int k = 0; k < SH_COEFFS; ++k) {
        irradiance += y[k] * vec3(environment.e[3 * SH_COEFFS + k], environment.e[4 * SH_COEFFS + k],
            environment.e[5 * SH_COEFFS + k]);
    }
    imageStore(sky, ixy, vec4(visibility * max(irradiance, vec3(0.0)) / SH_PI, 0.0));
#endif
}
