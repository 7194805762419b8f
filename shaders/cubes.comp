// Tiny environment cubes (issue 18, item 3; paper 001, "Environment maps"; src/passes/cubes.rs):
// one 6x6x6 cube of incoming light per dynamic object (a node with proxies), used as a cheap
// indirect mode for the object's receivers.
//
// FILL and SMOOTH run over the cubes of this frame's refresh list (all of them, or a slice and
//   the ones whose object or light moved; src/frame/cubes.rs); the others keep last frame's.
// FILL: per cube texel, CUBE_SAMPLES rays from the centre of the object's bounding sphere
//   through fixed points of the texel (2x2 strata), starting where they leave the own proxy
//   spheres that hold the centre; a later hit inside one of the object's own proxy spheres is
//   stepped over (up to CUBE_SELF_HITS times), so the object does not see itself.
//   The paper paints objects as z-buffered pixels over a sky dome; a ray through the BVH is the
//   same nearest-surface test over the whole scene. A ray that escapes sees the environment; a
//   hit sends what it reflects of the one-bounce light the path tracer counts: next-event
//   estimation to the punctual lights and, in a scene with an environment, one cosine-sampled
//   ray towards it (fixed seed per texel and sample: no noise over time).
// SMOOTH: the paper's smoothing, per texel t of direction n:
//   Lbar(n) = sum_s L_s max(0, n . d_s) w_s / sum_s max(0, n . d_s) w_s,
//   w_s = 1 as published, or the texel's solid angle (push.config.z = 1).
// SHADE: at every receiver inside one of a cube's spheres (its object's proxies), the outgoing
//   diffuse radiance kd * Lbar(n) (E = pi Lbar, kd / pi * E; kd from brdf_indirect_weights):
//   Lbar of the smoothed texel holding n (the paper's lookup), or the smoothing sum evaluated
//   at n itself (push.config.y = 1: seamless, 216 multiply-adds). Other receivers keep the
//   technique's light. Writes RGBA16F at receiver resolution. tests/cubes.rs checks the cubes
//   against the path tracer.
//! variant fill FILL=1
//! variant smooth SMOOTH=1
//! variant shade SHADE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "cube.glsl"

// Rays per texel of the fill (2x2 strata): shine::passes::cubes::SAMPLES.
const uint CUBE_SAMPLES = 4u;
// Hits on the object's own proxies a fill ray steps over before it gives up (black); each step
// leaves every own sphere holding the hit, so a ray needs at most one per own sphere.
const uint CUBE_SELF_HITS = 8u;
// An own proxy, grown by this share of its radius (and 1e-5), holds the object's triangles; a
// larger margin would reach under the floor an object rests on.
const float CUBE_SELF_MARGIN = 1e-3;

#ifdef FILL
#define SURFACE_SAMPLE(tex, uvw) textureLod(sampler2DArray(tex, texture_sampler), uvw, 0.0)
#include "surface.glsl"
#include "brdf.glsl"
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#define TRACE_TOP_BINDING 17
#define TRACE_INSTANCES_BINDING 18
#include "trace.glsl"
#define ENVIRONMENT_BINDING 19
#define ENVIRONMENT_SAMPLER_BINDING 20
#include "environment.glsl"
#else
#include "brdf.glsl"
#endif

layout(local_size_x = 8, local_size_y = 8) in;

// shine::passes::cubes::CubesPush (48 bytes).
layout(push_constant) uniform Push {
    // FILL: x refreshed cubes, y light count, z 1 when the environment lights the hits.
    // SMOOTH: x refreshed cubes. SHADE: xy receiver extent, z sphere count, w 1 with a light
    // input.
    uvec4 frame;
    // SHADE: xyz camera position.
    vec4 camera;
    // y: 1 = look up at the normal (SHADE); z: 1 = solid-angle weights (FILL);
    // w: 1 = write the mask of the cubes' receivers instead of light (SHADE).
    uvec4 config;
} push;

