// Proxy shading (paper 002 §3-5): the SH exponential of the summed log-occlusion and the
// normalisation of the proxy indirect light. At every receiver:
//   O_p = exp(sum of log-occlusion)  (OL, PS or HYB; PRODUCT: the sum already is O_p)  eq. 4
//   psi_shadow = H(N_p) . (O_p * L) = L . (O_p * H(N_p))  per rgb channel             eq. 10
//   xi_p = (sqrt(4 pi) - (O_p)_0) / (omega_p / sqrt(4 pi)),  I_p . H = xi_p (sum I_i . H)  eq. 12
//   radiance = kd / pi * max(psi_shadow + xi_p (sum I_i . H), 0) + ks * max(L . (O_p * F_w), 0)
// with kd, ks from brdf_indirect_weights at n.v (ks through brdf_table_fresnel_weight and times
// 1 - specular_trace_weight, the share the traced specular pass leaves), F_w the receiver's GGX
// row of the BRDF SH tables at theta_o rotated from the receiver frame (z = n, omega_o in xz)
// to the world (shine's extension: paper 002 shades Lambert receivers).
// Writes the radiance (RGBA16F, a = 0, 0 on background) and O_p (for tests and debugging).
// CPU twin: shine::reference::proxy::shade_cpu.
//! variant hyb_b3 EXP_HYB=1 SH_BANDS=3
//! variant hyb_b4 EXP_HYB=1 SH_BANDS=4
//! variant hyb_b5 EXP_HYB=1 SH_BANDS=5
//! variant hyb_b6 EXP_HYB=1 SH_BANDS=6
//! variant ps_b3 EXP_PS=1 SH_BANDS=3
//! variant ps_b4 EXP_PS=1 SH_BANDS=4
//! variant ps_b5 EXP_PS=1 SH_BANDS=5
//! variant ps_b6 EXP_PS=1 SH_BANDS=6
//! variant ol_b3 EXP_OL=1 SH_BANDS=3
//! variant ol_b4 EXP_OL=1 SH_BANDS=4
//! variant ol_b5 EXP_OL=1 SH_BANDS=5
//! variant ol_b6 EXP_OL=1 SH_BANDS=6
//! variant product_b3 PRODUCT=1 SH_BANDS=3
//! variant product_b4 PRODUCT=1 SH_BANDS=4
//! variant product_b5 PRODUCT=1 SH_BANDS=5
//! variant product_b6 PRODUCT=1 SH_BANDS=6
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define SH_LOOP_ATTRIBUTES
#define PROXY_TABLES_BINDING 8
#include "proxy_tables.glsl"
#include "sh.glsl"
#include "brdf.glsl"
#include "amortise.glsl"

// shine::passes::brdf_tables::GatherBrdf::gpu_data at SH_BANDS: the glossy receivers' rows.
layout(set = 0, binding = 9, std430) readonly buffer Brdf {
    float f[];
} brdf;
#include "brdf_table.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 7, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba8) readonly uniform image2D recv_albedo;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D recv_material;

layout(set = 0, binding = 3, std430) readonly buffer Sums {
    float s[];
} sums;

layout(set = 0, binding = 4, std430) readonly buffer Environment {
    float e[];
} environment;

layout(set = 0, binding = 5, std430) buffer Occlusion {
    float o[];
} occlusion;

layout(set = 0, binding = 6, rgba16f) uniform image2D proxy_gi;


// shine::passes::proxy::ShadePush
layout(push_constant) uniform Push {
    // xyz: camera position; w: the specular pass's roughness limit (0: none)
    vec4 camera;
    uvec2 extent;
    // roughness of the first glossy table, step between tables
    vec2 roughness_nodes;
    // number of glossy tables
    uint glossy_tables;
    // 0: every receiver; 1 + k: the receiver at (k & 1, k >> 1) of every 2x2 cell;
    // AMORTISE_REGATHER_SLICE: the receivers marked by alpha -1 in proxy_gi
    // (src/passes/amortise.rs)
    uint slice;
    uint pad0;
    uint pad1;
} push;


