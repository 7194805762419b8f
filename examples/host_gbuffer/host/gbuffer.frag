// The host engine's own G-buffer fragment shader (examples/host_gbuffer/host): normals packed as
// UNORM (n * 0.5 + 0.5), albedo, roughness/metallic, and the host's own direct light (one
// unshadowed spot light, Lambert).
#version 460

layout(location = 0) in vec3 world_position;
layout(location = 1) in vec3 world_normal;

layout(push_constant) uniform Draw {
    mat4 view_proj;
    vec4 base_color_roughness;
    vec4 light_position_metallic;
    vec4 light_intensity;
    vec4 light_direction_cos_outer;
} draw;

layout(location = 0) out vec4 out_normal;
layout(location = 1) out vec4 out_albedo;
layout(location = 2) out vec4 out_material;
layout(location = 3) out vec4 out_direct;

void main() {
    vec3 n = normalize(world_normal);
    vec3 albedo = draw.base_color_roughness.rgb;
    vec3 to_light = draw.light_position_metallic.xyz - world_position;
    float d2 = max(dot(to_light, to_light), 1e-6);
    vec3 l = to_light * inversesqrt(d2);
    float cos_outer = draw.light_direction_cos_outer.w;
    float cone = smoothstep(cos_outer, min(cos_outer + 0.05, 1.0),
                            dot(-l, draw.light_direction_cos_outer.xyz));
    vec3 direct = albedo / 3.14159265 * draw.light_intensity.rgb * max(dot(n, l), 0.0) * cone / d2;
    out_normal = vec4(n * 0.5 + 0.5, 0.0);
    out_albedo = vec4(albedo, 1.0);
    out_material = vec4(draw.base_color_roughness.w, draw.light_position_metallic.w, 0.0, 0.0);
    out_direct = vec4(direct, 1.0);
}
