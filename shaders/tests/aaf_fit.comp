// Runs AafFit of aaf.glsl on a buffer of cases so tests/aaf_fit_glsl.rs can compare it with
// shine_sh::aaf::LocalFit. Case (AAF_FIT_CASE_WORDS words): the degree, the neighbour count,
// then per neighbour u, y and its precision p (float bits); result: the fit's value at u = 0
// and its precision.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "aaf.glsl"

layout(local_size_x = 32) in;

// tests/aaf_fit_glsl.rs: CASE_WORDS and NEIGHBOURS_MAX.
const uint AAF_FIT_NEIGHBOURS_MAX = 8u;
const uint AAF_FIT_CASE_WORDS = 2u + 3u * AAF_FIT_NEIGHBOURS_MAX;

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
    uint base = AAF_FIT_CASE_WORDS * i;
    uint degree = cases.v[base];
    uint neighbours = min(cases.v[base + 1u], AAF_FIT_NEIGHBOURS_MAX);
    AafFit fit = aaf_fit_new();
    for (uint k = 0u; k < neighbours; ++k) {
        uint at = base + 2u + 3u * k;
        float y = uintBitsToFloat(cases.v[at + 1u]);
        aaf_fit_add(fit, uintBitsToFloat(cases.v[at]), mat3(vec3(y, 0.0, 0.0), vec3(0.0), vec3(0.0)),
            uintBitsToFloat(cases.v[at + 2u]));
    }
    float value = aaf_fit_value(fit, degree, mat3(-1.0))[0].x;
    results.v[i] = vec2(value, aaf_fit_precision(fit, degree, -1.0));
}
