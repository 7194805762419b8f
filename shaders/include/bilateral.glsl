// The joint bilateral match of two receivers (paper 002 §4.2, eq. 11), shared by the upsample
// and the sky filter: how much a receiver at depth z_i with normal n_i stands for a target at
// depth z with normal n,
//   m = 1 / (1 + |z − z_i| / (σ_z z)) · max(0, n · n_i)^n
// (eq. 11's 1/(ε + |z − z_i|), with ε = σ_z z; n = 32 in the paper). CPU twin:
// shine::passes::upsample::match_weight.
#ifndef BILATERAL_GLSL
#define BILATERAL_GLSL

float bilateral_match(float z, vec3 n, float z_i, vec3 n_i, float depth_sigma, float normal_power) {
    float wz = 1.0 / (1.0 + abs(z - z_i) / (depth_sigma * z));
    float wn = pow(max(dot(n, n_i), 0.0), normal_power);
    return wz * wn;
}

#endif
