// The G-buffer (docs/frame.md): world position and linear depth, shading normal, albedo,
// roughness/metallic, emission, geometric normal (the interpolated vertex normal, facing the
// viewer, before normal mapping: paper 000's discontinuity filter tests it).
#version 460
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"
#include "surface.glsl"

layout(location = 0) in vec3 v_position;
layout(location = 1) in flat uint v_material;
layout(location = 2) in vec3 v_normal;
layout(location = 3) in vec4 v_tangent;
layout(location = 4) in vec2 v_uv;
layout(location = 5) in float v_depth;

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_material;
layout(location = 4) out vec4 out_emissive;
layout(location = 5) out vec4 out_geometric_normal;

void main() {
    Surface s = surface(v_material, v_normal, v_tangent, v_uv, gl_FrontFacing);
    out_position = vec4(v_position, max(v_depth, 1e-6));
    out_normal = vec4(s.normal, 0.0);
    out_albedo = vec4(s.base_color, 1.0);
    out_material = vec4(s.roughness, s.metallic, 0.0, 0.0);
    out_emissive = vec4(s.emissive, 0.0);
    vec3 ng = normalize(v_normal);
    out_geometric_normal = vec4(gl_FrontFacing ? ng : -ng, 0.0);
}
