// HVL near field (src/passes/hvl/near.rs): the light a receiver gets from surfaces closer than
// 2R, traced, where HVLs cannot give it. An HVL's sphere caps its light near its centre, so a
// receiver a few centimetres from a lit wall (a room's corners, the base of a box) misses most
// of that wall's light. Split every sender point y by its distance t from the receiver with
// the weight f(t) = smoothstep(R, 2R, t) (hvl_far_weight): the gather takes f(d) of each
// HVL's diffuse light (d its centre's distance), this pass the rest,
//   E_near = pi / N * sum_k (1 - f(t_k)) L(y_k -> x)
// over N cosine-weighted rays (t_k < 2R), L the light the hit reflects towards the receiver
// from the punctual lights (next-event estimation with shadow rays, path.glsl). Together they
// are the split of Kollig and Keller's bias compensation (2004) at a smooth boundary. Writes
// the demodulated light E_near / pi (RGBA16F, 0 on background) and in a the rays' mean hit
// distance (2R for a ray that meets nothing within 2R: the denoiser's footprint,
// src/passes/denoise.rs); the denoiser (or sky_filter.comp) filters it and multiplies by kd.
#version 460
#extension GL_GOOGLE_include_directive : require
#define SURFACE_SAMPLE(tex, uvw) textureLod(sampler2DArray(tex, texture_sampler), uvw, 0.0)
#include "surface.glsl"
#include "brdf.glsl"
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#define TRACE_TOP_BINDING 17
#define TRACE_INSTANCES_BINDING 18
#include "trace.glsl"
#include "hvl_near.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// shine::passes::hvl::near::NearPush (32 bytes).
layout(push_constant) uniform Push {
    // receiver buffer size
    uvec2 extent;
    // rays per receiver
    uint rays;
    // seed of the rays
    uint seed;
    // lights in the light buffer
    uint light_count;
    // R: the near field's inner radius (world units); rays reach 2R
    float range;
    uint pad0;
    uint pad1;
} push;

#define PATH_LIGHT_COUNT push.light_count
#define PATH_FLAGS 0u
#include "path.glsl"

layout(set = 0, binding = 9, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 10, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 12, rgba16f) writeonly uniform image2D near_light;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    vec4 position = imageLoad(recv_position, ixy);
    vec3 n = imageLoad(recv_normal, ixy).xyz;
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        imageStore(near_light, ixy, vec4(0.0));
        return;
    }
    n = normalize(n);
    vec3 origin = trace_offset(position.xyz, n);
    float range = push.range;
    uint strata = uint(floor(sqrt(float(push.rays))));
    rng_state = pcg(pcg(xy.x ^ pcg(push.seed ^ 0x5bd1e995u)) + xy.y);
    vec2 rotation = vec2(rand(), rand());
    vec3 sum = vec3(0.0);
    float reach = 0.0;
    for (uint s = 0u; s < push.rays; ++s) {
        vec2 xi = vec2(rand(), rand());
        if (s < strata * strata) {
            xi = (vec2(float(s % strata), float(s / strata)) + xi) / float(strata);
        }
        vec3 d = sample_cosine(n, fract(xi + rotation));
        TraceHit hit;
        if (!trace_closest(origin, d, 0.0, 2.0 * range, hit)) {
            reach += 2.0 * range;
            continue;
        }
        reach += hit.t;
        float near = 1.0 - hvl_far_weight(hit.t, range);
        if (near <= 0.0) {
            continue;
        }
        vec3 l = punctual_lights(shade(hit, d), -d);
        if (!any(isnan(l)) && !any(isinf(l))) {
            sum += near * l;
        }
    }
    float rays = float(max(push.rays, 1u));
    imageStore(near_light, ixy, vec4(sum / rays, reach / rays));
}