#ifdef FILL
#define PATH_LIGHT_COUNT push.frame.y
#define PATH_FLAGS 0u
#include "path.glsl"
#endif

#ifdef FILL
// shine::passes::cubes::GpuCube: the bounding sphere (centre, radius), then the first of its
// object's spheres and their count
struct Cube {
    vec4 sphere;
    uvec4 spheres;
};
layout(set = 0, binding = 9, std430) readonly buffer Cubes {
    Cube c[];
} cubes;
#endif

#if defined(FILL) || defined(SMOOTH)
// the indices of this frame's refreshed cubes
layout(set = 0, binding = 15, std430) readonly buffer Refresh {
    uint r[];
} refresh;
#endif

#if defined(FILL) || defined(SHADE)
// shine::passes::cubes::GpuCubeSphere: (centre, radius), then (the index of its object's
// cube, as a float, 0, 0, 0)
layout(set = 0, binding = 12, std430) readonly buffer Spheres {
    vec4 s[];
} spheres;
#endif

// CUBE_TEXELS texels per cube, written by FILL: rgb the radiance times the texel's weight in
// the smoothing sum, a that weight (its solid angle, or 1 for the paper's plain sum)
layout(set = 0, binding = 10, std430)
#ifndef FILL
readonly
#endif
buffer Radiance {
    vec4 r[];
} radiance;

#if defined(SMOOTH) || defined(SHADE)
// Lbar per cube texel, written by SMOOTH
layout(set = 0, binding = 11, std430)
#ifdef SHADE
readonly
#endif
buffer Smoothed {
    vec4 s[];
} smoothed;

// The smoothing sum of cube `cube` evaluated at the unit direction n.
vec3 cube_smoothed(uint cube, vec3 n) {
    vec3 sum = vec3(0.0);
    float weight_sum = 0.0;
    for (uint t = 0u; t < CUBE_TEXELS; ++t) {
        float c = max(dot(n, cube_texel_direction(t, vec2(0.5))), 0.0);
        vec4 texel = radiance.r[cube * CUBE_TEXELS + t];
        sum += c * texel.rgb;
        weight_sum += c * texel.a;
    }
    return weight_sum > 0.0 ? sum / weight_sum : vec3(0.0);
}
#endif

#ifdef SHADE
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D recv_albedo;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D recv_material;
layout(set = 0, binding = 13, rgba16f) readonly uniform image2D light;
layout(set = 0, binding = 14, rgba16f) writeonly uniform image2D shaded;
#endif

#ifdef FILL
// Where the ray centre + t d leaves `sphere` (grown by CUBE_SELF_MARGIN) if the point at
// t = `at` lies inside it; else 0.
float cube_own_exit(vec4 sphere, vec3 centre, vec3 d, float at) {
    vec3 oc = centre - sphere.xyz;
    float r = sphere.w * (1.0 + CUBE_SELF_MARGIN) + 1e-5;
    vec3 p = oc + at * d;
    if (dot(p, p) > r * r) {
        return 0.0;
    }
    float b = dot(oc, d);
    return -b + sqrt(max(b * b - (dot(oc, oc) - r * r), 0.0));
}
#endif

