// Traced specular reflections (issue 21, item 3; src/passes/specular.rs): the part of each
// G-buffer pixel's GGX lobe that is sharper than the SH techniques resolve. Per pixel,
// `samples` half vectors drawn from D(h)·(n·h) (sample_ggx_half) give directions
// l = reflect(-v, h) with the solid-angle density D·(n·h)/(4 v·h); a sample adds
// f_s(l, v)·(n·l)·L(l)/pdf, f_s the GGX term of brdf_metallic_roughness. L(l) is next-event
// estimation to the punctual lights at the first hit through the BVH (path.glsl), plus, in a
// scene with an environment, one cosine-sampled ray from the hit that sees it (f·π·L_env when
// unoccluded), or the environment where the ray escapes: the one-bounce light the path-traced
// reference sees in a mirror. Emission of the hit surfaces adds nothing (the GI techniques'
// convention). With push.options.x (specular.regularise) a hit's BRDF is evaluated no sharper
// than the receiver's roughness (path regularisation, Kaplanyan and Dachsbacher 2013, as AAF's
// hit_roughness_min): a point light's highlight on a mirror, seen through a rough lobe, is
// blurred by that lobe anyway, and unregularised it is found by one ray in hundreds.
// The mean is weighted by specular_trace_weight(roughness, limit): pixels rougher than the
// limit keep their SH glossy term and are skipped here. With the denoiser after it
// (config.z = 1, src/passes/denoise.rs) alpha holds the samples' mean parallax d / (z + d)
// (d the hit distance, 1 where a ray escapes; z the pixel's distance from the eye), the
// footprint of the reflection the filter spans; else 0. No CPU twin: tests/specular.rs checks
// the pass against the path tracer.
// A pixel's rays are split over dispatches of at most push.options.z rays each
// (shine::passes::specular::RAYS_PER_DISPATCH): lavapipe ends every loop of an invocation after
// 65 535 iterations in all (docs/pitfalls.md), and each ray's traversals are loops. Variant
// `whole` traces every ray in one dispatch; `first`, `middle` and `last` carry the sums from
// one dispatch to the next in `partial_sum` (rgb: radiance, a: parallax) and `partial_met`
// (the rays that met the lobe), in f32, so the split changes no bit of the sums' order.
//! variant whole
//! variant first PARTIAL_OUT=1
//! variant middle PARTIAL_IN=1 PARTIAL_OUT=1
//! variant last PARTIAL_IN=1
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
#define ENVIRONMENT_BINDING 19
#define ENVIRONMENT_SAMPLER_BINDING 20
#include "environment.glsl"
#include "denoise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// shine::passes::specular::SpecularPush (64 bytes).
layout(push_constant) uniform Push {
    // x: width, y: height, z: light count, w: seed (varies per frame).
    uvec4 frame;
    // xyz: camera position, w: the roughness limit of the pass.
    vec4 camera;
    // x: samples per pixel, y: 1 when the environment lights the hits, z: 1 to store the
    // parallax in alpha (the denoiser follows), w: 1 to share the frame's x · traced-pixels
    // rays by the lobes' widths (`budget`, denoise_ray_count).
    uvec4 config;
    // x: 1 to regularise the paths (a hit's roughness at least the receiver's), y: the first
    // ray of this dispatch, z: the most rays of one dispatch, w: padding.
    uvec4 options;
} push;

#define PATH_LIGHT_COUNT push.frame.z
#define PATH_FLAGS 0u
#include "path.glsl"

layout(set = 0, binding = 9, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 10, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 11, rgba16f) readonly uniform image2D gb_geometric_normal;
layout(set = 0, binding = 15, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 16, rgba8) readonly uniform image2D gb_material;
#ifdef PARTIAL_IN
layout(set = 0, binding = 22, rgba32f) readonly uniform image2D partial_sum_in;
layout(set = 0, binding = 23, r32f) readonly uniform image2D partial_met_in;
#endif
#ifdef PARTIAL_OUT
layout(set = 0, binding = 24, rgba32f) writeonly uniform image2D partial_sum;
layout(set = 0, binding = 25, r32f) writeonly uniform image2D partial_met;
#else
layout(set = 0, binding = 12, rgba16f) writeonly uniform image2D specular;
#endif
// specular_budget_total.comp: the frame's total claim on the rays and its traced pixels.
layout(set = 0, binding = 21, std430) readonly buffer Budget {
    vec2 total;
} budget;

