// Direct light (docs/frame.md): every punctual light on the G-buffer with the metallic-
// roughness BRDF, each shadowed through its tiles of the shadow atlas with a PCF kernel (soft
// edges), plus emission; background pixels show the environment. CPU side: src/passes/direct.rs, src/passes/shadows.rs.
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
layout(set = 0, binding = 6) uniform texture2D shadow_atlas;
layout(set = 0, binding = 7) uniform sampler shadow_sampler;
layout(set = 0, binding = 8, rgba16f) uniform image2D direct;

// shine::passes::shadows::ShadowViewRecord
struct ShadowView {
    mat4 view_proj;
    // xy: tile origin in atlas uv; zw: tile size in atlas uv
    vec4 tile;
    // x: texel size in metres at 1 m (perspective) or absolute (orthographic); y: 1 orthographic
    vec4 params;
};

// shine::passes::shadows::LightShadowRecord
struct LightShadow {
    uint first_view;
    uint view_count;
    uint pad0;
    uint pad1;
};

layout(set = 0, binding = 9, std430) readonly buffer ShadowViews {
    ShadowView v[];
} shadow_views;

layout(set = 0, binding = 10, std430) readonly buffer ShadowLights {
    LightShadow l[];
} shadow_lights;

// The environment seen through background pixels (black without one).
#define ENVIRONMENT_BINDING 11
#define ENVIRONMENT_SAMPLER_BINDING 12
#include "environment.glsl"

layout(push_constant) uniform Push {
    // Clip space of the camera to world, without the camera's translation (background pixels
    // look up the environment along the direction between two unprojected points).
    mat4 inv_view_proj;
    vec4 eye;
    // x: light count, y: PCF radius in texels, z: 1 when the frame has a shadow atlas
    uvec4 counts;
    // x: depth bias in NDC depth units; y: normal offset in texels; zw: one atlas texel in uv
    vec4 shadow;
} push;

// The cube face of a point light that sees direction d (shine::passes::shadows::CUBE_FACES
// order: +x, -x, +y, -y, +z, -z), by d's major axis.
uint cube_face(vec3 d) {
    vec3 a = abs(d);
    if (a.x >= a.y && a.x >= a.z) {
        return d.x >= 0.0 ? 0u : 1u;
    }
    if (a.y >= a.z) {
        return d.y >= 0.0 ? 2u : 3u;
    }
    return d.z >= 0.0 ? 4u : 5u;
}

// Normal-offset PCF lookup in shadow view k: the receiver point moves along its normal by a
// few shadow-map texels (their world size grows with distance under a perspective light),
// which removes acne at grazing angles without a large depth bias; the taps stay inside the
// view's tile. 1 outside the view's frustum (nothing is known there: a spot cone wider than
// the 2.9 rad frustum still lights that ring).
float shadow_view_visibility(uint k, vec3 p, vec3 n, vec3 light_position) {
    mat4 view_proj = shadow_views.v[k].view_proj;
    vec4 tile = shadow_views.v[k].tile;
    vec4 params = shadow_views.v[k].params;
    float texel = params.y > 0.5 ? params.x : params.x * distance(p, light_position);
    p += n * texel * push.shadow.y;
    vec4 clip = view_proj * vec4(p, 1.0);
    if (clip.w <= 0.0) {
        return 1.0;
    }
    vec3 ndc = clip.xyz / clip.w;
    vec2 uv = ndc.xy * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        return 1.0;
    }
    vec2 texel_uv = push.shadow.zw;
    vec2 lo = tile.xy + 0.5 * texel_uv;
    vec2 hi = tile.xy + tile.zw - 0.5 * texel_uv;
    vec2 centre = tile.xy + uv * tile.zw;
    int r = int(push.counts.y);
    float lit = 0.0;
    float taps = 0.0;
    for (int y = -r; y <= r; ++y) {
        for (int x = -r; x <= r; ++x) {
            vec2 at = clamp(centre + vec2(x, y) * texel_uv, lo, hi);
            float stored = textureLod(sampler2D(shadow_atlas, shadow_sampler), at, 0.0).r;
            lit += (ndc.z - push.shadow.x <= stored) ? 1.0 : 0.0;
            taps += 1.0;
        }
    }
    return lit / taps;
}

// Visibility of light i from p: 1 for an unshadowed light, else through its view (the cube
// face facing p for a point light).
float shadow_visibility(uint i, Light light, vec3 p, vec3 n) {
    uint count = shadow_lights.l[i].view_count;
    if (push.counts.z == 0u || count == 0u) {
        return 1.0;
    }
    uint k = shadow_lights.l[i].first_view;
    if (count == 6u) {
        k += cube_face(p - light.position);
    }
    return shadow_view_visibility(k, p, n, light.position);
}

void main() {
    ivec2 pixel = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(pixel, imageSize(direct)))) {
        return;
    }
    vec4 position = imageLoad(gb_position, pixel);
    if (position.w <= 0.0) {
        // Background: the environment along the camera ray through the pixel centre (between
        // two depths in front of the camera, so perspective, infinite and orthographic
        // projections all work).
        vec2 ndc = (vec2(pixel) + 0.5) / vec2(imageSize(direct)) * 2.0 - 1.0;
        vec4 near = push.inv_view_proj * vec4(ndc, 0.0, 1.0);
        vec4 mid = push.inv_view_proj * vec4(ndc, 0.5, 1.0);
        vec3 ray = mid.xyz / mid.w - near.xyz / near.w;
        imageStore(direct, pixel, vec4(environment_radiance(ray), 1.0));
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
        float visibility = shadow_visibility(i, light, p, n);
        radiance += brdf_metallic_roughness(n, l, v, albedo, rm.y, rm.x) * irradiance * nl * visibility;
    }
    imageStore(direct, pixel, vec4(radiance, 1.0));
}
