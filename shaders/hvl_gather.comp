// HVL gather (paper 003 §5.1, eq. 1, 3, 19-22): outgoing radiance towards the camera at each
// receiver from every HVL of the cache (brute force, as the paper's prototype), read as the
// records hvl_gather_prep.comp wrote (per-HVL terms computed once). Per pair, no GLSL
// trigonometry (hvl_cap_terms evaluates eq. 22 with polynomials, branch-free: lavapipe runs
// every branch), and the cap meets the BRDF rows in their m >= 0 half only (see Receiver).
// As published, HVLs are unshadowed (§6). The `_vis` and `_shadows` variants (shine's
// extension) shadow them through the BVH, aiming each shadow ray at the HVL's centre lifted off
// its surface by 1% of its radius; a receiver inside an HVL's sphere is never shadowed from it.
//   `_vis`: one ray per receiver and HVL, `indirect` the shadowed sum.
//   `_shadows`: push.shadow_rays = K rays per receiver, one per stratum of the HVLs: stratum k
//     holds every light's samples k, k + K, k + 2K, ... of its sequence (by identity, not by
//     slot: a light's records are consecutive and its first holds its count, so when one
//     light's count changes the others' strata stay. On the grid a stratum interleaves the
//     cells; by flux, the samples k, k + K, ... of a Sobol sequence share the low bits of
//     their index, so for K a power of two a stratum is a band of the light's flux, one of K)
//     and draws one of them in proportion to its weight w_j = (c_j.r + c_j.g + c_j.b) / 3
//     (c_j the HVL's light) by an exponential race: the least key -ln(u_j) / w_j wins, which
//     happens with probability w_j / W_k, u_j a hash of the receiver and the HVL's identity
//     (hvl_shadow_uniform). The draw depends on no order, so an HVL keeps its number when the
//     records reorder or the counts change (issue 43; a reservoir in slot order with the
//     receiver's random stream drew anew whenever one light's count moved the others' slots).
//     With W_k the
//     stratum's weight outside the spheres, V_k its drawn HVL's visibility and W_in the weight
//     inside them, the shadowed weight
//       S = W_in + sum_k W_k V_k
//     is unbiased; `unshadowed` holds (U, W_in + W) (U the unshadowed sum, W = sum_k W_k),
//     `indirect` (U * min(1, S / (W_in + W)), S). hvl_shadow_filter.comp then returns
//     U * min(1, sum w S / sum w (W_in + W)) over the receivers around (the ratio estimator of
//     Heitz et al. 2018): exactly U where nothing is in the way. Regathered receivers
//     (amortised frames) are scattered and keep their own ratio.
//! variant full_c1 HVL_FULL=1 SH_BANDS=1
//! variant full_c2 HVL_FULL=1 SH_BANDS=2
//! variant full_c3 HVL_FULL=1 SH_BANDS=3
//! variant full_c4 HVL_FULL=1 SH_BANDS=4
//! variant full_c5 HVL_FULL=1 SH_BANDS=5
//! variant full_c6 HVL_FULL=1 SH_BANDS=6
//! variant full_c7 HVL_FULL=1 SH_BANDS=7
//! variant full_c8 HVL_FULL=1 SH_BANDS=8
//! variant full_c9 HVL_FULL=1 SH_BANDS=9
//! variant full_c10 HVL_FULL=1 SH_BANDS=10
//! variant zonal_c1 HVL_ZONAL=1 SH_BANDS=1
//! variant zonal_c2 HVL_ZONAL=1 SH_BANDS=2
//! variant zonal_c3 HVL_ZONAL=1 SH_BANDS=3
//! variant zonal_c4 HVL_ZONAL=1 SH_BANDS=4
//! variant zonal_c5 HVL_ZONAL=1 SH_BANDS=5
//! variant zonal_c6 HVL_ZONAL=1 SH_BANDS=6
//! variant zonal_c7 HVL_ZONAL=1 SH_BANDS=7
//! variant zonal_c8 HVL_ZONAL=1 SH_BANDS=8
//! variant zonal_c9 HVL_ZONAL=1 SH_BANDS=9
//! variant zonal_c10 HVL_ZONAL=1 SH_BANDS=10
//! variant full_c1_vis HVL_FULL=1 SH_BANDS=1 HVL_VISIBILITY=1
//! variant full_c2_vis HVL_FULL=1 SH_BANDS=2 HVL_VISIBILITY=1
//! variant full_c3_vis HVL_FULL=1 SH_BANDS=3 HVL_VISIBILITY=1
//! variant full_c4_vis HVL_FULL=1 SH_BANDS=4 HVL_VISIBILITY=1
//! variant full_c5_vis HVL_FULL=1 SH_BANDS=5 HVL_VISIBILITY=1
//! variant full_c6_vis HVL_FULL=1 SH_BANDS=6 HVL_VISIBILITY=1
//! variant full_c7_vis HVL_FULL=1 SH_BANDS=7 HVL_VISIBILITY=1
//! variant full_c8_vis HVL_FULL=1 SH_BANDS=8 HVL_VISIBILITY=1
//! variant full_c9_vis HVL_FULL=1 SH_BANDS=9 HVL_VISIBILITY=1
//! variant full_c10_vis HVL_FULL=1 SH_BANDS=10 HVL_VISIBILITY=1
//! variant zonal_c1_vis HVL_ZONAL=1 SH_BANDS=1 HVL_VISIBILITY=1
//! variant zonal_c2_vis HVL_ZONAL=1 SH_BANDS=2 HVL_VISIBILITY=1
//! variant zonal_c3_vis HVL_ZONAL=1 SH_BANDS=3 HVL_VISIBILITY=1
//! variant zonal_c4_vis HVL_ZONAL=1 SH_BANDS=4 HVL_VISIBILITY=1
//! variant zonal_c5_vis HVL_ZONAL=1 SH_BANDS=5 HVL_VISIBILITY=1
//! variant zonal_c6_vis HVL_ZONAL=1 SH_BANDS=6 HVL_VISIBILITY=1
//! variant zonal_c7_vis HVL_ZONAL=1 SH_BANDS=7 HVL_VISIBILITY=1
//! variant zonal_c8_vis HVL_ZONAL=1 SH_BANDS=8 HVL_VISIBILITY=1
//! variant zonal_c9_vis HVL_ZONAL=1 SH_BANDS=9 HVL_VISIBILITY=1
//! variant zonal_c10_vis HVL_ZONAL=1 SH_BANDS=10 HVL_VISIBILITY=1
//! variant full_c1_shadows HVL_FULL=1 SH_BANDS=1 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c2_shadows HVL_FULL=1 SH_BANDS=2 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c3_shadows HVL_FULL=1 SH_BANDS=3 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c4_shadows HVL_FULL=1 SH_BANDS=4 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c5_shadows HVL_FULL=1 SH_BANDS=5 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c6_shadows HVL_FULL=1 SH_BANDS=6 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c7_shadows HVL_FULL=1 SH_BANDS=7 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c8_shadows HVL_FULL=1 SH_BANDS=8 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c9_shadows HVL_FULL=1 SH_BANDS=9 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant full_c10_shadows HVL_FULL=1 SH_BANDS=10 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c1_shadows HVL_ZONAL=1 SH_BANDS=1 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c2_shadows HVL_ZONAL=1 SH_BANDS=2 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c3_shadows HVL_ZONAL=1 SH_BANDS=3 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c4_shadows HVL_ZONAL=1 SH_BANDS=4 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c5_shadows HVL_ZONAL=1 SH_BANDS=5 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c6_shadows HVL_ZONAL=1 SH_BANDS=6 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c7_shadows HVL_ZONAL=1 SH_BANDS=7 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c8_shadows HVL_ZONAL=1 SH_BANDS=8 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c9_shadows HVL_ZONAL=1 SH_BANDS=9 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
//! variant zonal_c10_shadows HVL_ZONAL=1 SH_BANDS=10 HVL_VISIBILITY=1 HVL_SHADOW_SAMPLES=1
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// Every loop inside the loop over HVLs unrolled: see SH_UNROLL in sh.glsl.
#define SH_LOOP_ATTRIBUTES 1
#include "sh.glsl"
#include "brdf.glsl"
#include "hvl.glsl"
#include "hvl_near.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
layout(set = 0, binding = 2, rgba8) readonly uniform image2D recv_albedo;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D recv_material;

