// sh_filter (paper 000 §3, steps 3-4): the discontinuity filter over each pixel's incident
// radiance SH (variants o2, o3, o4) or, classic IGI (variant irr), over its irradiance and glossy
// radiance; then the BRDF. CPU twin: shine::reference::igi::sh_filter.
//
// Filter: the mean over a window of k n x k m pixels (k = filter_radius tiles of the n x m
// pattern; x from p.x - floor(k n / 2), likewise y) of the pixels q with geometry
// (gb_position.w != 0), a depth offset within depth_tolerance * z_p (plane_test: the distance
// |n_p . (x_q - x_p)| off p's geometric tangent plane, issue 43; else the linear depths'
// difference |z_q - z_p|, paper 000 §2.3, which parts a grazing plane's rows), and a GEOMETRIC
// normal (gb_geometric_normal, not the normal-mapped one) with n_p . n_q >= normal_threshold;
// p itself always counts. Unclipped and in a continuous region the window holds every
// interleaved set exactly k^2 times (paper 000 §2.3: a filter exactly as wide as the pattern).
// k = 0 is no filter.
// Resolve (paper 000 §3.1, §3.3) about the SHADING normal n and reflected direction r:
//   SH, Phong (o2-o4): L_o = kd . (L . B_lambert(n)) + ks . (L . B_phong(r, e)), per channel,
//     kd, ks: brdf_indirect_weights; e = igi_phong_exponent(roughness);
//   SH, GGX (g2-g4): L rotated into the receiver frame of the BRDF SH tables (z = n, omega_o
//     in the xz half-plane) by sh_rotation, then kd (L . F_lambert(theta_o)) +
//     brdf_table_fresnel_weight(ks) (L . F_ggx(roughness, theta_o)) with the HVL gather's tables
//     (brdf_table.glsl) and the weights of brdf_indirect_weights;
//   irr: L_o = kd / pi . E + ks . G.
// Output clamped at 0 per channel (band-limited ringing must not go negative in RGBA16F).
//! variant o2 SH_BANDS=2
//! variant o3 SH_BANDS=3
//! variant o4 SH_BANDS=4
//! variant g2 SH_BANDS=2 IGI_GGX=1
//! variant g3 SH_BANDS=3 IGI_GGX=1
//! variant g4 SH_BANDS=4 IGI_GGX=1
//! variant irr SH_BANDS=1 IGI_IRRADIANCE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "igi.glsl"
#include "brdf.glsl"

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

#ifdef IGI_GGX
// shine::passes::brdf_tables::GatherBrdf::gpu_data at SH_BANDS bands
layout(set = 0, binding = 7, std430) readonly buffer Brdf {
    float f[];
} brdf;
#include "brdf_table.glsl"
#endif

#ifdef IGI_IRRADIANCE
#define SH_OUT 2
#else
#define SH_OUT SH_COEFFS
#endif

// shine::passes::igi::FilterPush
layout(push_constant) uniform Push {
    // xyz: camera position; w: the specular pass's roughness limit (0: none)
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
    // number of glossy tables (GGX path)
    uint glossy_tables;
    // roughness of the first glossy table, step between tables (GGX path)
    vec2 roughness_nodes;
    // 1: the depth offset is the distance off p's tangent plane; 0: the depths' difference
    uint plane_test;
    float pad;
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
                vec4 pq = imageLoad(gb_position, q);
                float offset = push.plane_test != 0u ? dot(ng, pq.xyz - position.xyz) : pq.w - z;
                if (pq.w == 0.0 || abs(offset) > push.depth_tolerance * z) {
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
    vec3 result;
#if defined(IGI_GGX)
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, roughness_metallic.y, dot(n, wo), kd, ks);
    ks *= 1.0 - specular_trace_weight(roughness_metallic.x, push.camera.w);
    ks = brdf_table_fresnel_weight(ks, dot(n, wo));
    // A shading normal facing away from the viewer is evaluated at grazing view.
    float cos_o = clamp(dot(n, wo), 1e-4, 1.0);
    vec3 t = wo - n * dot(n, wo);
    if (dot(t, t) < 1e-12) {
        t = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        t -= n * dot(n, t);
    }
    t = normalize(t);
    vec3 b = cross(n, t);
    float rot[SH_ROT_SIZE];
    sh_rotation(transpose(mat3(t, b, n)), rot);
    float theta_o = acos(cos_o);
    float f_lambert[SH_COEFFS];
    float f_glossy[SH_COEFFS];
    brdf_table_row(0, theta_o, f_lambert);
    brdf_table_glossy_row(roughness_metallic.x, push.roughness_nodes, push.glossy_tables, theta_o, f_glossy);
    for (int c = 0; c < 3; ++c) {
        float world[SH_COEFFS];
        for (int k = 0; k < SH_COEFFS; ++k) {
            world[k] = sum[k][c] / count;
        }
        float local[SH_COEFFS];
        sh_rotation_apply(rot, world, local);
        result[c] = kd[c] * sh_dot(local, f_lambert) + ks[c] * sh_dot(local, f_glossy);
    }
#elif defined(IGI_IRRADIANCE)
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, roughness_metallic.y, dot(n, wo), kd, ks);
    ks *= 1.0 - specular_trace_weight(roughness_metallic.x, push.camera.w);
    result = kd / IGI_PI * (sum[0] / count) + ks * (sum[1] / count);
#else
    vec3 kd;
    vec3 ks;
    brdf_indirect_weights(albedo, roughness_metallic.y, dot(n, wo), kd, ks);
    ks *= 1.0 - specular_trace_weight(roughness_metallic.x, push.camera.w);
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
