// sh_filter (paper 000 §3, steps 3-4): the discontinuity filter over each pixel's incident
// radiance SH (variants o2, o3, o4) or, classic IGI (variant irr), over its irradiance and glossy
// radiance; then the BRDF. CPU twin: shine::igi_reference::sh_filter.
//
// Filter: the mean over a window of k n x k m pixels (k = filter_radius tiles of the n x m
// pattern; x from p.x - floor(k n / 2), likewise y) of the pixels q with geometry
// (gb_position.w != 0), a linear depth within depth_tolerance * z_p of p's, and a GEOMETRIC
// normal (gb_geometric_normal, not the normal-mapped one) with n_p . n_q >= normal_threshold;
// p itself always counts. Unclipped and in a continuous region the window holds every
// interleaved set exactly k^2 times (paper 000 §2.3: a filter exactly as wide as the pattern).
// k = 0 is no filter.
// Resolve (paper 000 §3.1, §3.3) about the SHADING normal n and reflected direction r:
//   SH:  L_o = kd . (L . B_lambert(n)) + ks . (L . B_phong(r, e)),   per rgb channel
//   irr: L_o = kd / pi . E + ks . G
// kd, ks: igi_material_weights; e = igi_phong_exponent(roughness). Output clamped at 0 per
// channel (band-limited ringing must not go negative in the RGBA16F image).
//! variant o2 SH_BANDS=2
//! variant o3 SH_BANDS=3
//! variant o4 SH_BANDS=4
//! variant irr SH_BANDS=1 IGI_IRRADIANCE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "igi.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D gb_geometric_normal;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D gb_albedo;
layout(set = 0, binding = 4, rgba8) readonly uniform image2D gb_material;

layout(set = 0, binding = 5, std430) readonly buffer VplSh {
    uint c[];
} vpl_sh;

layout(set = 0, binding = 6, rgba16f) uniform image2D indirect;

#ifdef IGI_IRRADIANCE
#define SH_OUT 2
#else
#define SH_OUT SH_COEFFS
#endif

// shine::passes::igi::FilterPush
layout(push_constant) uniform Push {
    // xyz: camera position; w unused
    vec4 camera;
    // image size
    uvec2 extent;
    // interleaving pattern n, m
    uvec2 pattern;
    // window size in pattern tiles k
    uint radius;
    // relative depth tolerance
    float depth_tolerance;
    // cosine threshold of the geometric normals
    float normal_threshold;
    uint pad0;
} push;

vec3 load(uint base, int k) {
    vec2 rg = unpackHalf2x16(vpl_sh.c[base + 2u * uint(k)]);
    vec2 b = unpackHalf2x16(vpl_sh.c[base + 2u * uint(k) + 1u]);
    return vec3(rg, b.x);
}

void main() {
    ivec2 px = ivec2(gl_GlobalInvocationID.xy);
    if (px.x >= int(push.extent.x) || px.y >= int(push.extent.y)) {
        return;
    }
    vec4 position = imageLoad(gb_position, px);
    if (position.w == 0.0) {
        imageStore(indirect, px, vec4(0.0));
        return;
    }
    float z = position.w;
    vec3 ng = normalize(imageLoad(gb_geometric_normal, px).xyz);
    vec3 sum[SH_OUT];
    for (int k = 0; k < SH_OUT; ++k) {
        sum[k] = vec3(0.0);
    }
    float count = 0.0;
    ivec2 size = ivec2(max(push.radius, 1u) * push.pattern);
    if (push.radius == 0u) {
        size = ivec2(1);
    }
    ivec2 lo = -(size / 2);
    for (int dy = lo.y; dy < lo.y + size.y; ++dy) {
        for (int dx = lo.x; dx < lo.x + size.x; ++dx) {
            ivec2 q = px + ivec2(dx, dy);
            if (q.x < 0 || q.y < 0 || q.x >= int(push.extent.x) || q.y >= int(push.extent.y)) {
                continue;
            }
            bool centre = dx == 0 && dy == 0;
            if (!centre) {
                float zq = imageLoad(gb_position, q).w;
                if (zq == 0.0 || abs(zq - z) > push.depth_tolerance * z) {
                    continue;
                }
                vec3 nq = normalize(imageLoad(gb_geometric_normal, q).xyz);
                if (dot(ng, nq) < push.normal_threshold) {
                    continue;
                }
            }
            uint base = (uint(q.y) * push.extent.x + uint(q.x)) * uint(SH_OUT) * 2u;
            for (int k = 0; k < SH_OUT; ++k) {
                sum[k] += load(base, k);
            }
            count += 1.0;
        }
    }
    vec3 x = position.xyz;
    vec3 n = normalize(imageLoad(gb_normal, px).xyz);
    vec3 albedo = imageLoad(gb_albedo, px).rgb;
    vec2 roughness_metallic = imageLoad(gb_material, px).rg;
    vec3 wo = normalize(push.camera.xyz - x);
    vec3 kd;
    vec3 ks;
    igi_material_weights(albedo, roughness_metallic.y, dot(n, wo), kd, ks);
    vec3 result;
#ifdef IGI_IRRADIANCE
    result = kd / IGI_PI * (sum[0] / count) + ks * (sum[1] / count);
#else
    float exponent = igi_phong_exponent(roughness_metallic.x);
    float b_lambert[SH_COEFFS];
    float b_phong[SH_COEFFS];
    igi_brdf_lambert(n, b_lambert);
    igi_brdf_phong(reflect(-wo, n), exponent, b_phong);
    vec3 diffuse = vec3(0.0);
    vec3 glossy = vec3(0.0);
    for (int k = 0; k < SH_COEFFS; ++k) {
        vec3 l = sum[k] / count;
        diffuse += l * b_lambert[k];
        glossy += l * b_phong[k];
    }
    result = kd * diffuse + ks * glossy;
#endif
    imageStore(indirect, px, vec4(max(result, vec3(0.0)), 0.0));
}