// The cache as hvl_gather_prep.comp prepared it: GatherHvl records, four texels each.
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D hvl_records;

#ifdef HVL_FULL
// shine::passes::brdf_tables::GatherBrdf::gpu_data: F of Lambert (albedo 1) then F of GGX at each
// roughness node, each 90 rows of SH_COEFFS floats (shine_sh::brdf_table layout)
layout(set = 0, binding = 5, std430) readonly buffer Brdf {
    float f[];
} brdf;
#include "brdf_table.glsl"
#endif

layout(set = 0, binding = 6, rgba16f) uniform image2D indirect;

#include "amortise.glsl"

#ifdef HVL_SHADOW_SAMPLES
layout(set = 0, binding = 11, rgba16f) writeonly uniform image2D unshadowed;
#include "random.glsl"

// Most shadow rays per receiver of the sampled visibility: shine::passes::hvl::shadows::RAYS_MAX.
#define HVL_SHADOW_RAYS_MAX 16

// A stratum's race starts with this key (finite: times a zero weight it stays 0, no NaN).
const float HVL_SHADOW_NO_KEY = 3.0e38;

// The shadow draw's uniform number of the HVL of `identity` (HVL_RECORD_IDENTITY) at the
// receiver of `receiver_key`, in (0, 1): a hash of the two alone, never of the HVL's slot.
float hvl_shadow_uniform(uint receiver_key, vec2 identity) {
    uint h = pcg(receiver_key ^ pcg(uint(identity.x) * 0x9E3779B9u + uint(identity.y)));
    return (float(h >> 8) + 0.5) * (1.0 / 16777216.0);
}
#endif

