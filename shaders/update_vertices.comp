// `update vertices`: every flattened vertex morphed, then skinned or placed by its instance, in
// the world vertex buffer; the first pass of a frame (src/passes/update_vertices.rs). The
// raster passes draw the result; every ray reads it at hits. CPU twin:
// shine_scene::Scene::instance_vertices (tests/frames.rs compares them).
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
// shine::gpu_scene::geometry::DeformInstance, ten vec4: world (4), normal matrix (4),
// (skin's first joint or ~0, first delta, target count, first weight), (first vertex, count).
layout(set = 0, binding = 2, std430) readonly buffer DeformInstances {
    vec4 v[];
} deform_instances;
// shine::gpu_scene::geometry::SkinVertex: (joints), (weights) per vertex.
layout(set = 0, binding = 3, std430) readonly buffer SkinVertices {
    uvec4 v[];
} skin_vertices;
// The frame's joint matrices, every skin's concatenated.
layout(set = 0, binding = 4, std430) readonly buffer JointMatrices {
    mat4 m[];
} joint_matrices;
// Morph deltas: (position delta, 0), (normal delta, 0) per vertex and target.
layout(set = 0, binding = 5, std430) readonly buffer MorphDeltas {
    vec4 v[];
} morph_deltas;
// The frame's morph weights, every morphing instance's concatenated.
layout(set = 0, binding = 6, std430) readonly buffer MorphWeights {
    float w[];
} morph_weights;

// shine::passes::update_vertices::UpdatePush
layout(push_constant) uniform Push {
    uint vertex_count;
} push;

const uint NO_SKIN = 0xffffffffu;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.vertex_count) {
        return;
    }
    vec4 position = source_vertices.v[4u * i];
    vec4 normal = source_vertices.v[4u * i + 1u];
    vec4 tangent = source_vertices.v[4u * i + 2u];
    uint instance = floatBitsToUint(normal.w);
    uint base = 10u * instance;
    mat4 world = mat4(deform_instances.v[base], deform_instances.v[base + 1u],
                      deform_instances.v[base + 2u], deform_instances.v[base + 3u]);
    uvec4 deform = floatBitsToUint(deform_instances.v[base + 8u]);
    uvec4 range = floatBitsToUint(deform_instances.v[base + 9u]);

    // 1. Morph: base plus weighted deltas (targets of zero weight skipped, as on the CPU).
    vec3 p = position.xyz;
    vec3 n = normal.xyz;
    uint local = i - range.x;
    for (uint k = 0u; k < deform.z; ++k) {
        float w = morph_weights.w[deform.w + k];
        if (w == 0.0) {
            continue;
        }
        uint d = 2u * (deform.y + k * range.y + local);
        p += w * morph_deltas.v[d].xyz;
        n += w * morph_deltas.v[d + 1u].xyz;
    }
    n = deform_normalize_or(n, vec3(0.0, 1.0, 0.0));

    // 2. Skin (a skinned instance's vertex with influences), else 3. rigid placement.
    vec4 weights = uintBitsToFloat(skin_vertices.v[2u * i + 1u]);
    mat4 m = world;
    if (deform.x != NO_SKIN && any(notEqual(weights, vec4(0.0)))) {
        uvec4 joints = skin_vertices.v[2u * i] + deform.x;
        m = deform_skin_matrix(joint_matrices.m[joints.x], joint_matrices.m[joints.y],
                               joint_matrices.m[joints.z], joint_matrices.m[joints.w], weights);
    }
    DeformedVertex o = deform_place(m, p, n, tangent);
    world_vertices.v[4u * i] = vec4(o.position, position.w);
    world_vertices.v[4u * i + 1u] = vec4(o.normal, normal.w);
    world_vertices.v[4u * i + 2u] = o.tangent;
    world_vertices.v[4u * i + 3u] = source_vertices.v[4u * i + 3u];
}
