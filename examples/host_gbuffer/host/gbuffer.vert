// The host engine's own G-buffer vertex shader (examples/host_gbuffer/host): world-space vertices.
#version 460

layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;

layout(push_constant) uniform Draw {
    mat4 view_proj;
    vec4 base_color_roughness;
    vec4 light_position_metallic;
    vec4 light_intensity;
    vec4 light_direction_cos_outer;
} draw;

layout(location = 0) out vec3 world_position;
layout(location = 1) out vec3 world_normal;

void main() {
    world_position = position;
    world_normal = normal;
    gl_Position = draw.view_proj * vec4(position, 1.0);
}
