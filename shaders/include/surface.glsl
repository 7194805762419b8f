// Material evaluation shared by the G-buffer and RSM fragment shaders: textures, normal
// mapping (glTF convention: bitangent = cross(n, t) * w).
#ifndef SURFACE_GLSL
#define SURFACE_GLSL
#include "scene.glsl"

#ifdef SURFACE_MATERIAL_TEXELS
// The materials in an RGBA32F image, five texels each (a copy of the buffer; rows of
// TRACE_ROW_TEXELS: the includer includes trace.glsl first): llvmpipe loads a storage buffer
// lane by lane, an image texel in one gather (docs/pitfalls.md).
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D material_texels;

Material load_material(uint i) {
    vec4 a = imageLoad(material_texels, trace_texel(5u * i));
    vec4 b = imageLoad(material_texels, trace_texel(5u * i + 1u));
    vec4 c = imageLoad(material_texels, trace_texel(5u * i + 2u));
    uvec4 d = floatBitsToUint(imageLoad(material_texels, trace_texel(5u * i + 3u)));
    uvec4 e = floatBitsToUint(imageLoad(material_texels, trace_texel(5u * i + 4u)));
    Material m;
    m.base_color = a;
    m.emissive = b.xyz;
    m.metallic = b.w;
    m.roughness = c.x;
    m.normal_scale = c.y;
    m.alpha_cutoff = c.z;
    m.alpha_mode = floatBitsToUint(c.w);
    m.base_color_texture = d.x;
    m.metallic_roughness_texture = d.y;
    m.normal_texture = d.z;
    m.emissive_texture = d.w;
    m.double_sided = e.x;
    m.pad0 = 0u;
    m.pad1 = 0u;
    m.pad2 = 0u;
    return m;
}
#else
layout(set = 0, binding = 0, std430) readonly buffer Materials {
    Material m[];
} materials;

// Field by field: a whole-struct copy out of a buffer is OpCopyLogical, which naga cannot
// read.
Material load_material(uint i) {
    Material m;
    m.base_color = materials.m[i].base_color;
    m.emissive = materials.m[i].emissive;
    m.metallic = materials.m[i].metallic;
    m.roughness = materials.m[i].roughness;
    m.normal_scale = materials.m[i].normal_scale;
    m.alpha_cutoff = materials.m[i].alpha_cutoff;
    m.alpha_mode = materials.m[i].alpha_mode;
    m.base_color_texture = materials.m[i].base_color_texture;
    m.metallic_roughness_texture = materials.m[i].metallic_roughness_texture;
    m.normal_texture = materials.m[i].normal_texture;
    m.emissive_texture = materials.m[i].emissive_texture;
    m.double_sided = materials.m[i].double_sided;
    m.pad0 = 0u;
    m.pad1 = 0u;
    m.pad2 = 0u;
    return m;
}
#endif
layout(set = 0, binding = 1) uniform texture2DArray srgb_textures;
layout(set = 0, binding = 2) uniform texture2DArray linear_textures;
layout(set = 0, binding = 3) uniform sampler texture_sampler;

// Texture lookups of `surface`: implicit-LOD sampling in fragment shaders; a compute shader
// (no derivatives) defines SURFACE_SAMPLE before the #include, e.g. with textureLod at mip 0.
#ifndef SURFACE_SAMPLE
#define SURFACE_SAMPLE(tex, uvw) texture(sampler2DArray(tex, texture_sampler), uvw)
#endif

// SURFACE_TEXTURES 0 leaves every texture lookup out, for scenes whose materials have none (a
// shader variant): lavapipe runs a lookup whatever its condition, four or five per surface
// (docs/pitfalls.md, "lavapipe runs every branch").
#ifndef SURFACE_TEXTURES
#define SURFACE_TEXTURES 1
#endif

struct Surface {
    vec3 base_color;
    vec3 normal;
    float roughness;
    float metallic;
    vec3 emissive;
};

// Emitted radiance of material `i` at `uv` (both sides emit): the emissive factor times its
// texture.
vec3 surface_emission(uint i, vec2 uv) {
    Material m = load_material(i);
    vec3 e = m.emissive;
    uint emissive_tex = m.emissive_texture;
#if SURFACE_TEXTURES
    if (emissive_tex != NO_TEXTURE) {
        e *= SURFACE_SAMPLE(srgb_textures, vec3(uv, float(emissive_tex))).rgb;
    }
#endif
    return e;
}

Surface surface(uint material_index, vec3 geometric_normal, vec4 tangent, vec2 uv, bool front) {
    Material m = load_material(material_index);
    Surface s;
    s.base_color = m.base_color.rgb;
    uint base_tex = m.base_color_texture;
#if SURFACE_TEXTURES
    if (base_tex != NO_TEXTURE) {
        s.base_color *= SURFACE_SAMPLE(srgb_textures, vec3(uv, float(base_tex))).rgb;
    }
#endif
    s.roughness = m.roughness;
    s.metallic = m.metallic;
    uint mr_tex = m.metallic_roughness_texture;
#if SURFACE_TEXTURES
    if (mr_tex != NO_TEXTURE) {
        vec4 mr = SURFACE_SAMPLE(linear_textures, vec3(uv, float(mr_tex)));
        s.roughness *= mr.g;
        s.metallic *= mr.b;
    }
#endif
    s.emissive = surface_emission(material_index, uv);
    uint normal_tex = m.normal_texture;
    float normal_scale = m.normal_scale;
    vec3 n = normalize(geometric_normal);
    if (!front) {
        n = -n;
    }
#if SURFACE_TEXTURES
    if (normal_tex != NO_TEXTURE) {
        vec3 t = normalize(tangent.xyz - n * dot(n, tangent.xyz));
        vec3 b = cross(n, t) * tangent.w;
        vec3 tn = SURFACE_SAMPLE(linear_textures, vec3(uv, float(normal_tex))).xyz * 2.0 - 1.0;
        tn.xy *= normal_scale;
        n = normalize(tn.x * t + tn.y * b + tn.z * n);
    }
#endif
    s.normal = n;
    return s;
}

#endif
