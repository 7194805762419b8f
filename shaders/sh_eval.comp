// Evaluates the real SH basis (sh.glsl) for a buffer of directions: the first shader of
// shine and the GPU side of the sh.glsl-versus-shine-sh test.
//! variant bands1 SH_BANDS=1
//! variant bands2 SH_BANDS=2
//! variant bands3 SH_BANDS=3
//! variant bands4 SH_BANDS=4
//! variant bands5 SH_BANDS=5
//! variant bands6 SH_BANDS=6
//! variant bands7 SH_BANDS=7
//! variant bands8 SH_BANDS=8
#version 460
#extension GL_GOOGLE_include_directive : require
#include "sh.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Directions {
    vec4 d[];
} directions;

layout(set = 0, binding = 1, std430) buffer Coefficients {
    float c[];
} coefficients;

layout(push_constant) uniform Push {
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    float y[SH_COEFFS];
    sh_basis(normalize(directions.d[i].xyz), y);
    for (int k = 0; k < SH_COEFFS; ++k) {
        coefficients.c[i * SH_COEFFS + k] = y[k];
    }
}
