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

// The receiver's demodulation weight w = kd + ks (brdf_indirect_weights at n.v, never below
// 1e-3): the samples store the BRDF-weighted radiance over w, the filter smooths that, and the
// result is multiplied by w again (paper 004 filters irradiance before albedo modulation; w
// extends it to the specular part of the metallic-roughness BRDF).
// CPU twin: shine::reference::aaf::demodulation.
vec3 aaf_demodulation(vec3 albedo, float metallic, float n_dot_v) {
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, metallic, n_dot_v, kd, ks);
    return max(kd + ks, vec3(1e-3));
}

#endif