#ifdef HVL_VISIBILITY
#define TRACE_NODES_BINDING 7
#define TRACE_TRIANGLES_BINDING 8
#define TRACE_TOP_BINDING 9
#define TRACE_INSTANCES_BINDING 10
#include "trace.glsl"

// The HVL centre lies on its sender's surface: the shadow ray aims at it lifted along the
// sender's normal by this fraction of the HVL radius (plus 0.1 mm), so the sender itself never
// hides it.
const float HVL_VISIBILITY_LIFT = 0.01;

// Where a shadow ray to an HVL aims: its centre lifted along its (unit) normal.
vec3 hvl_shadow_target(vec4 position_radius, vec3 hvl_normal) {
    return position_radius.xyz + hvl_normal * (HVL_VISIBILITY_LIFT * position_radius.w + 1e-4);
}

// Whether the segment from origin to target is blocked.
bool trace_occluded_by(vec3 origin, vec3 target) {
    vec3 to_target = target - origin;
    float reach = length(to_target);
    return trace_occluded(origin, to_target / reach, 0.0, reach);
}
#endif

// shine::passes::hvl::GatherPush
layout(push_constant) uniform Push {
    // xyz: camera position; w: the specular pass's roughness limit (0: none)
    vec4 camera;
    // receiver buffer size
    uvec2 extent;
    // HVLs in the cache
    uint hvl_count;
    // bands of the HVL emission reconstructed (1-5)
    uint emission_bands;
    // roughness of the first glossy table, step between tables
    vec2 roughness_nodes;
    // number of glossy tables
    uint glossy_tables;
    // 0: every receiver; 1 + k: only the receiver at offset (k & 1, k >> 1) of every 2×2
    // cell; AMORTISE_REGATHER_SLICE: only the receivers marked by alpha -1 in `indirect`
    // (amortised frames, src/passes/amortise.rs)
    uint slice;
    // width of the sinc window on the light's SH bands (paper 003 §4.2), 0: none
    float window_width;
    // 1: the disc's near-field falloff (hvl_disc_falloff); 0: the paper's sphere
    uint disc_falloff;
    // `_shadows` variants: shadow rays per receiver, 1..HVL_SHADOW_RAYS_MAX
    uint shadow_rays;
    // seed of the sampled shadow rays' random numbers
    uint seed;
    // R of the near field (hvl_near.comp, world units): each HVL's diffuse light is scaled by
    // smoothstep(R, 2R, d), d its centre's distance; 0: no near field
    float near_range;
    uint pad0;
    uint pad1;
    uint pad2;
} push;

// Receivers closer than this to an HVL centre get nothing from it (metres).
const float HVL_MIN_DISTANCE = 1e-6;

#ifdef HVL_FULL
// brdf_row / glossy_row: shaders/include/brdf_table.glsl (shared with sh_filter.comp)
void brdf_row(int table, float theta_o, out float f[SH_COEFFS]) {
    brdf_table_row(table, theta_o, f);
}

