// Direct light (docs/frame.md): every punctual light on the G-buffer with the metallic-
// roughness BRDF, the primary light shadowed through its RSM depth with a PCF kernel (soft
// edges), plus emission.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "scene.glsl"
#include "brdf.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) uniform readonly image2D gb_position;
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D gb_normal;
layout(set = 0, binding = 2, rgba8) uniform readonly image2D gb_albedo;
layout(set = 0, binding = 3, rgba8) uniform readonly image2D gb_material;
layout(set = 0, binding = 4, rgba16f) uniform readonly image2D gb_emissive;
layout(set = 0, binding = 5, std430) readonly buffer Lights {
    Light l[];
} lights;
DEFINE_LOAD_LIGHT(lights)
layout(set = 0, binding = 6) uniform texture2D shadow_depth;
layout(set = 0, binding = 7) uniform sampler shadow_sampler;
layout(set = 0, binding = 8, rgba16f) uniform image2D direct;

layout(push_constant) uniform Push {
    mat4 shadow_view_proj;
    vec4 eye;
    // x: light count, y: primary (shadowed) light or 0xffffffff, z: PCF radius in texels,
    // w: 1 when the frame has a shadow map.
    uvec4 counts;
    // x: depth bias in NDC depth units; y: shadow-map texel size in metres at 1 m from the
    // light (perspective) or in metres (orthographic, z = 1); w: normal offset in texels.
    vec4 shadow;
} push;

// Normal-offset shadow lookup: the receiver point moves along its normal by a few shadow-map
// texels (their world size grows with distance under a perspective light), which removes acne
// on surfaces at grazing angles to the light without a large depth bias.
float shadow_visibility(vec3 p, vec3 n, vec3 light_position) {
    float texel = push.shadow.z > 0.5 ? push.shadow.y : push.shadow.y * distance(p, light_position);
    p += n * texel * push.shadow.w;
    vec4 clip = push.shadow_view_proj * vec4(p, 1.0);
    if (clip.w <= 0.0) {
        return 0.0;
    }
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        return 0.0;
    }
    vec2 texel_uv = 1.0 / vec2(textureSize(sampler2D(shadow_depth, shadow_sampler), 0));
    int r = int(push.counts.z);
    float lit = 0.0;
    float taps = 0.0;
    for (int y = -r; y <= r; ++y) {
        for (int x = -r; x <= r; ++x) {
            float stored = textureLod(sampler2D(shadow_depth, shadow_sampler), uv + vec2(x, y) * texel_uv, 0.0).r;
            lit += (ndc.z - push.shadow.x <= stored) ? 1.0 : 0.0;
            taps += 1.0;
        }
    }
    return lit / taps;
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(direct)))) {
        return;
    }
    vec4 position = imageLoad(gb_position, pixel);
    if (position.w <= 0.0) {
        imageStore(direct, pixel, vec4(0.0));
        return;
    }
    vec3 p = position.xyz;
    vec3 n = normalize(imageLoad(gb_normal, pixel).xyz);
    vec3 albedo = imageLoad(gb_albedo, pixel).rgb;
    vec2 rm = imageLoad(gb_material, pixel).rg;
    vec3 v = normalize(push.eye.xyz - p);
    vec3 radiance = imageLoad(gb_emissive, pixel).rgb;
    for (uint i = 0u; i < push.counts.x; ++i) {
        Light light = load_light(i);
        vec3 l;
        vec3 irradiance;
        if (light.kind == LIGHT_DIRECTIONAL) {
            l = -light.direction;
            irradiance = light.color * light.intensity;
        } else {
            vec3 to_light = light.position - p;
            float d = length(to_light);
            l = to_light / max(d, 1e-6);
            irradiance = light_intensity(light, -l) * light_range_window(light, d) / max(d * d, 1e-8);
        }
        float nl = dot(n, l);
        if (nl <= 0.0) {
            continue;
        }
        float visibility = 1.0;
        if (i == push.counts.y && push.counts.w == 1u) {
            visibility = shadow_visibility(p, n, light.position);
        }
        radiance += brdf_metallic_roughness(n, l, v, albedo, rm.y, rm.x) * irradiance * nl * visibility;
    }
    imageStore(direct, pixel, vec4(radiance, 1.0));
}
