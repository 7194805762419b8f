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
const uint AAF_SUMS_STRIDE = 5u;
// shine::passes::aaf::ROWS_STRIDE: vec4 per pixel of the filter's rows.
const uint AAF_ROWS_STRIDE = 4u;

// shine_sh::aaf::TANGENT_SCALE (8/3): the irradiance vector over pi of a pixel is
// V = M0 n + AAF_TANGENT_SCALE M1t, M0 the mean of its cosine-weighted samples about n and M1t
// the mean of the samples times their direction's part tangent to n; V . m is the mean at a
// nearby normal m.
const float AAF_TANGENT_SCALE = 2.6666667;

// shine::reference::aaf::WEIGHT_MIN: the least demodulation weight divided by; a pixel whose kd
// sums to less over its channels (a metal) carries no diffuse light.
const float AAF_WEIGHT_MIN = 1e-3;

// Whether the diffuse weight kd carries light (AAF_WEIGHT_MIN).
bool aaf_carries_light(vec3 kd) {
    return kd.r + kd.g + kd.b >= AAF_WEIGHT_MIN;
}

// The share of the incident light a diffuse sample carries, f_d / kd, one number for the three
// channels (their sums' ratio): f_d and kd share the albedo and (1 - metallic), so their ratio
// is the same on every channel for a grey F0 (dielectrics) and stays finite where one channel's
// albedo is 0 (dividing channel by channel would leave that channel's diffuse mean dark and
// darken its neighbours'). 0 where kd carries no light.
float aaf_diffuse_share(vec3 f_d, vec3 kd) {
    return aaf_carries_light(kd) ? (f_d.r + f_d.g + f_d.b) / (kd.r + kd.g + kd.b) : 0.0;
}

// shine_sh::aaf::FIT_CONDITION_MIN
const float AAF_FIT_CONDITION_MIN = 1e-4;

// shine_sh::aaf::LocalFit: one separable filter pass at one pixel as a weighted least-squares
// polynomial fit in u (signed world distance along the axis, in units of beta) with the paper's
// gaussian weights g times each value's precision p (inverse noise variance, in units of one
// pixel's mean); degree 0 is paper 004's normalised gaussian (eq. 16). Nine channels: the
// irradiance vector's x, y, z columns (rgb each), or an rgb value in column 0. v0..v4 are
// sum g w u^k, the fitted value's noise variance (aaf_fit_precision).
struct AafFit {
    float s0, s1, s2, s3, s4;
    mat3 t0, t1, t2;
    float v0, v1, v2, v3, v4;
};

AafFit aaf_fit_new() {
    return AafFit(0.0, 0.0, 0.0, 0.0, 0.0, mat3(0.0), mat3(0.0), mat3(0.0),
        0.0, 0.0, 0.0, 0.0, 0.0);
}

void aaf_fit_add(inout AafFit f, float u, mat3 y, float p) {
    float g = exp(-0.5 * u * u);
    float w = g * p;
    float w1 = w * u;
    float w2 = w1 * u;
    float w3 = w2 * u;
    float w4 = w3 * u;
    f.s0 += w;
    f.s1 += w1;
    f.s2 += w2;
    f.s3 += w3;
    f.s4 += w4;
    f.t0 += w * y;
    f.t1 += w1 * y;
    f.t2 += w2 * y;
    f.v0 += g * w;
    f.v1 += g * w1;
    f.v2 += g * w2;
    f.v3 += g * w3;
    f.v4 += g * w4;
}

// The coefficients c of the fit at u = 0, c.x t0 + c.y t1 + c.z t2, of the highest
// well-conditioned degree up to `degree`; the caller checks for neighbours (s0 > 0).
vec3 aaf_fit_coefficients(AafFit f, uint degree) {
    vec3 c = vec3(1.0 / f.s0, 0.0, 0.0);
    float det2 = f.s0 * (f.s2 * f.s4 - f.s3 * f.s3) - f.s1 * (f.s1 * f.s4 - f.s2 * f.s3)
        + f.s2 * (f.s1 * f.s3 - f.s2 * f.s2);
    float det1 = f.s0 * f.s2 - f.s1 * f.s1;
    if (degree >= 2u && det2 > AAF_FIT_CONDITION_MIN * f.s0 * f.s2 * f.s4) {
        c = vec3(f.s2 * f.s4 - f.s3 * f.s3, f.s2 * f.s3 - f.s1 * f.s4, f.s1 * f.s3 - f.s2 * f.s2) / det2;
    } else if (degree >= 1u && det1 > AAF_FIT_CONDITION_MIN * f.s0 * f.s2) {
        c = vec3(f.s2 / det1, -f.s1 / det1, 0.0);
    }
    return c;
}

// The fit at u = 0, not clamped (the irradiance vector's components are signed); `fallback`
// without neighbours.
mat3 aaf_fit_value(AafFit f, uint degree, mat3 fallback) {
    if (f.s0 <= 0.0) {
        return fallback;
    }
    vec3 c = aaf_fit_coefficients(f, degree);
    return c.x * f.t0 + c.y * f.t1 + c.z * f.t2;
}

// The precision of the fit at u = 0 (shine_sh::aaf::LocalFit::precision); `fallback` without
// neighbours or where the inverse is not finite.
float aaf_fit_precision(AafFit f, uint degree, float fallback) {
    if (f.s0 <= 0.0) {
        return fallback;
    }
    vec3 c = aaf_fit_coefficients(f, degree);
    float variance = c.x * c.x * f.v0 + 2.0 * c.x * c.y * f.v1
        + (c.y * c.y + 2.0 * c.x * c.z) * f.v2 + 2.0 * c.y * c.z * f.v3 + c.z * c.z * f.v4;
    float inverse = 1.0 / variance;
    return variance > 0.0 && !isinf(inverse) ? inverse : fallback;
}

#endif
