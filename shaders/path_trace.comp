// Reference path tracer (docs/frame.md, "Path-traced reference"): progressive Monte-Carlo
// estimate of the camera's radiance, split into direct, indirect and full, with the materials,
// lights and BRDF of the raster passes. Each dispatch adds `frame.w` samples per pixel to the
// sums in `accumulation` (planes direct | indirect | full, w = samples so far).
//
// Path: the camera ray hits vertex 0; at every vertex the punctual lights are sampled
// (next-event estimation, shadow rays through trace.glsl) and the BRDF is importance-sampled
// (Lambert + GGX mixture, brdf.glsl) for the next ray, which gathers emission and the
// environment where it lands. A contribution that scattered once is direct, more than once is
// indirect; what the camera sees unscattered (emission, background) is direct. `bounces` B
// vertices after the first scatter further (B = 1: one-bounce indirect, what the GI techniques
// compute). No Russian roulette, no clamping; a non-finite sample is dropped.
#version 460
#extension GL_GOOGLE_include_directive : require
#define SURFACE_SAMPLE(tex, uvw) textureLod(sampler2DArray(tex, texture_sampler), uvw, 0.0)
#include "surface.glsl"
#include "brdf.glsl"
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#include "trace.glsl"
#define ENVIRONMENT_BINDING 9
#define ENVIRONMENT_SAMPLER_BINDING 10
#include "environment.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// Bindings 0-3 (materials, srgb_textures, linear_textures, texture_sampler): surface.glsl.
// GpuScene::vertices: four vec4 per vertex, (position, material bits), (normal, 0), tangent,
// (uv, 0, 0).
layout(set = 0, binding = 4, std430) readonly buffer Vertices {
    vec4 v[];
} vertices;
layout(set = 0, binding = 5, std430) readonly buffer Indices {
    uint i[];
} indices;
layout(set = 0, binding = 6, std430) readonly buffer Lights {
    Light l[];
} lights;
DEFINE_LOAD_LIGHT(lights)
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
    vec4 pad;
} push;

const uint PT_JITTER = 1u;
const uint PT_EMISSIVE_LIGHTING = 2u;
const uint PT_LAMBERT_ONLY = 4u;
const float PT_FAR = 1e30;

uint rng_state;

// PCG hash (Jarzynski & Olano 2020).
uint pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float rand() {
    rng_state = pcg(rng_state);
    return float(rng_state >> 8) * (1.0 / 16777216.0);
}

struct Vertex {
    vec3 position;
    vec3 geometric_normal;
    Surface s;
};

vec3 unproject(vec2 ndc, float z) {
    vec4 p = push.inv_view_proj * vec4(ndc, z, 1.0);
    return p.xyz / p.w;
}

// The surface at a hit, its geometric normal turned towards the ray's origin.
Vertex shade(TraceHit hit, vec3 dir) {
    uint i0 = indices.i[3u * hit.triangle];
    uint i1 = indices.i[3u * hit.triangle + 1u];
    uint i2 = indices.i[3u * hit.triangle + 2u];
    vec3 b = vec3(1.0 - hit.u - hit.v, hit.u, hit.v);
    Vertex x;
    x.position = b.x * vertices.v[4u * i0].xyz + b.y * vertices.v[4u * i1].xyz + b.z * vertices.v[4u * i2].xyz;
    vec3 n = b.x * vertices.v[4u * i0 + 1u].xyz + b.y * vertices.v[4u * i1 + 1u].xyz + b.z * vertices.v[4u * i2 + 1u].xyz;
    vec4 t = b.x * vertices.v[4u * i0 + 2u] + b.y * vertices.v[4u * i1 + 2u] + b.z * vertices.v[4u * i2 + 2u];
    vec2 uv = b.x * vertices.v[4u * i0 + 3u].xy + b.y * vertices.v[4u * i1 + 3u].xy + b.z * vertices.v[4u * i2 + 3u].xy;
    uint material = floatBitsToUint(vertices.v[4u * i0].w);
    vec3 ng = normalize(trace_geometric_normal(hit.leaf_triangle));
    bool front = dot(ng, dir) < 0.0;
    x.geometric_normal = front ? ng : -ng;
    // Tangent w is ±1 at every vertex: keep the sign.
    t.w = t.w < 0.0 ? -1.0 : 1.0;
    x.s = surface(material, n, t, uv, front);
    return x;
}

