// Instant GI with SH-filtered incident radiance (paper 000): the per-VPL and per-pixel formulas
// shared by vpl_sh.comp and sh_filter.comp. CPU twin: shine::reference::igi (same names without
// the igi_ prefix); tests/igi.rs compares the passes built on them with it.
//
// Needs SH_BANDS and sh.glsl (included here).
#ifndef IGI_GLSL
#define IGI_GLSL
#include "sh.glsl"

const float IGI_PI = 3.14159265358979323846;
// Smallest distance a VPL is evaluated at when the clamp is off (keeps 1/d^2 finite).
const float IGI_MIN_DISTANCE = 1e-4;
// Largest Phong exponent of a glossy lobe (sharper lobes are beyond any SH order <= 4 anyway).
const float IGI_PHONG_MAX = 1e4;

// Irradiance-weight E_j of one VPL at a receiver (paper 000 §3.2, a Lambertian VPL of
// Instant Radiosity): the VPL's radiant intensity I = Phi max(0, n_j . -w) / pi over the squared
// distance, clamped: E_j = I / max(d, d_min, rho)^2. w: unit direction receiver -> VPL.
// rho = k r_j is the VPL's footprint (shine's, issue 43; 0 gives the paper's clamp alone): a
// receiver nearer the VPL than its neighbours are apart sees a bounded light instead of a
// 1/d^2 spike that sweeps across the wall as the VPL moves.
// The incident radiance is E_j delta(w): its SH projection (eq. 1) is E_j Y(w).
vec3 igi_vpl_irradiance(vec3 flux, vec3 vpl_normal, vec3 w, float dist, float clamp_distance, float footprint) {
    float cos_sender = max(0.0, -dot(vpl_normal, w));
    float d = max(max(max(dist, clamp_distance), footprint), IGI_MIN_DISTANCE);
    return flux * (cos_sender / (IGI_PI * d * d));
}

// Phong exponent (about the reflected direction) standing for the GGX lobe of a perceptual
// roughness: alpha = roughness^2 as the direct pass, Blinn-Phong exponent 2/alpha^2 - 2
// (Walter et al. 2007), and a quarter of it for a lobe about the reflected direction (the
// half-vector lobe is twice as narrow). Clamped to 1..IGI_PHONG_MAX.
float igi_phong_exponent(float roughness) {
    float a = max(roughness * roughness, 1e-3);
    return clamp(0.5 / (a * a) - 0.5, 1.0, IGI_PHONG_MAX);
}

// Paper 000 §3.3: B_lm = sqrt(4 pi / (2l+1)) r_l Y_lm(w_c). Lambert (§3.3.1) with k_d = 1:
// r_l = clamped-cosine ZH / pi about the shading normal n.
void igi_brdf_lambert(vec3 n, out float b[SH_COEFFS]) {
    float k[SH_BANDS];
    sh_clamped_cosine_zh(k);
    for (int l = 0; l < SH_BANDS; ++l) {
        k[l] /= IGI_PI;
    }
    sh_rotate_zh(k, n, b);
}

// Phong (§3.3.2) with k_s = 1: r_l of the normalised lobe (n+1)/(2 pi) cos^n about the reflected
// direction r.
void igi_brdf_phong(vec3 r, float exponent, out float b[SH_COEFFS]) {
    float k[SH_BANDS];
    sh_phong_zh(exponent, k);
    sh_rotate_zh(k, r, b);
}

// The set of pixel px in an n x m interleaving pattern (paper 000 §2.3): s = (x mod n) + n (y mod m).
uint igi_set(ivec2 px, uvec2 pattern) {
    return uint(px.x) % pattern.x + pattern.x * (uint(px.y) % pattern.y);
}

#endif
