// Scene data as uploaded by src/gpu_scene/mod.rs: materials and lights (std430 mirrors of
// shine_scene::Material, 80 bytes, and shine_scene::Light, 64 bytes).
#ifndef SCENE_GLSL
#define SCENE_GLSL

const uint NO_TEXTURE = 0xffffffffu;
const uint LIGHT_DIRECTIONAL = 0u;
const uint LIGHT_POINT = 1u;
const uint LIGHT_SPOT = 2u;

struct Material {
    vec4 base_color;
    vec3 emissive;
    float metallic;
    float roughness;
    float normal_scale;
    float alpha_cutoff;
    uint alpha_mode;
    uint base_color_texture;
    uint metallic_roughness_texture;
    uint normal_texture;
    uint emissive_texture;
    uint double_sided;
    uint pad0;
    uint pad1;
    uint pad2;
};

struct Light {
    vec3 position;
    uint kind;
    vec3 direction;
    float range;
    vec3 color;
    float intensity;
    float inner_cone_angle;
    float outer_cone_angle;
    uint node;
    uint pad;
};

// Radiant intensity towards `to_receiver` (unit, from the light) as KHR_lights_punctual:
// colour * intensity * spot cone falloff; directional lights return their illuminance.
vec3 light_intensity(Light light, vec3 to_receiver) {
    vec3 c = light.color * light.intensity;
    if (light.kind == LIGHT_SPOT) {
        float cos_outer = cos(light.outer_cone_angle);
        float cos_inner = cos(light.inner_cone_angle);
        float scale = 1.0 / max(0.001, cos_inner - cos_outer);
        float t = clamp((dot(light.direction, to_receiver) - cos_outer) * scale, 0.0, 1.0);
        c *= t * t;
    }
    return c;
}

// Distance window of KHR_lights_punctual (1 when range is 0, i.e. infinite); the inverse
// square law is applied separately.
float light_range_window(Light light, float d) {
    if (light.range <= 0.0) {
        return 1.0;
    }
    float r = d / light.range;
    float w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
    return w * w;
}

// Declares `Light load_light(uint i)` reading field by field from `buffer_name.l[i]` (a
// whole-struct copy out of a buffer is OpCopyLogical, which naga cannot read).
#define DEFINE_LOAD_LIGHT(buffer_name) \
    Light load_light(uint i) { \
        Light light; \
        light.position = buffer_name.l[i].position; \
        light.kind = buffer_name.l[i].kind; \
        light.direction = buffer_name.l[i].direction; \
        light.range = buffer_name.l[i].range; \
        light.color = buffer_name.l[i].color; \
        light.intensity = buffer_name.l[i].intensity; \
        light.inner_cone_angle = buffer_name.l[i].inner_cone_angle; \
        light.outer_cone_angle = buffer_name.l[i].outer_cone_angle; \
        light.node = buffer_name.l[i].node; \
        light.pad = 0u; \
        return light; \
    }

#endif