vec3 brdf(Vertex x, vec3 l, vec3 v) {
    if ((push.config.z & PT_LAMBERT_ONLY) != 0u) {
        return x.s.base_color / BRDF_PI;
    }
    return brdf_metallic_roughness(x.s.normal, l, v, x.s.base_color, x.s.metallic, x.s.roughness);
}

// Next-event estimation: every punctual light, shadowed by a ray through the BVH.
vec3 punctual_lights(Vertex x, vec3 v) {
    vec3 sum = vec3(0.0);
    vec3 origin = trace_offset(x.position, x.geometric_normal);
    for (uint i = 0u; i < push.config.y; ++i) {
        Light light = load_light(i);
        vec3 l;
        vec3 irradiance;
        float d;
        if (light.kind == LIGHT_DIRECTIONAL) {
            l = -light.direction;
            irradiance = light.color * light.intensity;
            d = PT_FAR;
        } else {
            vec3 to_light = light.position - x.position;
            d = length(to_light);
            l = to_light / max(d, 1e-6);
            irradiance = light_intensity(light, -l) * light_range_window(light, d) / max(d * d, 1e-8);
        }
        float nl = dot(x.s.normal, l);
        if (nl <= 0.0 || all(equal(irradiance, vec3(0.0)))) {
            continue;
        }
        // The shadow ray stops just short of the light (the offset origin is a little closer).
        if (trace_occluded(origin, l, 0.0, d * (1.0 - 1e-5))) {
            continue;
        }
        sum += brdf(x, l, v) * irradiance * nl;
    }
    return sum;
}

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    uvec2 extent = push.frame.xy;
    if (any(greaterThanEqual(pixel, extent))) {
        return;
    }
    uint bounces = push.config.x;
    uint flags = push.config.z;
    vec3 sum_direct = vec3(0.0);
    vec3 sum_indirect = vec3(0.0);
    for (uint s = 0u; s < push.frame.w; ++s) {
        uint sample_index = push.frame.z + s;
        rng_state = pcg(pcg(pcg(pixel.x ^ pcg(push.config.w)) + pixel.y) + sample_index);
        vec2 jitter = (flags & PT_JITTER) != 0u ? vec2(rand(), rand()) : vec2(0.5);
        vec2 ndc = (vec2(pixel) + jitter) / vec2(extent) * 2.0 - 1.0;
        vec3 near = unproject(ndc, 0.0);
        vec3 origin = near;
        vec3 dir = normalize(unproject(ndc, 0.5) - near);
        vec3 throughput = vec3(1.0);
        vec3 direct = vec3(0.0);
        vec3 indirect = vec3(0.0);
        // `scatters`: surface interactions before the current ray (0 for the camera ray).
        for (uint scatters = 0u; ; ++scatters) {
            TraceHit hit;
            if (!trace_closest(origin, dir, 0.0, PT_FAR, hit)) {
                vec3 env = throughput * environment_radiance(dir);
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
            } else if ((flags & PT_EMISSIVE_LIGHTING) != 0u) {
                if (scatters == 1u) {
                    direct += throughput * x.s.emissive;
                } else {
                    indirect += throughput * x.s.emissive;
                }
            }
            if (scatters > bounces) {
                break;
            }
            vec3 nee = throughput * punctual_lights(x, v);
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
            if ((flags & PT_LAMBERT_ONLY) != 0u) {
                l = sample_cosine(n, xi.xy);
                weight = x.s.base_color;
            } else {
                float p_specular = brdf_specular_probability(x.s.base_color, x.s.metallic);
                l = brdf_sample(n, v, p_specular, x.s.roughness, xi);
                float pdf = brdf_pdf(n, l, v, p_specular, x.s.roughness);
                weight = pdf > 0.0 ? brdf(x, l, v) * max(dot(n, l), 0.0) / pdf : vec3(0.0);
            }
            if (dot(n, l) <= 0.0 || dot(x.geometric_normal, l) <= 0.0 || all(equal(weight, vec3(0.0)))) {
                break;
            }
            throughput *= weight;
            origin = trace_offset(x.position, x.geometric_normal);
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
    float count = float(push.frame.w);
    accumulation.a[p] += vec4(sum_direct, count);
    accumulation.a[plane + p] += vec4(sum_indirect, count);
    accumulation.a[2u * plane + p] += vec4(sum_direct + sum_indirect, count);
}
