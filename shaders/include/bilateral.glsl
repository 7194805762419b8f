// The joint bilateral match of two receivers (paper 002 §4.2, eq. 11), shared by the upsample
// and the sky filter: how much a receiver at depth z_i with normal n_i stands for a target at
// depth z with normal n,
//   m = 1 / (1 + |z − z_i| / (σ_z z)) · max(0, n · n_i)^n
// (eq. 11's 1/(ε + |z − z_i|), with ε = σ_z z; n = 32 in the paper). CPU twin:
// shine::passes::upsample::bilateral_match.
#ifndef BILATERAL_GLSL
#define BILATERAL_GLSL

float bilateral_match(float z, vec3 n, float z_i, vec3 n_i, float depth_sigma, float normal_power) {
    float wz = 1.0 / (1.0 + abs(z - z_i) / (depth_sigma * z));
    float wn = pow(max(dot(n, n_i), 0.0), normal_power);
    return wz * wn;
}

// The same match with the depth offset measured off the target's tangent plane, |n · (x_i − x)|
// in place of |z − z_i| (issue 43): on a plane seen at a grazing angle the rows' depths differ by
// more than σ_z z, so the depth test keeps a receiver's own row and a filter of noisy samples
// leaves stripes that flicker as the samples move; the plane's own receivers lie on it at 0.
// HVL's sampled shadows' ratio filter (docs/quality.md, issue 43, change 12) and the near
// field's filter (sky_filter.comp with a world reach, change 13) use it.
// CPU twin: shine::passes::upsample::bilateral_plane_match.
float bilateral_plane_match(vec3 x, float z, vec3 n, vec3 x_i, vec3 n_i, float depth_sigma,
    float normal_power) {
    float wz = 1.0 / (1.0 + abs(dot(n, x_i - x)) / (depth_sigma * z));
    float wn = pow(max(dot(n, n_i), 0.0), normal_power);
    return wz * wn;
}

#endif