void glossy_row(float roughness, float theta_o, out float f[SH_COEFFS]) {
    brdf_table_glossy_row(roughness, push.roughness_nodes, push.glossy_tables, theta_o, f);
}
#endif

// No light at px (background, or a receiver seen from behind).
void store_nothing(ivec2 px) {
    imageStore(indirect, px, vec4(0.0));
#ifdef HVL_SHADOW_SAMPLES
    imageStore(unshadowed, px, vec4(0.0));
#endif
}

// What every pair of a receiver shares, set up once per receiver in main.
struct Receiver {
    vec3 x;
    vec3 n;
    vec3 kd;
    vec3 ks;
#ifdef HVL_FULL
    // The receiver frame of the tables: z = n, omega_o in the xz half-plane (phi_o = 0, eq. 17).
    vec3 t;
    vec3 b;
    // dot(window * cap, F) of a cap ZH rotated to d (sh_rotate_zh) is
    //   sum_l cap_l win_l sqrt(4 pi / (2l + 1)) sum_m Y_lm(d) F_lm,
    // so the rows take the per-band factors once per receiver. In the receiver frame Lambert's F
    // is zonal and the glossy F even in phi (shine_sh::brdf_table tests): only m = 0, and
    // m >= 0, are kept.
    float lambert_zh[SH_BANDS];
    float glossy_even[SH_EVEN_COEFFS];
#else
    float cc[SH_BANDS];
    // The window's factor per band (1 without a window), applied to each HVL's cap.
    float win[SH_BANDS];
#endif
#ifdef HVL_VISIBILITY
    // Where the receiver's shadow rays start.
    vec3 origin;
#endif
    // push.near_range and push.disc_falloff, read once per receiver: llvmpipe loads a push
    // constant read inside a loop lane by lane at every iteration (docs/pitfalls.md).
    float near_range;
    bool disc_falloff;
};

// HVL j's light at the receiver towards the camera (eq. 1, 3, 19-22), 0 when it sends none
// there (an empty cell, a receiver at its centre, a sender facing away, a cap below the
// horizon; in `_vis`, a shadow ray blocked). `inside`: the receiver lies in its sphere.
vec3 pair_light(Receiver rc, uint j, out bool inside) {
    inside = false;
    vec4 position_radius = imageLoad(hvl_records, hvl_record_texel(j, HVL_RECORD_POSITION_RADIUS));
    float r = position_radius.w;
    if (!(r > 0.0)) {
        return vec3(0.0);
    }
    vec3 v = position_radius.xyz - rc.x;
    float dist2 = dot(v, v);
    if (dist2 < HVL_MIN_DISTANCE * HVL_MIN_DISTANCE) {
        return vec3(0.0);
    }
    float inv_dist = inversesqrt(dist2);
    float dist = dist2 * inv_dist;
    inside = dist <= r;
    vec3 wj = v * inv_dist;
    // Eq. 21 in parts: the sender's cosine, then H (eq. 22).
    vec4 normal_area = imageLoad(hvl_records, hvl_record_texel(j, HVL_RECORD_NORMAL_AREA));
    vec3 hvl_normal = normal_area.xyz;
    float facing = -dot(hvl_normal, wj);
    if (!(facing > 0.0)) {
        return vec3(0.0);
    }
    float cos_r = dot(rc.n, wj);
    float cos_a;
    float h = hvl_cap_terms(dist, r, cos_r, cos_a);
    if (!(h > 0.0)) {
        return vec3(0.0);
    }
    // hvl_geometric_factor_of(facing, h, r), its 1 / (pi r^2) from the record.
    float g = facing * h * normal_area.w;
#if defined(HVL_VISIBILITY) && !defined(HVL_SHADOW_SAMPLES)
    if (!inside && trace_occluded_by(rc.origin, hvl_shadow_target(position_radius, hvl_normal))) {
        return vec3(0.0);
    }
#endif
    // The near field's share of the diffuse light is hvl_near.comp's.
    float far = hvl_far_weight(dist, rc.near_range);
    vec4 flux_e0 = imageLoad(hvl_records, hvl_record_texel(j, HVL_RECORD_FLUX_E0));
    vec4 e14 = imageLoad(hvl_records, hvl_record_texel(j, HVL_RECORD_EMISSION));
    float e_poly[HVL_EMISSION_MAX_BANDS] = float[](flux_e0.w, e14.x, e14.y, e14.z, e14.w);
    float e = max(0.0, hvl_poly_eval(e_poly, min(facing, 1.0)));
    if (rc.disc_falloff) {
        e *= hvl_disc_falloff(dist, r);
    }
    vec3 lj = flux_e0.rgb * (e * g);
    float cap[SH_BANDS];
    sh_cap_zh(cos_a, cap);
#ifdef HVL_FULL
    // wj in the receiver frame is unit already (t, b, n orthonormal).
    float y[SH_EVEN_COEFFS];
    sh_basis_even(vec3(dot(wj, rc.t), dot(wj, rc.b), cos_r), y);
    float diffuse = 0.0;
    float glossy = 0.0;
    SH_UNROLL for (int l = 0; l < SH_BANDS; ++l) {
        float band = 0.0;
        SH_UNROLL for (int m = 0; m < SH_BANDS; ++m) {
            if (m > l) {
                continue;
            }
            band += rc.glossy_even[l * (l + 1) / 2 + m] * y[l * (l + 1) / 2 + m];
        }
        diffuse += cap[l] * rc.lambert_zh[l] * y[l * (l + 1) / 2];
        glossy += cap[l] * band;
    }
    // The near field's traced light is diffuse: the glossy lobe keeps all of the HVL.
    return max(vec3(0.0), lj * (rc.kd * (far * diffuse) + rc.ks * glossy));
#else
    SH_UNROLL for (int l = 0; l < SH_BANDS; ++l) {
        cap[l] *= rc.win[l];
    }
    return max(vec3(0.0), lj * rc.kd * (far * hvl_zh_dot(cap, rc.cc, cos_r) / SH_PI));
#endif
}

