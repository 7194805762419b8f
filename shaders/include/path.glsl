// Paths through the scene, shared by the reference path tracer (path_trace.comp) and AAF's
// sampling pass (aaf_sample.comp): the scene's vertex, index and light buffers (bindings 4-6),
// the surface at a ray hit, the BRDF, next-event estimation to the punctual lights with shadow
// rays, and the random numbers of random.glsl.
//
// The includer includes surface.glsl, brdf.glsl and trace.glsl first, and defines
// PATH_LIGHT_COUNT (the number of lights) and PATH_FLAGS (PT_* bits) as expressions.
#ifndef PATH_GLSL
#define PATH_GLSL

// Bindings 0-3 (materials, srgb_textures, linear_textures, texture_sampler): surface.glsl.
// GpuScene::vertices: four vec4 per vertex, (position, material bits), (normal, 0), tangent,
// (uv, 0, 0). With PATH_SCENE_TEXELS defined the vertices, indices and lights are read from
// images holding copies of those buffers (`vertex_texels` RGBA32F, `index_texels` R32UI,
// `light_texels` RGBA32F; rows of TRACE_ROW_TEXELS, as trace.glsl's): llvmpipe loads a
// storage buffer lane by lane, an image texel in one gather (docs/pitfalls.md).
#ifdef PATH_SCENE_TEXELS
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D vertex_texels;
layout(set = 0, binding = 5, r32ui) readonly uniform uimage2D index_texels;
layout(set = 0, binding = 6, rgba32f) readonly uniform image2D light_texels;

// vec4 k of the vertices.
vec4 path_vertex(uint k) {
    return imageLoad(vertex_texels, trace_texel(k));
}

// Index k of the flattened index buffer.
uint path_index(uint k) {
    return imageLoad(index_texels, trace_texel(k)).x;
}

Light load_light(uint i) {
    vec4 a = imageLoad(light_texels, trace_texel(4u * i));
    vec4 b = imageLoad(light_texels, trace_texel(4u * i + 1u));
    vec4 c = imageLoad(light_texels, trace_texel(4u * i + 2u));
    vec4 d = imageLoad(light_texels, trace_texel(4u * i + 3u));
    Light light;
    light.position = a.xyz;
    light.kind = floatBitsToUint(a.w);
    light.direction = b.xyz;
    light.range = b.w;
    light.color = c.xyz;
    light.intensity = c.w;
    light.inner_cone_angle = d.x;
    light.outer_cone_angle = d.y;
    light.node = floatBitsToUint(d.z);
    light.pad = 0u;
    return light;
}
#else
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

// vec4 k of the vertices.
vec4 path_vertex(uint k) {
    return vertices.v[k];
}

// Index k of the flattened index buffer.
uint path_index(uint k) {
    return indices.i[k];
}
#endif

const uint PT_JITTER = 1u;
const uint PT_EMISSIVE_LIGHTING = 2u;
const uint PT_LAMBERT_ONLY = 4u;
const uint PT_LIGHT_SAMPLING = 8u;
const uint PT_PRIMARY_SPECULAR = 16u;
const float PT_FAR = 1e30;

#include "random.glsl"

struct Vertex {
    vec3 position;
    vec3 geometric_normal;
    Surface s;
};

// The surface at a hit, its geometric normal turned towards the ray's origin.
Vertex shade(TraceHit hit, vec3 dir) {
    uint i0 = path_index(3u * hit.triangle);
    uint i1 = path_index(3u * hit.triangle + 1u);
    uint i2 = path_index(3u * hit.triangle + 2u);
    vec3 b = vec3(1.0 - hit.u - hit.v, hit.u, hit.v);
    Vertex x;
    x.position = b.x * path_vertex(4u * i0).xyz + b.y * path_vertex(4u * i1).xyz + b.z * path_vertex(4u * i2).xyz;
    vec3 n = b.x * path_vertex(4u * i0 + 1u).xyz + b.y * path_vertex(4u * i1 + 1u).xyz + b.z * path_vertex(4u * i2 + 1u).xyz;
    vec4 t = b.x * path_vertex(4u * i0 + 2u) + b.y * path_vertex(4u * i1 + 2u) + b.z * path_vertex(4u * i2 + 2u);
    vec2 uv = b.x * path_vertex(4u * i0 + 3u).xy + b.y * path_vertex(4u * i1 + 3u).xy + b.z * path_vertex(4u * i2 + 3u).xy;
    uint material = floatBitsToUint(path_vertex(4u * i0).w);
    vec3 ng = normalize(hit.normal);
    bool front = dot(ng, dir) < 0.0;
    x.geometric_normal = front ? ng : -ng;
    // Tangent w is ±1 at every vertex: keep the sign.
    t.w = t.w < 0.0 ? -1.0 : 1.0;
    x.s = surface(material, n, t, uv, front);
    return x;
}

vec3 brdf(Vertex x, vec3 l, vec3 v) {
    if ((PATH_FLAGS & PT_LAMBERT_ONLY) != 0u) {
        return x.s.base_color / BRDF_PI;
    }
    return brdf_metallic_roughness(x.s.normal, l, v, x.s.base_color, x.s.metallic, x.s.roughness);
}

// Solid-angle density of `sample_direction`'s choice of l at x (the BRDF's importance sampling).
float brdf_sample_pdf(Vertex x, vec3 l, vec3 v) {
    if ((PATH_FLAGS & PT_LAMBERT_ONLY) != 0u) {
        return max(dot(x.s.normal, l), 0.0) / BRDF_PI;
    }
    float p_specular = brdf_specular_probability(x.s.base_color, x.s.metallic);
    return brdf_pdf(x.s.normal, l, v, p_specular, x.s.roughness);
}

// Punctual light i seen from x: the unit direction l towards it, its distance d (PT_FAR for
// a directional light) and the irradiance it brings to a surface facing it.
void punctual_light(Vertex x, uint i, out vec3 l, out float d, out vec3 irradiance) {
    Light light = load_light(i);
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
}

// The shadow ray's end short of a punctual light at distance d (the offset origin is a little
// closer).
float punctual_shadow_end(float d) {
    return d * (1.0 - 1e-5);
}

// Next-event estimation: every punctual light, shadowed by a ray through the BVH.
vec3 punctual_lights(Vertex x, vec3 v) {
    vec3 sum = vec3(0.0);
    vec3 origin = trace_offset(x.position, x.geometric_normal);
    for (uint i = 0u; i < PATH_LIGHT_COUNT; ++i) {
        vec3 l;
        float d;
        vec3 irradiance;
        punctual_light(x, i, l, d, irradiance);
        float nl = dot(x.s.normal, l);
        if (nl <= 0.0 || all(equal(irradiance, vec3(0.0)))) {
            continue;
        }
        if (trace_occluded(origin, l, 0.0, punctual_shadow_end(d))) {
            continue;
        }
        sum += brdf(x, l, v) * irradiance * nl;
    }
    return sum;
}

#endif