void main() {
    uvec2 xy = uvec2(amortise_pixel(gl_GlobalInvocationID.xy, push.slice));
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    if (push.slice == AMORTISE_REGATHER_SLICE && imageLoad(proxy_gi, ixy).a >= 0.0) {
        return;
    }
    uint r = xy.y * push.extent.x + xy.x;
    uint base = r * uint(SH_COEFFS + 4);
    vec4 nw = imageLoad(recv_normal, ixy);
    float f[SH_COEFFS];
    for (int k = 0; k < SH_COEFFS; ++k) {
        f[k] = sums.s[base + uint(k)];
    }
    float o[SH_COEFFS];
#if defined(EXP_HYB)
    sh_exp_hyb(f, o);
#elif defined(EXP_PS)
    sh_exp_ps(f, o);
#elif defined(EXP_OL)
    sh_exp_ol_ab(f, sh_ol_coefficients(sh_norm_without_dc(f)), o);
#else
    o = f;
#endif
    for (int k = 0; k < SH_COEFFS; ++k) {
        occlusion.o[r * uint(SH_COEFFS) + uint(k)] = o[k];
    }
    vec3 n = nw.xyz;
    vec4 position = imageLoad(recv_position, ixy);
    if (!(position.w > 0.0) || dot(n, n) <= 0.0) {
        // background receiver: no light
        imageStore(proxy_gi, ixy, vec4(0.0));
        return;
    }
    n = normalize(n);
    float cc[SH_BANDS];
    sh_clamped_cosine_zh(cc);
    float hn[SH_COEFFS];
    sh_rotate_zh(cc, n, hn);
    // H . (O * L) = L . (O * H): the triple product is symmetric, so one product serves the
    // three channels
    float oh[SH_COEFFS];
    sh_product(o, hn, oh);
    vec3 psi = vec3(0.0);
    for (int k = 0; k < SH_COEFFS; ++k) {
        psi += oh[k] * vec3(environment.e[k], environment.e[SH_COEFFS + k],
            environment.e[2 * SH_COEFFS + k]);
    }
    vec3 summed = vec3(sums.s[base + uint(SH_COEFFS)], sums.s[base + uint(SH_COEFFS) + 1u],
        sums.s[base + uint(SH_COEFFS) + 2u]);
    float xi = sh_overlap_normalisation(o[0], sums.s[base + uint(SH_COEFFS) + 3u]);
    vec3 albedo = imageLoad(recv_albedo, ixy).rgb;
    vec2 roughness_metallic = imageLoad(recv_material, ixy).rg;
    vec3 wo = normalize(push.camera.xyz - position.xyz);
    float cos_o = dot(n, wo);
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, roughness_metallic.y, cos_o, kd, ks);
    ks = brdf_table_fresnel_weight(ks, cos_o) * (1.0 - specular_trace_weight(roughness_metallic.x, push.camera.w));
    vec3 radiance = kd / SH_PI * max(psi + xi * summed, vec3(0.0));
    if (cos_o > 0.0 && any(greaterThan(ks, vec3(0.0)))) {
        // Receiver frame of the tables: z = n, omega_o in the xz half-plane.
        vec3 t = wo - n * cos_o;
        if (dot(t, t) < 1e-12) {
            t = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
            t -= n * dot(n, t);
        }
        t = normalize(t);
        vec3 b = cross(n, t);
        float f_local[SH_COEFFS];
        brdf_table_glossy_row(roughness_metallic.x, push.roughness_nodes, push.glossy_tables, acos(min(cos_o, 1.0)), f_local);
        float rot[SH_ROT_SIZE];
        sh_rotation(mat3(t, b, n), rot);
        float f_world[SH_COEFFS];
        sh_rotation_apply(rot, f_local, f_world);
        // L . (O * F_w): one product for the three channels
        float of[SH_COEFFS];
        sh_product(o, f_world, of);
        vec3 glossy = vec3(0.0);
        for (int k = 0; k < SH_COEFFS; ++k) {
            glossy += of[k] * vec3(environment.e[k], environment.e[SH_COEFFS + k],
                environment.e[2 * SH_COEFFS + k]);
        }
        radiance += ks * max(glossy, vec3(0.0));
    }
    imageStore(proxy_gi, ixy, vec4(radiance, 0.0));
}
