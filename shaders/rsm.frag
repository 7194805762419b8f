// Reflective shadow map of the primary light (docs/frame.md, paper 003 §3 after Dachsbacher
// and Stamminger): world position, normal and the flux each texel's patch reflects.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"
#include "surface.glsl"

layout(set = 0, binding = 4, std430) readonly buffer Lights {
    Light l[];
} lights;
DEFINE_LOAD_LIGHT(lights)

layout(location = 0) in vec3 v_position;
layout(location = 1) in flat uint v_material;
layout(location = 2) in vec3 v_normal;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec2 v_uv;
layout(location = 5) in float v_depth;

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_flux;

void main() {
    Surface s = surface(v_material, v_normal, v_tangent, v_uv, gl_FrontFacing);
    Light light = load_light(uint(view.params.z));
    vec3 power;
    if (view.params.y > 0.5) {
        // Directional: illuminance E over the texel's footprint A_t perpendicular to the light.
        power = light.color * light.intensity * view.params.x;
    } else {
        // Spot/point: I(w) times the texel's solid angle, (2 tan(fov/2) / S)^2 cos^3(alpha),
        // alpha the angle to the view's axis (depth_plane.xyz is the unit forward direction:
        // the spot's direction, or towards the scene for a point light).
        vec3 w = normalize(v_position - view.eye.xyz);
        float cos_axis = max(dot(w, normalize(view.depth_plane.xyz)), 0.0);
        float omega = view.params.x * cos_axis * cos_axis * cos_axis;
        power = light_intensity(light, w) * omega * light_range_window(light, distance(v_position, view.eye.xyz));
    }
    out_position = vec4(v_position, 1.0);
    out_normal = vec4(normalize(v_normal) * (gl_FrontFacing ? 1.0 : -1.0), 0.0);
    out_flux = vec4(s.base_color * power, 0.0);
}
