// Paper 004's filter width and sampling rate per pixel: the GLSL twin of shine_sh::aaf (tied by
// tests/aaf.rs through the aaf_beta pass). z_min, z_max: nearest and farthest reflector seen
// from the pixel; d: world-space size of the pixel at the receiver (A_p = d^2). The includer
// includes brdf.glsl first.
#ifndef AAF_GLSL
#define AAF_GLSL

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
