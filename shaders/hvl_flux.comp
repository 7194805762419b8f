// HVL cache by flux (shine's distribution, hvl.distribution = "flux"; paper 003 §5.2 cuts one
// light's RSM uniformly instead, hvl_cache.comp) over the RSM faces of every light (a spot or
// directional light has one face, a point light six cube faces, consecutive). Texels are drawn
// in proportion to their flux weight w = r + g + b (0 for an empty texel).
//
// Samples with identities (issue 43). Each RSM face is a "light" k here, with its own
// sequence (a point light's six cube faces are six: one sequence over the six ran from one
// face's last row into the next face's first, so a sample could step across the room when
// flux moved between faces; push.light_id is shine::passes::hvl::flux::sequence_id). Light k
// owns the progressive sequence j = 0, 1, 2, ... of Sobol (0, 2)-sequence points (u_j, v_j)
// (sobol_02, random.glsl: every prefix of 2^k points is stratified), warped through its own
// flux: sample j takes the light's row where the light's running row sum passes u_j of its
// total Phi_k, then the texel of that row where the row's running sum passes v_j of the row's
// total. A point's place depends on j and on that light's flux
// alone, never on the budget or on the other lights, so when a light moves its samples slide
// with it, and when a light's share changes the others' stay put.
// The budget: M' = M - (N - 1) samples (N lights) split by flux, s_k = M' Phi_k / Phi; light k
// keeps n_k = ceil(s_k) samples, the last faded by the fractional part of s_k (weight
// clamp(s_k - j, 0, 1)), so a share that grows fades its newest sample in instead of redrawing
// the set. Sum n_k <= M. Every sample carries Phi / M' times its weight.
// Positions come from a continuous inverse: where the target falls within its texel's share
// of the running sum (f in [0, 1) across the row, g down the rows) places the sample between
// texel centres, bilinearly among the texel and its neighbours on the side it leans to that
// lie on the same surface (hvl_flux_blend).
// Record m = offset_k + j (offsets in light order) stores its identity (light, j); empty slots
// are zero (the buffer is cleared first).
//
// Comparisons that pick texels are written as products (a > u * total), never quotients: IEEE
// products and sums are correctly rounded on every Vulkan device, so the GPU picks the same
// texels as the CPU twin (shine::reference::hvl_flux).
//
// `cdf` holds T running sums (face f's S_f * S_f at texel_offset_f, row by row), then the R
// row totals (global row order), then the R running sums of the row totals, restarted at each
// light's first row, then the light table: [Phi, M', 0, 0] and per light k [Phi_k, s_k, n_k,
// offset_k] (T = sum S_f^2, R = sum S_f).
// `rows`: one invocation per row of one face (a dispatch per face): its running sums and total.
// `marginal`: one invocation per light (a dispatch per light): its rows' running sums, Phi_k.
// `budget`: one invocation: Phi, M', and every light's s_k, n_k and offset_k.
// `build`: one invocation per sample j of one light, a dispatch per face: sample j is written
// by the dispatch of the face its row falls in.
//! variant rows HVL_FLUX_ROWS=1
//! variant marginal HVL_FLUX_MARGINAL=1
//! variant budget HVL_FLUX_BUDGET=1
//! variant build HVL_FLUX_BUILD=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"
#include "sample_identity.glsl"
#include "random.glsl"

layout(local_size_x = 64) in;

#if defined(HVL_FLUX_ROWS) || defined(HVL_FLUX_BUILD)
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
    // this face's light: its first global row, its row count, its place k in the light order,
    // its index in the scene (the samples' identity)
    uint light_row_offset;
    uint light_rows;
    uint light_order;
    uint light_id;
    // N: lights
    uint light_count;
} push;

// The light table's first float.
uint light_table() {
    return push.texels_total + 2u * push.rows_total;
}

