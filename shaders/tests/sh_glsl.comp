// Runs every per-pixel function of sh.glsl on a buffer of cases so tests/sh_glsl.rs can compare
// them with shine-sh on the same inputs (docs/architecture.md, "Conventions": one formula in Rust, one in GLSL, tied by a
// test). Layouts are documented in tests/sh_glsl.rs.
//! variant bands2 SH_BANDS=2
//! variant bands3 SH_BANDS=3
//! variant bands4 SH_BANDS=4
//! variant bands6 SH_BANDS=6
#version 460
#extension GL_GOOGLE_include_directive : require
#include "sh.glsl"

layout(local_size_x = 32) in;

#define IN_STRIDE (16 + 2 * SH_COEFFS)
#if SH_BANDS <= 4
#define OUT_STRIDE (5 * SH_COEFFS + 4 * SH_BANDS + SH_EVEN_COEFFS + 6)
#else
#define OUT_STRIDE (3 * SH_COEFFS + 4 * SH_BANDS + SH_EVEN_COEFFS + 6)
#endif

layout(set = 0, binding = 0, std430) readonly buffer Cases {
    float v[];
} cases;

layout(set = 0, binding = 1, std430) buffer Results {
    float v[];
} results;

layout(push_constant) uniform Push {
    uint count;
} push;

uint o;

void put(float x) {
    results.v[o] = x;
    o += 1u;
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    uint b = i * uint(IN_STRIDE);
    vec3 dir = vec3(cases.v[b], cases.v[b + 1u], cases.v[b + 2u]);
    float cos_a = cases.v[b + 3u];
    float phong_n = cases.v[b + 4u];
    float window = cases.v[b + 5u];
    float radius = cases.v[b + 6u];
    float half_angle = cases.v[b + 7u];
    vec3 hvl_normal = vec3(cases.v[b + 8u], cases.v[b + 9u], cases.v[b + 10u]);
    float hvl_distance = cases.v[b + 11u];
    vec3 receiver_normal = vec3(cases.v[b + 12u], cases.v[b + 13u], cases.v[b + 14u]);
    float f[SH_COEFFS];
    float g[SH_COEFFS];
    for (int k = 0; k < SH_COEFFS; ++k) {
        f[k] = cases.v[b + 16u + uint(k)];
        g[k] = cases.v[b + 16u + uint(SH_COEFFS + k)];
    }
    o = i * uint(OUT_STRIDE);

    vec3 d = normalize(dir);
    float y[SH_COEFFS];
    sh_basis(d, y);
    for (int k = 0; k < SH_COEFFS; ++k) put(y[k]);

    float zh[SH_BANDS];
    sh_cap_zh(cos_a, zh);
    for (int l = 0; l < SH_BANDS; ++l) put(zh[l]);

    float cap[SH_COEFFS];
    sh_cap(d, cos_a, cap);
    for (int k = 0; k < SH_COEFFS; ++k) put(cap[k]);

    put(sh_dot(f, g));
    put(sh_evaluate(f, dir));

    float cosine[SH_BANDS];
    sh_clamped_cosine_zh(cosine);
    for (int l = 0; l < SH_BANDS; ++l) put(cosine[l]);

    float phong[SH_BANDS];
    sh_phong_zh(phong_n, phong);
    for (int l = 0; l < SH_BANDS; ++l) put(phong[l]);

    float conv[SH_COEFFS];
    sh_convolve(f, phong, conv);
    for (int k = 0; k < SH_COEFFS; ++k) put(conv[k]);

    sh_apply_window_sinc_zh(zh, window);
    for (int l = 0; l < SH_BANDS; ++l) put(zh[l]);

    // shine_sh::hvl::geometric_factor (eq. 21) from its parts
    float facing = max(0.0, dot(normalize(hvl_normal), -d));
    float cap_fraction = hvl_hemisphere_cap_fraction(dot(normalize(receiver_normal), d), half_angle);
    put(hvl_geometric_factor_of(facing, cap_fraction, radius));
    put(hvl_cap_half_angle(hvl_distance, radius));

    float even[SH_EVEN_COEFFS];
    sh_basis_even(d, even);
    for (int k = 0; k < SH_EVEN_COEFFS; ++k) put(even[k]);

    float cos_a_terms;
    float h = hvl_cap_terms(hvl_distance, radius, dot(normalize(receiver_normal), d), cos_a_terms);
    put(cos_a_terms);
    put(h);

#if SH_BANDS <= 4
    float prod[SH_COEFFS];
    sh_product(f, g, prod);
    for (int k = 0; k < SH_COEFFS; ++k) put(prod[k]);

    float e[SH_COEFFS];
    sh_exp_hyb(f, e);
    for (int k = 0; k < SH_COEFFS; ++k) put(e[k]);
#endif
}
