// Reference path tracer (docs/frame.md, "Path-traced reference"): progressive Monte-Carlo
// estimate of the camera's radiance, split into direct, indirect and full, with the materials,
// lights and BRDF of the raster passes. Each dispatch adds `frame.w` samples per pixel to the
// sums in `accumulation` (planes direct | indirect | full, w = samples so far).
//
// Path: the camera ray hits vertex 0; at every vertex one light is sampled (next-event
// estimation with one shadow ray through trace.glsl), chosen uniformly among the punctual
// lights and, with PT_LIGHT_SAMPLING, the emissive triangles as one choice (when they light
// the scene: PT_EMISSIVE_LIGHTING) and the environment (when its tables say it has peaks;
// light_sampling.glsl); then the BRDF is importance-sampled (Lambert + GGX mixture, brdf.glsl)
// for the next ray, which gathers emission and the environment where it lands. Both estimates
// of an area light's light are weighted by the power heuristic, the light's density including
// the probability of its choice. A contribution that scattered once is direct, more than
// once is indirect; what the camera sees unscattered (emission, background) is direct. `bounces` B
// vertices after the first scatter further (B = 1: one-bounce indirect, what the GI techniques
// compute). No Russian roulette, no clamping; a non-finite sample is dropped. Variants:
// `environment` samples the environment when its tables say so, `no_environment` never does;
// the `_untextured` ones, for scenes whose materials have no textures, make no lookups.
//! variant no_environment PT_ENVIRONMENT_SAMPLING=0 SURFACE_TEXTURES=1
//! variant environment PT_ENVIRONMENT_SAMPLING=1 SURFACE_TEXTURES=1
//! variant no_environment_untextured PT_ENVIRONMENT_SAMPLING=0 SURFACE_TEXTURES=0
//! variant environment_untextured PT_ENVIRONMENT_SAMPLING=1 SURFACE_TEXTURES=0
#version 460
#extension GL_GOOGLE_include_directive : require
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#define TRACE_TOP_BINDING 12
#define TRACE_INSTANCES_BINDING 13
#include "trace.glsl"
// The scene's materials, vertices, indices, lights and light tables from images that copy
// their buffers (src/reference/mod.rs): llvmpipe loads a storage buffer lane by lane.
#define SURFACE_MATERIAL_TEXELS
#define PATH_SCENE_TEXELS
#define SURFACE_SAMPLE(tex, uvw) textureLod(sampler2DArray(tex, texture_sampler), uvw, 0.0)
#include "surface.glsl"
#include "brdf.glsl"
#define ENVIRONMENT_BINDING 9
#define ENVIRONMENT_SAMPLER_BINDING 10
#include "environment.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 11, std430) buffer Accumulation {
    vec4 a[];
} accumulation;

// PathTraceConstants in src/passes/path_trace.rs (112 bytes).
layout(push_constant) uniform Push {
    // Clip (with the raster's Y flip) to world.
    mat4 inv_view_proj;
    // x: width, y: height, z: index of this dispatch's first sample, w: samples per pixel.
    uvec4 frame;
    // x: bounces B, y: light count, z: flags (PT_*), w: seed.
    uvec4 config;
    // x: the specular limit of PT_PRIMARY_SPECULAR; y, z, w: unused.
    vec4 options;
} push;

// The push constants the loops read, read once per invocation in main: llvmpipe loads a push
// constant read inside a loop lane by lane at every iteration (docs/pitfalls.md).
uint path_light_count;
uint path_flags;
#define PATH_LIGHT_COUNT path_light_count
#define PATH_FLAGS path_flags
#include "path.glsl"
#define LIGHT_TABLES_BINDING 14
#include "light_sampling.glsl"

// The point at clip-space (ndc, z) in the world; `inv_view_proj` is push.inv_view_proj.
vec3 unproject(mat4 inv_view_proj, vec2 ndc, float z) {
    vec4 p = inv_view_proj * vec4(ndc, z, 1.0);
    return p.xyz / p.w;
}

