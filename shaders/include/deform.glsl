// Vertex deformation: a mesh-space vertex morphed, then skinned or placed rigidly in the
// world. GLSL twin of shine_scene::Scene::instance_vertices (crates/scene/src/pose.rs, glTF
// 2.0 §3.7.2.2 and §3.7.3), line by line; tests/frames.rs ties them.
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
    float inv = 1.0 / sqrt(dot(v, v));
    return (isinf(inv) || isnan(inv) || inv <= 0.0) ? fallback : v * inv;
}

// shine_scene::skin_matrix: S = Σ_k weight_k · jointMatrix[joint_k].
mat4 deform_skin_matrix(mat4 j0, mat4 j1, mat4 j2, mat4 j3, vec4 weights) {
    return j0 * weights.x + j1 * weights.y + j2 * weights.z + j3 * weights.w;
}

// Places a (morphed, renormalised) vertex with `m`: positions by m, normals by the inverse
// transpose of its 3×3, tangents by its 3×3.
DeformedVertex deform_place(mat4 m, vec3 p, vec3 n, vec4 t) {
    mat3 m3 = mat3(m);
    DeformedVertex d;
    d.position = (m * vec4(p, 1.0)).xyz;
    d.normal = deform_normalize_or(transpose(inverse(m3)) * n, vec3(0.0, 1.0, 0.0));
    d.tangent = vec4(deform_normalize_or(m3 * t.xyz, vec3(1.0, 0.0, 0.0)), t.w);
    return d;
}

#endif