void main() {
#ifdef FILL
    uint t = gl_GlobalInvocationID.x;
    if (t >= CUBE_TEXELS || gl_GlobalInvocationID.y >= push.frame.x) {
        return;
    }
    uint cube = refresh.r[gl_GlobalInvocationID.y];
    vec3 centre = cubes.c[cube].sphere.xyz;
    uvec2 own = cubes.c[cube].spheres.xy;
    vec3 sum = vec3(0.0);
    for (uint k = 0u; k < CUBE_SAMPLES; ++k) {
        vec2 s = (vec2(k & 1u, k >> 1u) + 0.5) * 0.5;
        vec3 d = cube_texel_direction(t, s);
        rng_state = pcg(pcg(t ^ pcg(cube)) + k);
        TraceHit hit;
        // Start where the ray leaves the own spheres that hold the centre (a ball's one proxy:
        // at its surface), so most rays never meet their own object.
        float t_min = 0.0;
        for (uint i = own.x; i < own.x + own.y; ++i) {
            t_min = max(t_min, cube_own_exit(spheres.s[2u * i], centre, d, 0.0));
        }
        bool found = false;
        bool escaped = false;
        for (uint step = 0u; step < CUBE_SELF_HITS; ++step) {
            found = trace_closest(centre, d, t_min, PT_FAR, hit);
            if (!found) {
                escaped = true;
                break;
            }
            // past every own sphere that holds the hit (none: the hit is another surface)
            float exit = 0.0;
            for (uint i = own.x; i < own.x + own.y; ++i) {
                exit = max(exit, cube_own_exit(spheres.s[2u * i], centre, d, hit.t));
            }
            if (exit <= hit.t) {
                break;
            }
            t_min = exit;
            found = false;
        }
        if (found) {
            Vertex x = shade(hit, d);
            vec3 incoming = punctual_lights(x, -d);
            if (push.frame.z != 0u) {
                vec3 e = sample_cosine(x.s.normal, vec2(rand(), rand()));
                if (dot(x.geometric_normal, e) > 0.0
                    && !trace_occluded(trace_offset(x.position, x.geometric_normal), e, 0.0, PT_FAR)) {
                    incoming += brdf(x, e, -d) * BRDF_PI * environment_radiance(e);
                }
            }
            if (!any(isnan(incoming)) && !any(isinf(incoming))) {
                sum += incoming;
            }
        } else if (escaped) {
            sum += environment_radiance(d);
        }
    }
    float weight = push.config.z != 0u ? cube_texel_solid_angle(t) : 1.0;
    radiance.r[cube * CUBE_TEXELS + t] = vec4(weight * sum / float(CUBE_SAMPLES), weight);
#endif
#ifdef SMOOTH
    uint t = gl_GlobalInvocationID.x;
    if (t >= CUBE_TEXELS || gl_GlobalInvocationID.y >= push.frame.x) {
        return;
    }
    uint cube = refresh.r[gl_GlobalInvocationID.y];
    smoothed.s[cube * CUBE_TEXELS + t] = vec4(cube_smoothed(cube, cube_texel_direction(t, vec2(0.5))), 0.0);
#endif
#ifdef SHADE
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.frame.xy))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    vec4 base = push.frame.w != 0u ? imageLoad(light, ixy) : vec4(0.0);
    vec4 position = imageLoad(recv_position, ixy);
    vec3 n = imageLoad(recv_normal, ixy).xyz;
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        imageStore(shaded, ixy, push.config.w != 0u ? vec4(0.0) : base);
        return;
    }
    n = normalize(n);
    // the first sphere holding the receiver (with a margin for the proxies' fit) names its cube
    int cube = -1;
    for (uint i = 0u; i < push.frame.z; ++i) {
        vec4 sphere = spheres.s[2u * i];
        vec3 off = position.xyz - sphere.xyz;
        float r = sphere.w * 1.01 + 1e-4;
        if (dot(off, off) <= r * r) {
            cube = int(spheres.s[2u * i + 1u].x);
            break;
        }
    }
    if (cube < 0) {
        imageStore(shaded, ixy, push.config.w != 0u ? vec4(0.0) : base);
        return;
    }
    if (push.config.w != 0u) {
        imageStore(shaded, ixy, vec4(1.0, 1.0, 1.0, 0.0));
        return;
    }
    vec3 lbar = push.config.y != 0u
        ? cube_smoothed(uint(cube), n)
        : smoothed.s[uint(cube) * CUBE_TEXELS + cube_texel_of(n)].rgb;
    vec3 albedo = imageLoad(recv_albedo, ixy).rgb;
    float metallic = imageLoad(recv_material, ixy).g;
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, metallic, dot(n, normalize(push.camera.xyz - position.xyz)), kd, ks);
    imageStore(shaded, ixy, vec4(kd * lbar, 0.0));
#endif
}