// One light sample's contribution at x (times the path's throughput): the BRDF, the cosine
// and the radiance over the density of its choice, weighted against BRDF sampling when the
// light has an area (`area`; a punctual light's `radiance` is its irradiance and `pdf` the
// probability of choosing it); 0 when l is below either normal or the shadow ray from `from`
// meets something before `t_max`.
vec3 light_contribution(Vertex x, vec3 v, vec3 from, vec3 l, float t_max, vec3 radiance, float pdf, bool area) {
    float nl = dot(x.s.normal, l);
    if (!(pdf > 0.0) || nl <= 0.0 || dot(x.geometric_normal, l) <= 0.0 || all(equal(radiance, vec3(0.0)))) {
        return vec3(0.0);
    }
    if (trace_occluded(from, l, 0.0, t_max)) {
        return vec3(0.0);
    }
    float w = area ? light_mis(pdf, brdf_sample_pdf(x, l, v)) : 1.0;
    return brdf(x, l, v) * radiance * nl / pdf * w;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    uvec4 frame = push.frame;
    uvec4 config = push.config;
    mat4 inv_view_proj = push.inv_view_proj;
    uvec2 extent = frame.xy;
    if (any(greaterThanEqual(pixel, extent))) {
        return;
    }
    path_light_count = config.y;
    path_flags = config.z;
    uint bounces = config.x;
    float specular_limit = push.options.x;
    bool sample_lights = (path_flags & PT_LIGHT_SAMPLING) != 0u;
    bool sample_emitters = sample_lights && (path_flags & PT_EMISSIVE_LIGHTING) != 0u && light_emitter_count() > 0u;
#if PT_ENVIRONMENT_SAMPLING
    bool sample_environment = sample_lights && light_environment_on();
#else
    // The `no_environment` variant, for light tables that do not sample the environment
    // (src/passes/path_trace.rs): none of that code in the loop, where lavapipe would run it
    // for every vertex whatever its condition (23% of the sample loop's instructions).
    const bool sample_environment = false;
#endif
    // Next-event estimation picks one light per vertex, uniformly among the punctual lights,
    // the emissive triangles (one choice; light_sampling.glsl then picks a triangle by power)
    // and the environment: one shadow ray per vertex, as Mitsuba's path tracer casts.
    uint light_choices = path_light_count + (sample_emitters ? 1u : 0u) + (sample_environment ? 1u : 0u);
    float choice_probability = light_choices > 0u ? 1.0 / float(light_choices) : 0.0;
    vec3 sum_direct = vec3(0.0);
    vec3 sum_indirect = vec3(0.0);
    uint seed = pcg(config.w);
    for (uint s = 0u; s < frame.w; ++s) {
        uint sample_index = frame.z + s;
        rng_state = pcg(pcg(pcg(pixel.x ^ seed) + pixel.y) + sample_index);
        vec2 jitter = (path_flags & PT_JITTER) != 0u ? vec2(rand(), rand()) : vec2(0.5);
        vec2 ndc = (vec2(pixel) + jitter) / vec2(extent) * 2.0 - 1.0;
        vec3 near = unproject(inv_view_proj, ndc, 0.0);
        vec3 origin = near;
        vec3 dir = normalize(unproject(inv_view_proj, ndc, 0.5) - near);
        vec3 throughput = vec3(1.0);
        vec3 direct = vec3(0.0);
        vec3 indirect = vec3(0.0);
        // The solid-angle density of the BRDF sample that chose `dir` (after the camera ray).
        float last_pdf = 0.0;
        // `scatters`: surface interactions before the current ray (0 for the camera ray).
        for (uint scatters = 0u; ; ++scatters) {
            TraceHit hit;
            if (!trace_closest(origin, dir, 0.0, PT_FAR, hit)) {
                float w = scatters > 0u && sample_environment ? light_mis(last_pdf, choice_probability * light_environment_pdf(dir)) : 1.0;
                vec3 env = w * throughput * environment_radiance(dir);
                if (scatters <= 1u) {
                    direct += env;
                } else {
                    indirect += env;
                }
                break;
            }
            Vertex x = shade(hit, dir);
            vec3 v = -dir;
            if (scatters == 0u) {
                direct += x.s.emissive;
            } else if ((path_flags & PT_EMISSIVE_LIGHTING) != 0u && any(greaterThan(x.s.emissive, vec3(0.0)))) {
                float w = sample_emitters ? light_mis(last_pdf, choice_probability * light_triangle_pdf(hit.triangle, origin, x.position)) : 1.0;
                if (scatters == 1u) {
                    direct += w * throughput * x.s.emissive;
                } else {
                    indirect += w * throughput * x.s.emissive;
                }
            }
            if (scatters > bounces) {
                break;
            }
            vec3 from = trace_offset(x.position, x.geometric_normal);
            vec3 nee = vec3(0.0);
            if (light_choices > 0u) {
                uint choice = min(uint(rand() * float(light_choices)), light_choices - 1u);
                vec3 xi = vec3(rand(), rand(), rand());
                vec3 l = x.s.normal;
                float t_max = 0.0;
                vec3 radiance = vec3(0.0);
                float pdf = 0.0;
                bool area = true;
                if (choice < path_light_count) {
                    float d;
                    punctual_light(x, choice, l, d, radiance);
                    t_max = punctual_shadow_end(d);
                    pdf = choice_probability;
                    area = false;
                } else if (sample_emitters && choice == path_light_count) {
                    float d;
                    pdf = choice_probability * light_sample_triangle(from, xi, l, d, radiance);
                    t_max = d * (1.0 - 1e-4);
                }
#if PT_ENVIRONMENT_SAMPLING
                else {
                    pdf = choice_probability * light_sample_environment(xi, l);
                    radiance = environment_radiance(l);
                    t_max = PT_FAR;
                }
#endif
                nee = throughput * light_contribution(x, v, from, l, t_max, radiance, pdf, area);
            }
            if (scatters == 0u) {
                direct += nee;
            } else {
                indirect += nee;
            }
            // The next direction.
            vec3 xi = vec3(rand(), rand(), rand());
            vec3 n = x.s.normal;
            vec3 l;
            vec3 weight;
            if ((path_flags & PT_LAMBERT_ONLY) != 0u) {
                l = sample_cosine(n, xi.xy);
                weight = x.s.base_color;
                last_pdf = max(dot(n, l), 0.0) / BRDF_PI;
            } else {
                float p_specular = brdf_specular_probability(x.s.base_color, x.s.metallic);
                l = brdf_sample(n, v, p_specular, x.s.roughness, xi);
                last_pdf = brdf_pdf(n, l, v, p_specular, x.s.roughness);
                vec3 f = brdf(x, l, v);
                if (scatters == 0u && (path_flags & PT_PRIMARY_SPECULAR) != 0u) {
                    // The truth of a GI context's specular output: the camera's surface reflects
                    // through its GGX lobe alone, by the share the traced specular takes.
                    vec3 f_diffuse;
                    brdf_metallic_roughness_parts(n, l, v, x.s.base_color, x.s.metallic, x.s.roughness, f_diffuse, f);
                    f *= specular_trace_weight(x.s.roughness, specular_limit);
                }
                weight = last_pdf > 0.0 ? f * max(dot(n, l), 0.0) / last_pdf : vec3(0.0);
            }
            if (dot(n, l) <= 0.0 || dot(x.geometric_normal, l) <= 0.0 || all(equal(weight, vec3(0.0)))) {
                break;
            }
            throughput *= weight;
            origin = from;
            dir = l;
        }
        if (any(isnan(direct)) || any(isinf(direct)) || any(isnan(indirect)) || any(isinf(indirect))) {
            continue;
        }
        sum_direct += direct;
        sum_indirect += indirect;
    }
    uint plane = extent.x * extent.y;
    uint p = pixel.y * extent.x + pixel.x;
    float count = float(frame.w);
    accumulation.a[p] += vec4(sum_direct, count);
    accumulation.a[plane + p] += vec4(sum_indirect, count);
    accumulation.a[2u * plane + p] += vec4(sum_direct + sum_indirect, count);
}
