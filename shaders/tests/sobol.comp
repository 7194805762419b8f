// Runs sobol_02 of random.glsl on a buffer of cases so tests/sequence_glsl.rs can compare it
// with shine_sh::sequence::sobol_02. Case: index, shift.x, shift.y (uints); result: the point.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "random.glsl"

layout(local_size_x = 32) in;

layout(set = 0, binding = 0, std430) readonly buffer Cases {
    uint v[];
} cases;

layout(set = 0, binding = 1, std430) buffer Results {
    vec2 v[];
} results;

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    results.v[i] = sobol_02(cases.v[3u * i], uvec2(cases.v[3u * i + 1u], cases.v[3u * i + 2u]));
}
