// World-space scene vertices (src/gpu_scene/mod.rs) through a view: the G-buffer, the shadow
// maps and the RSM. The `motion` variant (the G-buffer) also places each vertex where it was in
// the previous frame, seen by the previous camera, for the fragment shader's motion vectors.
//! variant plain MOTION=0
//! variant motion MOTION=1
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

#if MOTION
// The previous frame's world vertices (same indices).
layout(set = 0, binding = 4, std430) readonly buffer PrevVertices {
    vec4 v[];
} prev_vertices;
// shine::frame::motion::MotionView: both frames' unjittered world-to-clip matrices.
layout(set = 0, binding = 5, std430) readonly buffer MotionView {
    mat4 previous;
    mat4 current;
} motion_view;
layout(location = 6) out vec4 v_clip;
layout(location = 7) out vec4 v_prev_clip;
#endif

void main() {
    v_position = position;
    v_material = material;
    v_normal = normal;
    v_tangent = tangent;
    v_uv = uv;
    v_depth = dot(view.depth_plane.xyz, position) + view.depth_plane.w;
    gl_Position = view.view_proj * vec4(position, 1.0);
#if MOTION
    v_clip = motion_view.current * vec4(position, 1.0);
    v_prev_clip = motion_view.previous * vec4(prev_vertices.v[4u * uint(gl_VertexIndex)].xyz, 1.0);
#endif
}
