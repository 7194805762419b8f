// `update vertices`: every flattened vertex moved from its mesh space to the world, the first
// pass of a frame (src/passes/update_vertices.rs). The raster passes draw the result; the
// path tracer and every ray read it at hits. CPU twin: shine::gpu_scene::GpuScene's
// `world_vertices` (tests/frames.rs compares them).
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 64) in;

#include "deform.glsl"

// shine::gpu_scene::Vertex, four vec4: (position, material bits), (normal, instance bits),
// tangent, (uv, 0, 0).
layout(set = 0, binding = 0, std430) readonly buffer SourceVertices {
    vec4 v[];
} source_vertices;
layout(set = 0, binding = 1, std430) buffer WorldVertices {
    vec4 v[];
} world_vertices;
// shine::gpu_scene::geometry::DeformInstance: mesh-to-world, normal matrix.
layout(set = 0, binding = 2, std430) readonly buffer DeformInstances {
    mat4 m[];
} deform_instances;

// shine::passes::update_vertices::UpdatePush
layout(push_constant) uniform Push {
    uint vertex_count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.vertex_count) {
        return;
    }
    vec4 position = source_vertices.v[4u * i];
    vec4 normal = source_vertices.v[4u * i + 1u];
    vec4 tangent = source_vertices.v[4u * i + 2u];
    uint instance = floatBitsToUint(normal.w);
    DeformedVertex d = deform_rigid(
        deform_instances.m[2u * instance],
        deform_instances.m[2u * instance + 1u],
        position.xyz,
        normal.xyz,
        tangent);
    world_vertices.v[4u * i] = vec4(d.position, position.w);
    world_vertices.v[4u * i + 1u] = vec4(d.normal, normal.w);
    world_vertices.v[4u * i + 2u] = d.tangent;
    world_vertices.v[4u * i + 3u] = source_vertices.v[4u * i + 3u];
}
