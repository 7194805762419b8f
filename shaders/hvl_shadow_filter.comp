// HVL shadow filter (src/passes/hvl/shadows.rs): the sampled visibility of hvl_gather.comp's
// `_shadows` variants leaves each receiver with its exact unshadowed light U, its weight W_u
// (`unshadowed`: rgb U, a W_u) and an unbiased but noisy shadowed weight S (`shadowed`, a).
// The ratio estimator (Heitz, Hill and McGuire 2018, "Combining analytic direct illumination
// and stochastic shadows") keeps U's detail and filters only the shadowing:
//   out = U * min(1, sum_q w_q S_q / sum_q w_q W_u,q)
// over the (2R+1)^2 receivers q around the receiver, with
//   w_q = exp(-|offset|^2 / (2 sigma^2)) * bilateral_plane_match(...)   (sigma = R,
// push.sigma_per_radius; the sky filter's weights with twice its sigma: paper 002 eq. 11's match
// with the upsample's sigma_z and normal exponent, its depth offset measured off the receiver's
// tangent plane so a grazing floor keeps its rows), so shadows are not blurred across edges;
// the ratio is at most 1, as visibility is, and exactly 1 where nothing is in the way. Amortised frames (push.slice = 1 + k) filter
// only the refreshed receivers, one per 2x2 cell at offset (k & 1, k >> 1), over the receivers
// of the same slice (offsets in steps of 2); the others are left for hvl_resolve (src/passes/amortise.rs). Writes
// RGBA16F, a = 0, 0 on background. CPU twin: shine::passes::hvl::shadows::ratio_filter.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "bilateral.glsl"
#include "amortise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D shadowed;
layout(set = 0, binding = 3, rgba16f) readonly uniform image2D unshadowed;
layout(set = 0, binding = 4, rgba16f) writeonly uniform image2D filtered;

// shine::passes::hvl::shadows::ShadowFilterPush (32 bytes).
layout(push_constant) uniform Push {
    // receiver buffer size
    uvec2 extent;
    // R: the filter's radius in receivers (0: the receiver's own ratio)
    uint radius;
    // sigma_z and n of the bilateral match
    float depth_sigma;
    float normal_power;
    // 0: every receiver; 1 + k: the slice of the amortised gather (hvl_gather.comp)
    uint slice;
    // sigma of the gaussian over the radius R
    float sigma_per_radius;
    uint pad2;
} push;

void main() {
    ivec2 ixy = amortise_pixel(gl_GlobalInvocationID.xy, push.slice);
    int step = push.slice == 0u ? 1 : 2;
    if (any(greaterThanEqual(ixy, ivec2(push.extent)))) {
        return;
    }
    vec4 position = imageLoad(recv_position, ixy);
    vec3 n = imageLoad(recv_normal, ixy).xyz;
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        imageStore(filtered, ixy, vec4(0.0));
        return;
    }
    n = normalize(n);
    int r = int(push.radius);
    float sigma = push.sigma_per_radius * float(r);
    float inv_two_sigma2 = r > 0 ? 0.5 / (sigma * sigma) : 0.0;
    ivec2 last = ivec2(push.extent) - 1;
    float num = 0.0;
    float den = 0.0;
    for (int dy = -r; dy <= r; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
            ivec2 c = ixy + step * ivec2(dx, dy);
            if (any(lessThan(c, ivec2(0))) || any(greaterThan(c, last))) {
                continue;
            }
            vec4 pc = imageLoad(recv_position, c);
            if (!(pc.w > 0.0)) {
                continue;
            }
            float w = exp(-float(dx * dx + dy * dy) * inv_two_sigma2)
                * bilateral_plane_match(position.xyz, position.w, n, pc.xyz,
                    imageLoad(recv_normal, c).xyz,
                    push.depth_sigma, push.normal_power);
            num += w * imageLoad(shadowed, c).a;
            den += w * imageLoad(unshadowed, c).a;
        }
    }
    vec3 u = imageLoad(unshadowed, ixy).rgb;
    imageStore(filtered, ixy, vec4(den > 0.0 ? u * min(1.0, num / den) : vec3(0.0), 0.0));
}