// Writes what this dispatch leaves: the sums for the next one, or the pixel's radiance (the
// sum over its `samples` rays times the trace share) and mean parallax.
void finish(ivec2 ixy, vec3 sum, float parallax, float parallax_count, float share, uint samples) {
#ifdef PARTIAL_OUT
    imageStore(partial_sum, ixy, vec4(sum, parallax));
    imageStore(partial_met, ixy, vec4(parallax_count));
#else
    float alpha = push.config.z != 0u ? (parallax_count > 0.0 ? parallax / parallax_count : 1.0) : 0.0;
    imageStore(specular, ixy, samples > 0u ? vec4(share * sum / float(samples), alpha) : vec4(0.0));
#endif
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, push.frame.xy))) {
        return;
    }
    ivec2 ixy = ivec2(pixel);
    vec4 position = imageLoad(gb_position, ixy);
    vec2 roughness_metallic = imageLoad(gb_material, ixy).rg;
    float share = specular_trace_weight(roughness_metallic.x, push.camera.w);
    vec3 n = normalize(imageLoad(gb_normal, ixy).xyz);
    vec3 v = normalize(push.camera.xyz - position.xyz);
    if (position.w == 0.0 || share <= 0.0 || dot(n, v) <= 0.0) {
        finish(ixy, vec3(0.0), 0.0, 0.0, 0.0, 0u);
        return;
    }
    vec3 ng = normalize(imageLoad(gb_geometric_normal, ixy).xyz);
    vec3 origin = trace_offset(position.xyz, ng);
    vec3 albedo = imageLoad(gb_albedo, ixy).rgb;
    float a = brdf_alpha(roughness_metallic.x);
    uint samples = max(push.config.x, 1u);
    if (push.config.w != 0u) {
        // Its own stream (the samples' streams below restart per sample).
        rng_state = pcg(pcg(pixel.x ^ pcg(push.frame.w ^ 0x9e3779b9u)) + pixel.y);
        samples = denoise_rays(a, share, samples, budget.total.y, budget.total.x, rand());
    }
    vec3 sum = vec3(0.0);
    float eye_distance = length(push.camera.xyz - position.xyz);
    float parallax = 0.0;
    float parallax_count = 0.0;
#ifdef PARTIAL_IN
    vec4 carried = imageLoad(partial_sum_in, ixy);
    sum = carried.rgb;
    parallax = carried.a;
    parallax_count = imageLoad(partial_met_in, ixy).r;
#endif
    uint first = push.options.y;
    uint end = min(samples, first + max(push.options.z, 1u));
    for (uint s = first; s < end; ++s) {
        rng_state = pcg(pcg(pcg(pixel.x ^ pcg(push.frame.w)) + pixel.y) + s);
        vec3 h = sample_ggx_half(n, a, vec2(rand(), rand()));
        vec3 l = reflect(-v, h);
        float nl = dot(n, l);
        float vh = dot(v, h);
        if (nl <= 0.0 || vh <= 0.0 || dot(ng, l) <= 0.0) {
            continue;
        }
        float nh = max(dot(n, h), 1e-6);
        float pdf = ggx_distribution(nh, a) * nh / (4.0 * vh);
        vec3 diffuse;
        vec3 f_s;
        brdf_metallic_roughness_parts(n, l, v, albedo, roughness_metallic.y, roughness_metallic.x, diffuse, f_s);
        TraceHit hit;
        vec3 incoming;
        parallax_count += 1.0;
        if (trace_closest(origin, l, 0.0, PT_FAR, hit)) {
            parallax += hit.t / (eye_distance + hit.t);
            Vertex x = shade(hit, l);
            if (push.options.x != 0u) {
                // Path regularisation: the hit's lobe no sharper than the receiver's.
                x.s.roughness = max(x.s.roughness, roughness_metallic.x);
            }
            incoming = punctual_lights(x, -l);
            if (push.config.y != 0u) {
                vec3 d = sample_cosine(x.s.normal, vec2(rand(), rand()));
                if (dot(x.geometric_normal, d) > 0.0
                    && !trace_occluded(trace_offset(x.position, x.geometric_normal), d, 0.0, PT_FAR)) {
                    incoming += brdf(x, d, -l) * BRDF_PI * environment_radiance(d);
                }
            }
        } else {
            parallax += 1.0;
            incoming = environment_radiance(l);
        }
        vec3 radiance = pdf > 0.0 ? f_s * nl * incoming / pdf : vec3(0.0);
        if (!any(isnan(radiance)) && !any(isinf(radiance))) {
            sum += radiance;
        }
    }
    finish(ixy, sum, parallax, parallax_count, share, samples);
}