#if defined(HVL_FLUX_ROWS) || defined(HVL_FLUX_BUILD)
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
    uint first = push.texels_total + push.light_row_offset;
    for (uint r = 0u; r < push.light_rows; ++r) {
        sum += cdf.c[first + r];
        cdf.c[first + push.rows_total + r] = sum;
    }
    cdf.c[light_table() + 4u * (push.light_order + 1u)] = sum;
}
#elif defined(HVL_FLUX_BUDGET)
void main() {
    if (gl_GlobalInvocationID.x != 0u) {
        return;
    }
    uint table = light_table();
    float total = 0.0;
    for (uint k = 0u; k < push.light_count; ++k) {
        total += cdf.c[table + 4u * (k + 1u)];
    }
    uint budget = hvl_flux_budget(push.count, push.light_count);
    cdf.c[table] = total;
    cdf.c[table + 1u] = float(budget);
    uint offset = 0u;
    for (uint k = 0u; k < push.light_count; ++k) {
        uint e = table + 4u * (k + 1u);
        float light_total = cdf.c[e];
        uint n = total > 0.0 ? hvl_flux_light_count(budget, light_total, total) : 0u;
        n = min(n, push.count - offset);
        cdf.c[e + 1u] = total > 0.0 ? float(budget) * light_total / total : 0.0;
        cdf.c[e + 2u] = float(n);
        cdf.c[e + 3u] = float(offset);
        offset += n;
    }
}
#else
// A sample's surface, blended from its texel and the neighbours it leans towards.
struct HvlFluxTexel {
    vec3 position;
    vec3 normal;
    // rgb of the flux over its weight (r + g + b = 1)
    vec3 chroma;
    // the flux weight, bilinear (the local density of samples, for the radius)
    float weight;
};

// The continuous inverse: a sample at fraction (f, g) of texel t's share lies between t's
// centre and the neighbours on the side it leans to, with bilinear weights, over the
// neighbours on t's own surface: not empty, on the face, normals within acos
// HVL_FLUX_BLEND_NORMAL_COS and the step to them within the plane (its component along t's
// normal at most HVL_FLUX_BLEND_PLANE of its length). At a crease or an RSM depth step the
// sample stops at its texel's edge and steps to the other surface there (the stable rule):
// blending across put HVLs in mid-air and lost 4% of the cornell box's indirect light.
const float HVL_FLUX_BLEND_NORMAL_COS = 0.9;
const float HVL_FLUX_BLEND_PLANE = 0.25;
HvlFluxTexel hvl_flux_blend(ivec2 t, float f, float g) {
    ivec2 dir = ivec2(f < 0.5 ? -1 : 1, g < 0.5 ? -1 : 1);
    vec2 lean = abs(vec2(f, g) - 0.5);
    vec3 position = vec3(0.0);
    vec3 normal = vec3(0.0);
    vec3 flux = vec3(0.0);
    float weight = 0.0;
    float total = 0.0;
    int s = int(push.face_size);
    vec3 own_position = imageLoad(rsm_position, t).xyz;
    vec3 own_normal = normalize(imageLoad(rsm_normal, t).xyz);
    for (int b = 0; b < 2; ++b) {
        for (int a = 0; a < 2; ++a) {
            ivec2 q = t + ivec2(a * dir.x, b * dir.y);
            if (q.x < 0 || q.y < 0 || q.x >= s || q.y >= s || imageLoad(rsm_position, q).w == 0.0) {
                continue;
            }
            vec3 step_to = imageLoad(rsm_position, q).xyz - own_position;
            bool same_surface = dot(normalize(imageLoad(rsm_normal, q).xyz), own_normal) >= HVL_FLUX_BLEND_NORMAL_COS
                && abs(dot(step_to, own_normal)) <= HVL_FLUX_BLEND_PLANE * length(step_to);
            if (!same_surface) {
                continue;
            }
            float k = (a == 1 ? lean.x : 1.0 - lean.x) * (b == 1 ? lean.y : 1.0 - lean.y);
            float w = texel_weight(q);
            position += k * imageLoad(rsm_position, q).xyz;
            normal += k * normalize(imageLoad(rsm_normal, q).xyz);
            flux += k * imageLoad(rsm_flux, q).rgb;
            weight += k * w;
            total += k;
        }
    }
    HvlFluxTexel o;
    o.position = position / total;
    o.normal = normalize(normal);
    o.chroma = flux / weight;
    o.weight = weight / total;
    return o;
}

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

