// sh.glsl's sh_rotation + sh_rotation_apply against shine_sh::rotation (tests/igi.rs).
// Case i: floats [12 i .. 12 i + 12) of `rotations` are the columns of a mat3 (xyz of three
// vec4); `inputs` holds SH_COEFFS coefficients per case; `outputs` the rotated ones.
//! variant b2 SH_BANDS=2
//! variant b3 SH_BANDS=3
//! variant b4 SH_BANDS=4
#version 460
#extension GL_GOOGLE_include_directive : require
#include "sh.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Rotations {
    float v[];
} rotations;

layout(set = 0, binding = 1, std430) readonly buffer Inputs {
    float v[];
} inputs;

layout(set = 0, binding = 2, std430) buffer Outputs {
    float v[];
} outputs;

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    uint b = 12u * i;
    mat3 r = mat3(
        vec3(rotations.v[b], rotations.v[b + 1u], rotations.v[b + 2u]),
        vec3(rotations.v[b + 4u], rotations.v[b + 5u], rotations.v[b + 6u]),
        vec3(rotations.v[b + 8u], rotations.v[b + 9u], rotations.v[b + 10u]));
    float c[SH_COEFFS];
    for (int k = 0; k < SH_COEFFS; ++k) {
        c[k] = inputs.v[i * uint(SH_COEFFS) + uint(k)];
    }
    float d[SH_ROT_SIZE];
    sh_rotation(r, d);
    float o[SH_COEFFS];
    sh_rotation_apply(d, c, o);
    for (int k = 0; k < SH_COEFFS; ++k) {
        outputs.v[i * uint(SH_COEFFS) + uint(k)] = o[k];
    }
}
