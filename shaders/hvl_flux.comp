// HVL cache by flux (shine's distribution, hvl.distribution = "flux"; paper 003 §5.2 cuts the
// RSM uniformly instead, hvl_cache.comp). M texels of the S*S RSM are drawn in proportion to
// their flux weight w = r + g + b (0 for an empty texel) by a fixed two-dimensional pattern:
// HVL m takes the row where the running sum of the row totals passes (m + 1/2)/M of the total,
// then the texel of that row where the running sum passes v_m of the row's total, v_m the
// base-2 radical inverse of m (the Hammersley set, warped by the flux). Every HVL carries Phi/M
// of the weight: flux = texel flux * Phi / (M w), from its own texel's position and normal.
// Its radius is r2 from the local spacing (shine_sh::hvl::radius_spacing) times the user scale.
//
// Comparisons are written as products (a * 2M > (2m + 1) * total), never quotients. IEEE
// products and sums are correctly rounded on every Vulkan device, so the GPU picks the same
// texels as the CPU twin (shine::reference::hvl_flux).
//
// `rows`: one invocation per RSM row; cdf[y S + x] is the running sum of the weights of row y
// up to x, and cdf[S S + y] is the row's total.
// `build`: one invocation per HVL.
//! variant rows HVL_FLUX_ROWS=1
//! variant build HVL_FLUX_BUILD=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D rsm_position;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D rsm_flux;

#ifdef HVL_FLUX_ROWS
layout(set = 0, binding = 4, std430) buffer Cdf {
    float c[];
} cdf;
#else
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D rsm_normal;
layout(set = 0, binding = 4, std430) readonly buffer Cdf {
    float c[];
} cdf;
layout(set = 0, binding = 3, std430) buffer Hvls {
    Hvl h[];
} hvls;
#endif

// shine::passes::hvl::CachePush (rows and use_r2 unused here)
layout(push_constant) uniform Push {
    // xyz: light position (perspective) or RSM eye (orthographic); w: fov lambda (radians) or
    // width W (metres)
    vec4 light_position_extent;
    // xyz: unit axis of the RSM view; w: 1 orthographic, 0 perspective
    vec4 light_direction_ortho;
    // RSM side S
    uint rsm_size;
    // HVL count M
    uint count;
    uint rows;
    uint use_r2;
    // user radius scale k (1-2, paper 003 §5.3)
    float radius_scale;
} push;

// The flux weight of texel t: r + g + b of its flux, 0 for an empty texel
// (shine::reference::hvl_flux::texel_weight).
float texel_weight(ivec2 t) {
    if (imageLoad(rsm_position, t).w == 0.0) {
        return 0.0;
    }
    vec3 f = imageLoad(rsm_flux, t).rgb;
    return max(f.r + f.g + f.b, 0.0);
}

#ifdef HVL_FLUX_ROWS
void main() {
    uint y = gl_GlobalInvocationID.x;
    uint s = push.rsm_size;
    if (y >= s) {
        return;
    }
    float sum = 0.0;
    for (uint x = 0u; x < s; ++x) {
        sum += texel_weight(ivec2(x, y));
        cdf.c[y * s + x] = sum;
    }
    cdf.c[s * s + y] = sum;
}
#else
// The first x of row y whose running sum exceeds `target`, or, when none does (target at the
// row's total), reaches it: a texel of positive weight either way.
uint find_column(uint y, float target, float row_total) {
    uint s = push.rsm_size;
    bool at_total = target >= row_total;
    uint lo = 0u;
    uint hi = s - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        float c = cdf.c[y * s + mid];
        if (at_total ? c >= row_total : c > target) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

void main() {
    uint m = gl_GlobalInvocationID.x;
    if (m >= push.count) {
        return;
    }
    uint s = push.rsm_size;
    float total = 0.0;
    for (uint y = 0u; y < s; ++y) {
        total += cdf.c[s * s + y];
    }
    vec4 position_radius = vec4(0.0);
    vec4 normal_distance = vec4(0.0);
    vec4 flux_valid = vec4(0.0);
    float emission_scale = 0.0;
    if (total > 0.0) {
        // The row: the first whose running sum a passes (m + 1/2)/M of the total.
        float goal = float(2u * m + 1u) * total;
        float twice_count = float(2u * push.count);
        float running = 0.0;
        uint y = s - 1u;
        for (uint j = 0u; j < s; ++j) {
            running += cdf.c[s * s + j];
            if (running * twice_count > goal) {
                y = j;
                break;
            }
        }
        // The texel: where the row's running sum passes v_m of its total (24-bit radical
        // inverse, exact in float).
        float row_total = cdf.c[s * s + y];
        float v = float(bitfieldReverse(m) >> 8u) * (1.0 / 16777216.0);
        ivec2 t = ivec2(find_column(y, v * row_total, row_total), y);
        float w = texel_weight(t);
        vec3 p = imageLoad(rsm_position, t).xyz;
        vec3 n = normalize(imageLoad(rsm_normal, t).xyz);
        bool ortho = push.light_direction_ortho.w > 0.5;
        vec3 axis = push.light_direction_ortho.xyz;
        vec3 from_light = p - push.light_position_extent.xyz;
        float d = ortho ? dot(from_light, axis) : length(from_light);
        vec3 to_surface = ortho ? axis : from_light / d;
        float area = hvl_rsm_texel_area(ortho, push.light_position_extent.w, float(s), d, dot(to_surface, axis), dot(n, -to_surface));
        float r = hvl_radius_spacing(area, w, total, float(push.count)) * push.radius_scale;
        position_radius = vec4(p, r);
        normal_distance = vec4(n, d);
        flux_valid = vec4(imageLoad(rsm_flux, t).rgb * (total / (float(push.count) * w)), 1.0);
        emission_scale = 1.0;
    }
    // Field by field: naga cannot read the OpCopyLogical of a whole-struct store.
    hvls.h[m].position_radius = position_radius;
    hvls.h[m].normal_distance = normal_distance;
    hvls.h[m].flux = flux_valid;
    // eq. 20: F' of the Lambert sender is 1/pi in every direction, band 0 only
    // (shine::reference::hvl::sender_emission_zh)
    for (int l = 0; l < 8; ++l) {
        hvls.h[m].emission[l] = l == 0 ? emission_scale * SH_SQRT_4PI / SH_PI : 0.0;
    }
}
#endif
