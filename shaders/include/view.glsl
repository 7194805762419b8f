// The view a raster pass draws from (camera for the G-buffer, light for the RSM): push
// constants shared by gbuffer.vert and the fragment shaders (112 bytes).
#ifndef VIEW_GLSL
#define VIEW_GLSL

layout(push_constant) uniform View {
    mat4 view_proj;
    // Linear view depth of world point p: dot(depth_plane.xyz, p) + depth_plane.w.
    vec4 depth_plane;
    // Eye (camera or light) position.
    vec4 eye;
    // RSM only: x = per-texel solid-angle factor (perspective) or texel area (orthographic),
    // y = 1 for orthographic, z = light index.
    vec4 params;
} view;

#endif
