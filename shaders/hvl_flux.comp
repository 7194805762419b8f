// HVL cache by flux (shine's distribution, hvl.distribution = "flux"; paper 003 §5.2 cuts one
// light's RSM uniformly instead, hvl_cache.comp) over the RSM faces of every light: a spot or
// directional light has one face, a point light six (cube faces). M texels of all the faces
// are drawn in proportion to their flux weight w = r + g + b (0 for an empty texel), so the
// HVL budget is split between the lights by the flux they reflect. The faces' rows are
// numbered one after the other, face by face (a global row r). HVL m takes the row where the
// running sum of the row totals passes (m + 1/2)/M of the total, then the texel of that row
// where the row's running sum passes v_m of its total, v_m the base-2 radical inverse of m
// (the Hammersley set, warped by the flux). Every HVL carries Phi/M of the weight:
// flux = texel flux * Phi / (M w), from its own texel's position and normal. Its radius is r2
// from the local spacing (shine_sh::hvl::radius_spacing) times the user scale.
//
// Comparisons are written as products (a * 2M > (2m + 1) * total), never quotients. IEEE
// products and sums are correctly rounded on every Vulkan device, so the GPU picks the same
// texels as the CPU twin (shine::reference::hvl_flux).
//
// `cdf` holds T running sums (face f's S_f * S_f at texel_offset_f, row by row), then the R
// row totals (global row order), then their R running sums (T = sum S_f^2, R = sum S_f).
// `rows`: one invocation per row of one face (a dispatch per face): its running sums and total.
// `marginal`: one invocation: the running sums of the row totals.
// `build`: one invocation per HVL, a dispatch per face: HVL m is written by the dispatch of
// the face its row falls in (by face 0 as an empty record when no face holds any flux).
//! variant rows HVL_FLUX_ROWS=1
//! variant marginal HVL_FLUX_MARGINAL=1
//! variant build HVL_FLUX_BUILD=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"

layout(local_size_x = 64) in;

#ifndef HVL_FLUX_MARGINAL
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D rsm_position;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D rsm_flux;
#endif

#ifdef HVL_FLUX_BUILD
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D rsm_normal;
layout(set = 0, binding = 4, std430) readonly buffer Cdf {
    float c[];
} cdf;
layout(set = 0, binding = 3, std430) buffer Hvls {
    Hvl h[];
} hvls;
#else
layout(set = 0, binding = 4, std430) buffer Cdf {
    float c[];
} cdf;
#endif

// shine::passes::hvl::FluxPush
layout(push_constant) uniform Push {
    // xyz: this face's light position (perspective) or RSM eye (orthographic); w: fov lambda
    // (radians) or width W (metres)
    vec4 light_position_extent;
    // xyz: unit axis of the face's view; w: 1 orthographic, 0 perspective
    vec4 light_direction_ortho;
    // this face's side S_f, its first running sum, its first global row
    uint face_size;
    uint texel_offset;
    uint row_offset;
    // R = sum S_f, T = sum S_f^2
    uint rows_total;
    uint texels_total;
    // HVL count M
    uint count;
    // user radius scale k (1-2, paper 003 §5.3)
    float radius_scale;
    uint pad;
} push;

#ifndef HVL_FLUX_MARGINAL
// The flux weight of texel t: r + g + b of its flux, 0 for an empty texel
// (shine::reference::hvl_flux::texel_weight).
float texel_weight(ivec2 t) {
    if (imageLoad(rsm_position, t).w == 0.0) {
        return 0.0;
    }
    vec3 f = imageLoad(rsm_flux, t).rgb;
    return max(f.r + f.g + f.b, 0.0);
}
#endif

#ifdef HVL_FLUX_ROWS
void main() {
    uint y = gl_GlobalInvocationID.x;
    uint s = push.face_size;
    if (y >= s) {
        return;
    }
    float sum = 0.0;
    for (uint x = 0u; x < s; ++x) {
        sum += texel_weight(ivec2(x, y));
        cdf.c[push.texel_offset + y * s + x] = sum;
    }
    cdf.c[push.texels_total + push.row_offset + y] = sum;
}
#elif defined(HVL_FLUX_MARGINAL)
void main() {
    if (gl_GlobalInvocationID.x != 0u) {
        return;
    }
    float sum = 0.0;
    for (uint r = 0u; r < push.rows_total; ++r) {
        sum += cdf.c[push.texels_total + r];
        cdf.c[push.texels_total + push.rows_total + r] = sum;
    }
}
#else
// The first x of a face row (its running sums from `first`) whose running sum exceeds
// `target`, or, when none does (target at the row's total), reaches it: a texel of positive
// weight either way.
uint find_column(uint first, float target, float row_total) {
    bool at_total = target >= row_total;
    uint lo = 0u;
    uint hi = push.face_size - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        float c = cdf.c[first + mid];
        if (at_total ? c >= row_total : c > target) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    return lo;
}

void write_hvl(uint m, vec4 position_radius, vec4 normal_distance, vec4 flux_valid, float emission_scale) {
    // Field by field: naga cannot read the OpCopyLogical of a whole-struct store.
    hvls.h[m].position_radius = position_radius;
    hvls.h[m].normal_distance = normal_distance;
    hvls.h[m].flux = flux_valid;
    for (int l = 0; l < 8; ++l) {
        hvls.h[m].emission[l] = emission_scale * hvl_sender_emission(l);
    }
}

void main() {
    uint m = gl_GlobalInvocationID.x;
    if (m >= push.count) {
        return;
    }
    uint marginal = push.texels_total + push.rows_total;
    float total = cdf.c[marginal + push.rows_total - 1u];
    if (!(total > 0.0)) {
        if (push.row_offset == 0u) {
            write_hvl(m, vec4(0.0), vec4(0.0), vec4(0.0), 0.0);
        }
        return;
    }
    // The global row: the first whose running sum a passes (m + 1/2)/M of the total.
    float goal = float(2u * m + 1u) * total;
    float twice_count = float(2u * push.count);
    uint lo = 0u;
    uint hi = push.rows_total - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (cdf.c[marginal + mid] * twice_count > goal) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    if (lo < push.row_offset || lo >= push.row_offset + push.face_size) {
        return;
    }
    uint s = push.face_size;
    uint y = lo - push.row_offset;
    // The texel: where the row's running sum passes v_m of its total (24-bit radical inverse,
    // exact in float).
    float row_total = cdf.c[push.texels_total + lo];
    float v = float(bitfieldReverse(m) >> 8u) * (1.0 / 16777216.0);
    ivec2 t = ivec2(find_column(push.texel_offset + y * s, v * row_total, row_total), y);
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
    vec3 flux = imageLoad(rsm_flux, t).rgb * (total / (float(push.count) * w));
    write_hvl(m, vec4(p, r), vec4(n, d), vec4(flux, 1.0), 1.0);
}
#endif