void write_hvl(uint m, vec4 position_radius, vec4 normal_distance, vec4 flux_valid, uint sample_index, uint light_samples) {
    // Field by field: naga cannot read the OpCopyLogical of a whole-struct store.
    hvls.h[m].position_radius = position_radius;
    hvls.h[m].normal_distance = normal_distance;
    hvls.h[m].flux = flux_valid;
    for (int l = 0; l < HVL_EMISSION_MAX_BANDS; ++l) {
        hvls.h[m].emission[l] = hvl_sender_emission(l);
    }
    hvls.h[m].light = push.light_id;
    hvls.h[m].sample_index = sample_index;
    hvls.h[m].light_samples = light_samples;
}

void main() {
    uint j = gl_GlobalInvocationID.x;
    uint table = light_table();
    uint e = table + 4u * (push.light_order + 1u);
    float light_total = cdf.c[e];
    float share = cdf.c[e + 1u];
    uint n = uint(cdf.c[e + 2u]);
    if (j >= n) {
        return;
    }
    uint slot = uint(cdf.c[e + 3u]) + j;
    // The light's row: the first whose running sum passes u_j of the light's total.
    uint marginal = push.texels_total + push.rows_total + push.light_row_offset;
    // Sample j's point: the (0, 2)-sequence's j-th, shifted by a half (a digital shift keeps
    // the stratification) so a light's first sample sits at the middle of its flux.
    vec2 point = sobol_02(j, uvec2(HVL_FLUX_SOBOL_SHIFT));
    float row_goal = point.x * light_total;
    uint lo = 0u;
    uint hi = push.light_rows - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (cdf.c[marginal + mid] > row_goal) {
            hi = mid;
        } else {
            lo = mid + 1u;
        }
    }
    uint row = push.light_row_offset + lo;
    if (row < push.row_offset || row >= push.row_offset + push.face_size) {
        return;
    }
    uint s = push.face_size;
    uint y = row - push.row_offset;
    // The texel: where the row's running sum passes v_j of its total.
    float row_total = cdf.c[push.texels_total + row];
    float target = point.y * row_total;
    uint first = push.texel_offset + y * s;
    uint x = find_column(first, target, row_total);
    // Where the targets fall within the texel's share: f across, g down.
    float w = texel_weight(ivec2(x, y));
    float before_x = x > 0u ? cdf.c[first + x - 1u] : 0.0;
    float f = clamp((target - before_x) / w, 0.0, 1.0);
    float before_y = lo > 0u ? cdf.c[marginal + lo - 1u] : 0.0;
    float g = clamp((row_goal - before_y) / row_total, 0.0, 1.0);
    HvlFluxTexel t = hvl_flux_blend(ivec2(x, y), f, g);
    bool ortho = push.light_direction_ortho.w > 0.5;
    vec3 axis = push.light_direction_ortho.xyz;
    vec3 from_light = t.position - push.light_position_extent.xyz;
    float d = ortho ? dot(from_light, axis) : length(from_light);
    vec3 to_surface = ortho ? axis : from_light / d;
    float area = hvl_rsm_texel_area(ortho, push.light_position_extent.w, float(s), d, dot(to_surface, axis), dot(t.normal, -to_surface));
    float total = cdf.c[table];
    float budget = cdf.c[table + 1u];
    float r = hvl_radius_spacing(area, t.weight, total, budget) * push.radius_scale;
    float fade = clamp(share - float(j), 0.0, 1.0);
    vec3 flux = t.chroma * (total * fade / budget);
    write_hvl(slot, vec4(t.position, r), vec4(t.normal, d), vec4(flux, 1.0), j, n);
}
#endif
