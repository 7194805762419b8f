// World-space scene vertices (src/gpu_scene/mod.rs) through a view: the G-buffer and the RSM.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "view.glsl"

layout(location = 0) in vec3 position;
layout(location = 1) in uint material;
layout(location = 2) in vec3 normal;
layout(location = 3) in vec4 tangent;
layout(location = 4) in vec2 uv;

layout(location = 0) out vec3 v_position;
layout(location = 1) out flat uint v_material;
layout(location = 2) out vec3 v_normal;
layout(location = 3) out vec4 v_tangent;
layout(location = 4) out vec2 v_uv;
layout(location = 5) out float v_depth;

void main() {
    v_position = position;
    v_material = material;
    v_normal = normal;
    v_tangent = tangent;
    v_uv = uv;
    v_depth = dot(view.depth_plane.xyz, position) + view.depth_plane.w;
    gl_Position = view.view_proj * vec4(position, 1.0);
}
