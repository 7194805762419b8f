// Paper 004's filter width and sampling rate per pixel: the GLSL twin of shine_sh::aaf (tied by
// tests/aaf.rs through the aaf_beta pass). z_min, z_max: nearest and farthest reflector seen
// from the pixel; d: world-space size of the pixel at the receiver (A_p = d^2). The includer
// includes brdf.glsl first.
#ifndef AAF_GLSL
#define AAF_GLSL

// shine_sh::aaf::blinn_phong_exponent: m = 2 / alpha^2 - 2 of GGX alpha = roughness^2
// (Walter et al. 2007), clamped to the fit's range [0, 50] of eq. 24.
float aaf_blinn_phong_exponent(float roughness) {
    float alpha = max(roughness * roughness, 1e-3);
    return clamp(2.0 / (alpha * alpha) - 2.0, 0.0, 50.0);
}

// shine_sh::aaf::receiver_bandlimit: the diffuse Omega_h blended by metallic towards the
// Blinn-Phong bandlimit 3.6 + 0.084 m (eq. 24, paper 004), never below Omega_h.
float aaf_receiver_bandlimit(float omega_h, float roughness, float metallic) {
    float glossy = 3.6 + 0.084 * aaf_blinn_phong_exponent(roughness);
    return omega_h + (max(glossy, omega_h) - omega_h) * clamp(metallic, 0.0, 1.0);
}

// eq. 15, paper 004: Omega_x^r = mu min(Omega_h / z_min, alpha / d).
float aaf_filter_bandwidth(float omega_h, float z_min, float d, float alpha, float mu) {
    return mu * min(omega_h / z_min, alpha / d);
}

// eq. 16, paper 004: beta = 2 / Omega_x^r, the world-space standard deviation of the filter.
float aaf_filter_width(float omega_r) {
    return 2.0 / omega_r;
}

// eq. 21, paper 004: n = gamma (mu Omega_h d / z_min + alpha)^2 Omega_h^2 (1 + mu z_max / z_min)^2.
float aaf_samples_per_pixel(float omega_h, float z_min, float z_max, float d, float alpha, float mu, float gamma) {
    float a = mu * omega_h * d / z_min + alpha;
    float b = 1.0 + mu * z_max / z_min;
    return gamma * a * a * omega_h * omega_h * b * b;
}

// shine::passes::aaf::SUMS_STRIDE: vec4 per pixel of the sampling passes' sums.
const uint AAF_SUMS_STRIDE = 2u;

// shine::reference::aaf::WEIGHT_MIN: the least demodulation weight divided by; a pixel whose kd
// is below it on every channel (a metal) carries no diffuse light.
const float AAF_WEIGHT_MIN = 1e-3;

// Whether the diffuse weight kd carries light (AAF_WEIGHT_MIN).
bool aaf_carries_light(vec3 kd) {
    return any(greaterThanEqual(kd, vec3(AAF_WEIGHT_MIN)));
}

// shine_sh::aaf::FIT_CONDITION_MIN
const float AAF_FIT_CONDITION_MIN = 1e-4;

// shine_sh::aaf::LocalFit: one separable filter pass at one pixel as a weighted least-squares
// polynomial fit in u (signed world distance along the axis, in units of beta) with the paper's
// gaussian weights; degree 0 is paper 004's normalised gaussian (eq. 16).
struct AafFit {
    float s0, s1, s2, s3, s4;
    vec3 t0, t1, t2;
};

AafFit aaf_fit_new() {
    return AafFit(0.0, 0.0, 0.0, 0.0, 0.0, vec3(0.0), vec3(0.0), vec3(0.0));
}

void aaf_fit_add(inout AafFit f, float u, vec3 y) {
    float w = exp(-0.5 * u * u);
    float w1 = w * u;
    float w2 = w1 * u;
    float w3 = w2 * u;
    f.s0 += w;
    f.s1 += w1;
    f.s2 += w2;
    f.s3 += w3;
    f.s4 += w3 * u;
    f.t0 += w * y;
    f.t1 += w1 * y;
    f.t2 += w2 * y;
}

// The fit at u = 0 of the highest well-conditioned degree up to `degree`, clamped at 0;
// `fallback` without neighbours.
vec3 aaf_fit_value(AafFit f, uint degree, vec3 fallback) {
    if (f.s0 <= 0.0) {
        return fallback;
    }
    float det2 = f.s0 * (f.s2 * f.s4 - f.s3 * f.s3) - f.s1 * (f.s1 * f.s4 - f.s2 * f.s3)
        + f.s2 * (f.s1 * f.s3 - f.s2 * f.s2);
    if (degree >= 2u && det2 > AAF_FIT_CONDITION_MIN * f.s0 * f.s2 * f.s4) {
        vec3 a = f.t0 * (f.s2 * f.s4 - f.s3 * f.s3) - f.t1 * (f.s1 * f.s4 - f.s2 * f.s3)
            + f.t2 * (f.s1 * f.s3 - f.s2 * f.s2);
        return max(a / det2, vec3(0.0));
    }
    float det1 = f.s0 * f.s2 - f.s1 * f.s1;
    if (degree >= 1u && det1 > AAF_FIT_CONDITION_MIN * f.s0 * f.s2) {
        return max((f.t0 * f.s2 - f.t1 * f.s1) / det1, vec3(0.0));
    }
    return max(f.t0 / f.s0, vec3(0.0));
}

#endif