void main() {
    ivec2 px = amortise_pixel(gl_GlobalInvocationID.xy, push.slice);
    if (px.x >= int(push.extent.x) || px.y >= int(push.extent.y)) {
        return;
    }
    // Only the receivers hvl_regather_mask marked.
    if (push.slice == AMORTISE_REGATHER_SLICE && imageLoad(indirect, px).a >= 0.0) {
        return;
    }
    vec4 position = imageLoad(recv_position, px);
    if (position.w == 0.0) {
        store_nothing(px);
        return;
    }
    Receiver rc;
    rc.near_range = push.near_range;
    rc.disc_falloff = push.disc_falloff != 0u;
    rc.x = position.xyz;
    rc.n = normalize(imageLoad(recv_normal, px).xyz);
    vec3 albedo = imageLoad(recv_albedo, px).rgb;
    vec2 roughness_metallic = imageLoad(recv_material, px).rg;
    float metallic = roughness_metallic.y;
    vec3 wo = normalize(push.camera.xyz - rc.x);
    float cos_o = dot(rc.n, wo);
    brdf_indirect_weights(albedo, metallic, cos_o, rc.kd, rc.ks);
    float win[SH_BANDS];
    SH_UNROLL for (int l = 0; l < SH_BANDS; ++l) {
        win[l] = push.window_width > 0.0 ? sh_window_sinc(l, push.window_width) : 1.0;
    }
#ifdef HVL_FULL
    rc.ks = brdf_table_fresnel_weight(rc.ks, cos_o) * (1.0 - specular_trace_weight(roughness_metallic.x, push.camera.w));
    if (cos_o <= 0.0) {
        store_nothing(px);
        return;
    }
    vec3 t = wo - rc.n * cos_o;
    if (dot(t, t) < 1e-12) {
        t = abs(rc.n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
        t -= rc.n * dot(rc.n, t);
    }
    rc.t = normalize(t);
    rc.b = cross(rc.n, rc.t);
    float theta_o = acos(min(cos_o, 1.0));
    float f_lambert[SH_COEFFS];
    float f_glossy[SH_COEFFS];
    brdf_row(0, theta_o, f_lambert);
    glossy_row(roughness_metallic.x, theta_o, f_glossy);
    SH_UNROLL for (int l = 0; l < SH_BANDS; ++l) {
        float k = win[l] * sh_zh_factor(l);
        rc.lambert_zh[l] = k * f_lambert[l * l + l];
        SH_UNROLL for (int m = 0; m < SH_BANDS; ++m) {
            if (m > l) {
                continue;
            }
            rc.glossy_even[l * (l + 1) / 2 + m] = k * f_glossy[l * l + l + m];
        }
    }
#else
    sh_clamped_cosine_zh(rc.cc);
    rc.win = win;
#endif
#ifdef HVL_VISIBILITY
    rc.origin = trace_offset(rc.x, rc.n);
#endif
    // The loops' bound, read once (a push constant: see Receiver.near_range).
    uint hvl_count = push.hvl_count;
#ifdef HVL_SHADOW_SAMPLES
    // The unshadowed sum and its weights (w_j = mean of c_j's channels), inside HVLs' spheres and
    // outside, and the weight the strata's rays found unblocked. The loops over HVLs carry no
    // per-stratum arrays and each stratum's ray is traced after its loop: lavapipe runs every
    // branch's and loop's code for every HVL whatever its condition (docs/pitfalls.md), so a
    // reservoir update that runs rarely still costs every pair.
    vec3 unshadowed_sum = vec3(0.0);
    float weight_inside = 0.0;
    float weight_total = 0.0;
    float weight_visible = 0.0;
    uint strata = clamp(push.shadow_rays, 1u, uint(HVL_SHADOW_RAYS_MAX));
    uint receiver_key = pcg(uint(px.x) + push.extent.x * uint(px.y) + pcg(push.seed));
    for (uint stratum = 0u; stratum < strata; ++stratum) {
        float weight = 0.0;
        uint pick = 0u;
        float best = HVL_SHADOW_NO_KEY;
        // Light by light (a light's records are consecutive, its first holds its count):
        // the stratum holds the samples whose index is `stratum` mod K.
        uint first = 0u;
        while (first < hvl_count) {
            uint samples = uint(imageLoad(hvl_records, hvl_record_texel(first, HVL_RECORD_IDENTITY)).z);
            // An empty slot (the flux distribution's tail) holds no count: the rest is one run.
            uint end = samples == 0u ? hvl_count : min(first + samples, hvl_count);
            for (uint j = first + stratum; j < end; j += strata) {
                bool inside;
                vec3 c = pair_light(rc, j, inside);
                unshadowed_sum += c;
                float w = (c.r + c.g + c.b) * (1.0 / 3.0);
                weight_inside += inside ? w : 0.0;
                float w_out = inside ? 0.0 : w;
                weight += w_out;
                // The race: HVL j's key -ln(u_j) / w_j against the least so far (compared as
                // products; w_out = 0 never wins).
                vec2 identity = imageLoad(hvl_records, hvl_record_texel(j, HVL_RECORD_IDENTITY)).xy;
                float e = -log(hvl_shadow_uniform(receiver_key, identity));
                bool take = e < best * w_out;
                best = take ? e / w_out : best;
                pick = take ? j : pick;
            }
            first = end;
        }
        if (weight > 0.0) {
            vec4 position_radius = imageLoad(hvl_records, hvl_record_texel(pick, HVL_RECORD_POSITION_RADIUS));
            vec3 hvl_normal = imageLoad(hvl_records, hvl_record_texel(pick, HVL_RECORD_NORMAL_AREA)).xyz;
            vec3 target = hvl_shadow_target(position_radius, hvl_normal);
            weight_visible += trace_occluded_by(rc.origin, target) ? 0.0 : weight;
        }
        weight_total += weight;
    }
    // The shadowed weight: the HVLs the receiver is inside of, plus the strata's visible weight.
    float shadowed_weight = weight_inside + weight_visible;
    float unshadowed_weight = weight_inside + weight_total;
    // The receiver's own ratio; scattered regathered receivers (amortised frames) have no
    // refreshed neighbours to filter with and keep it, the history smooths it.
    vec3 sum = unshadowed_weight > 0.0 ? unshadowed_sum * min(1.0, shadowed_weight / unshadowed_weight) : vec3(0.0);
    imageStore(unshadowed, px, vec4(unshadowed_sum, unshadowed_weight));
    if (push.slice != AMORTISE_REGATHER_SLICE) {
        imageStore(indirect, px, vec4(sum, shadowed_weight));
        return;
    }
#else
    vec3 sum = vec3(0.0);
    for (uint j = 0u; j < hvl_count; ++j) {
        bool inside;
        sum += pair_light(rc, j, inside);
    }
#endif
    imageStore(indirect, px, vec4(sum, 0.0));
}
