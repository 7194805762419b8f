// Vertex deformation: a mesh-space vertex placed in the world. GLSL twin of
// shine::gpu_scene::geometry (rigid instances); tests/frames.rs ties them.
#ifndef DEFORM_GLSL
#define DEFORM_GLSL

struct DeformedVertex {
    vec3 position;
    vec3 normal;
    // xyz unit, w the bitangent sign.
    vec4 tangent;
};

// v / |v|, or `fallback` for a zero (or non-finite) vector, as glam's normalize_or.
vec3 deform_normalize_or(vec3 v, vec3 fallback) {
    float inv = inversesqrt(dot(v, v));
    return (isinf(inv) || isnan(inv) || inv <= 0.0) ? fallback : v * inv;
}

// A vertex of a rigid instance: `world` moves positions and tangents, `normal_matrix` (the
// inverse transpose of world's 3×3) normals.
DeformedVertex deform_rigid(mat4 world, mat4 normal_matrix, vec3 p, vec3 n, vec4 t) {
    DeformedVertex d;
    d.position = (world * vec4(p, 1.0)).xyz;
    d.normal = deform_normalize_or(mat3(normal_matrix) * n, vec3(0.0, 1.0, 0.0));
    d.tangent = vec4(deform_normalize_or(mat3(world) * t.xyz, vec3(1.0, 0.0, 0.0)), t.w);
    return d;
}

#endif
