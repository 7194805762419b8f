// upsample: joint bilateral upsampling of a receiver-resolution result (paper 002 §4.2, eq. 11).
//
// Target pixel p (full resolution) blends the 2×2 nearest receiver samples i with
//   w̃_i = w_i^b · m_i,  m_i = w_i^z · w_i^N
//   w_i^b  standard bilinear weight of p between the receiver sample centres (clamped to edge)
//   w_i^z  = 1 / (1 + |z_p − z_i| / (σ_z · z_p))      (eq. 11's 1/(ε + |z_p − z_i|), ε = σ_z z_p)
//   w_i^N  = max(0, N_p · N_i)^n                       (eq. 11, n = 32 in the paper)
// and w̃_i = 0 for a receiver that does not match p (m_i < μ) or is background (w = 0).
// Result Σ w̃_i L_i / Σ w̃_i. Fallback (no receiver of the 2×2 matches p, Σ w̃_i = 0): the radiance
// of the valid receiver with the largest m among the 3×3 around p's own receiver (own on ties),
// 0 when all are background. Background targets (w == 0) get 0; with s = 1 the rest is an exact
// copy. docs/frame.md "Upsample";
// CPU reference: `shine::passes::upsample::upsample_cpu`.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bilateral.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) readonly uniform image2D radiance;
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 3, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D gb_normal;

layout(set = 0, binding = 5, rgba16f) uniform image2D upsampled;

layout(push_constant) uniform Push {
    // Full-resolution extent W×H.
    uvec2 extent;
    // Coarse extent: ceil(W/s)×ceil(H/s) for receivers, the internal size for a GI context.
    uvec2 recv_extent;
    // Full-resolution pixels per coarse sample (s for receivers; sample i's centre sits at
    // (i + 0.5)·step).
    vec2 step;
    // σ_z: relative depth difference that halves w^z.
    float depth_sigma;
    // n: exponent of the normal weight.
    float normal_power;
    // μ: the least w^z · w^N of a receiver that matches the target.
    float min_match;
} push;

// w^z · w^N of receiver c for a target at depth z with normal n; -1 for a background receiver.
float match_weight(ivec2 c, float z, vec3 n) {
    vec4 position = imageLoad(recv_position, c);
    if (position.w <= 0.0) {
        return -1.0;
    }
    return bilateral_match(z, n, position.w, imageLoad(recv_normal, c).xyz, push.depth_sigma,
        push.normal_power);
}

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.extent.x || p.y >= push.extent.y) {
        return;
    }
    vec4 target = imageLoad(gb_position, ivec2(p));
    if (target.w <= 0.0) {
        imageStore(upsampled, ivec2(p), vec4(0.0));
        return;
    }
    if (push.step == vec2(1.0) && push.recv_extent == push.extent) {
        // s = 1: the receiver is the pixel itself, an exact copy.
        imageStore(upsampled, ivec2(p), imageLoad(radiance, ivec2(p)));
        return;
    }
    vec3 normal = imageLoad(gb_normal, ivec2(p)).xyz;

    // Position of p in receiver texel coordinates (sample centres at integers).
    vec2 centre = vec2(p) + 0.5;
    vec2 u = centre / push.step - 0.5;
    vec2 base = floor(u);
    vec2 f = u - base;
    ivec2 last = ivec2(push.recv_extent) - 1;

    vec4 sum = vec4(0.0);
    float weight_sum = 0.0;
    for (int k = 0; k < 4; k++) {
        ivec2 offset = ivec2(k & 1, k >> 1);
        ivec2 c = clamp(ivec2(base) + offset, ivec2(0), last);
        float wb = (offset.x == 1 ? f.x : 1.0 - f.x) * (offset.y == 1 ? f.y : 1.0 - f.y);
        float m = match_weight(c, target.w, normal);
        float w = m >= push.min_match ? wb * m : 0.0;
        sum += w * imageLoad(radiance, c);
        weight_sum += w;
    }
    vec4 result;
    if (weight_sum > 0.0) {
        result = sum / weight_sum;
    } else {
        // Fallback: the best match among the 3×3 receivers around p's own (own on ties).
        ivec2 own = min(ivec2(floor(centre / push.step)), last);
        float best = match_weight(own, target.w, normal);
        result = best >= 0.0 ? imageLoad(radiance, own) : vec4(0.0);
        for (int dy = -1; dy <= 1; dy++) {
            for (int dx = -1; dx <= 1; dx++) {
                ivec2 c = clamp(own + ivec2(dx, dy), ivec2(0), last);
                float m = match_weight(c, target.w, normal);
                if (m > best) {
                    best = m;
                    result = imageLoad(radiance, c);
                }
            }
        }
    }
    imageStore(upsampled, ivec2(p), result);
}
