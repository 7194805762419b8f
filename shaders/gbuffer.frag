// The G-buffer (docs/frame.md): world position and linear depth, shading normal, albedo,
// roughness/metallic, emission, geometric normal (the interpolated vertex normal, facing the
// viewer, before normal mapping: paper 000's discontinuity filter tests it), motion (where the
// surface point was in the previous frame, as an offset in texture coordinates: uv now minus uv
// then, jitter excluded).
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
layout(location = 6) in vec4 v_clip;
layout(location = 7) in vec4 v_prev_clip;

layout(location = 0) out vec4 out_position;
layout(location = 1) out vec4 out_normal;
layout(location = 2) out vec4 out_albedo;
layout(location = 3) out vec4 out_material;
layout(location = 4) out vec4 out_emissive;
layout(location = 5) out vec4 out_geometric_normal;
layout(location = 6) out vec4 out_motion;

void main() {
    Surface s = surface(v_material, v_normal, v_tangent, v_uv, gl_FrontFacing);
    out_position = vec4(v_position, max(v_depth, 1e-6));
    out_normal = vec4(s.normal, 0.0);
    out_albedo = vec4(s.base_color, 1.0);
    out_material = vec4(s.roughness, s.metallic, 0.0, 0.0);
    out_emissive = vec4(s.emissive, 0.0);
    vec3 ng = normalize(v_normal);
    out_geometric_normal = vec4(gl_FrontFacing ? ng : -ng, 0.0);
    // Clip to NDC to uv: the y axes of Vulkan NDC and of images both point down.
    vec2 now = v_clip.xy / v_clip.w;
    vec2 then = v_prev_clip.xy / v_prev_clip.w;
    out_motion = vec4(0.5 * (now - then), 0.0, 0.0);
}
