// HVL cache (paper 003 §5.2-5.3): distributes M Harmonics Virtual Lights over the RSM.
//
// `build`: the S*S RSM is cut into exactly M cells (shine::passes::hvl::HvlGrid: R rows of equal
// height, row j holding cells floor(jM/R)..floor((j+1)M/R) of equal width; a K*K grid when
// M = K*K). Each cell gives one HVL: its position and normal are those of the cell's valid texel
// nearest the cell centre (first in row-major order on a tie), its flux is the sum of the flux
// of every valid texel of the cell (so the light's reflected power is conserved for any M), its
// emission is the sender's F' (Lambert: 1/pi in every direction, band 0 only, eq. 20). Radius r2
// (eq. 24-26; for an orthographic RSM sqrt(2) W / sqrt(M)) here; with r1 the radius is left 0
// for the `r1` stage. A cell without a valid texel is an empty HVL (flux.a = 0, radius 0): the
// gather skips it. The distance d_j to the light is Euclidean (perspective) or along the
// light's direction (orthographic).
//
// `r1`: radius heuristic r1 (eq. 23) over the cell's neighbours (HvlGrid::neighbours); an HVL
// without a usable neighbour falls back to r2. Both stages apply the user scale.
// CPU twin: shine::reference::hvl::build_cache.
//! variant build HVL_STAGE_BUILD=1
//! variant r1 HVL_STAGE_R1=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"

layout(local_size_x = 64) in;

#ifdef HVL_STAGE_BUILD
layout(set = 0, binding = 0, rgba32f) readonly uniform image2D rsm_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D rsm_normal;
layout(set = 0, binding = 2, rgba32f) readonly uniform image2D rsm_flux;
#else
layout(set = 0, binding = 0, std430) readonly buffer Source {
    Hvl h[];
} source;
#endif

layout(set = 0, binding = 3, std430) buffer Hvls {
    Hvl h[];
} hvls;

// shine::passes::hvl::CachePush
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
    // rows R of the cell grid
    uint rows;
    // 1: r2 in the build stage; 0: the r1 stage sets the radius
    uint use_r2;
    // user radius scale k (1-2, paper 003 §5.3)
    float radius_scale;
} push;

// eq. 23, paper 003: epsilon of the weights w_n = 1 / (|d - d_n| + epsilon), metres
const float HVL_R1_EPSILON = 1e-3;

bool orthographic() {
    return push.light_direction_ortho.w > 0.5;
}

float r2_radius(float light_distance) {
    if (orthographic()) {
        return hvl_radius_r2_orthographic(push.light_position_extent.w, float(push.count));
    }
    return hvl_radius_r2(light_distance, push.light_position_extent.w, float(push.count));
}

// HvlGrid::row_start
uint row_start(uint j) {
    return j * push.count / push.rows;
}

// HvlGrid::row_of: ceil((m + 1) R / M) - 1
uint row_of(uint m) {
    return ((m + 1u) * push.rows + push.count - 1u) / push.count - 1u;
}

// HvlGrid::cell: texels [lo, hi) of cell m
void cell_rect(uint m, out uvec2 lo, out uvec2 hi) {
    uint j = row_of(m);
    uint first = row_start(j);
    uint n = row_start(j + 1u) - first;
    uint i = m - first;
    uint s = push.rsm_size;
    lo = uvec2(i * s / n, j * s / push.rows);
    hi = uvec2((i + 1u) * s / n, (j + 1u) * s / push.rows);
}

void main() {
    uint index = gl_GlobalInvocationID.x;
    if (index >= push.count) {
        return;
    }
#ifdef HVL_STAGE_BUILD
    uvec2 lo;
    uvec2 hi;
    cell_rect(index, lo, hi);
    vec2 centre = 0.5 * vec2(lo + hi);
    float best = 3.0e38;
    ivec2 rep = ivec2(-1);
    vec3 flux = vec3(0.0);
    for (uint y = lo.y; y < hi.y; ++y) {
        for (uint x = lo.x; x < hi.x; ++x) {
            ivec2 t = ivec2(x, y);
            if (imageLoad(rsm_position, t).w == 0.0) {
                continue;
            }
            flux += imageLoad(rsm_flux, t).rgb;
            vec2 off = vec2(t) + 0.5 - centre;
            float d2 = dot(off, off);
            if (d2 < best) {
                best = d2;
                rep = t;
            }
        }
    }
    // Field by field: naga cannot read the OpCopyLogical of a whole-struct store.
    vec4 position_radius = vec4(0.0);
    vec4 normal_distance = vec4(0.0);
    vec4 flux_valid = vec4(0.0);
    float emission_scale = 0.0;
    if (rep.x >= 0) {
        vec3 p = imageLoad(rsm_position, rep).xyz;
        vec3 n = normalize(imageLoad(rsm_normal, rep).xyz);
        vec3 from_light = p - push.light_position_extent.xyz;
        float d = orthographic() ? dot(from_light, push.light_direction_ortho.xyz) : length(from_light);
        float r = push.use_r2 != 0u ? r2_radius(d) * push.radius_scale : 0.0;
        position_radius = vec4(p, r);
        normal_distance = vec4(n, d);
        flux_valid = vec4(flux, 1.0);
        emission_scale = 1.0;
    }
    hvls.h[index].position_radius = position_radius;
    hvls.h[index].normal_distance = normal_distance;
    hvls.h[index].flux = flux_valid;
    for (int l = 0; l < HVL_EMISSION_MAX_BANDS; ++l) {
        hvls.h[index].emission[l] = emission_scale * hvl_sender_emission(l);
    }
    // Identity: the grid holds the primary light's cells alone, cell `index`.
    hvls.h[index].light = 0u;
    hvls.h[index].sample_index = index;
    hvls.h[index].light_samples = push.count;
#else
    vec4 position_radius = source.h[index].position_radius;
    float d = source.h[index].normal_distance.w;
    if (source.h[index].flux.a != 0.0) {
        vec3 p = position_radius.xyz;
        float num = 0.0;
        float den = 0.0;
        uint j = row_of(index);
        uvec2 lo;
        uvec2 hi;
        cell_rect(index, lo, hi);
        for (int dj = -1; dj <= 1; ++dj) {
            int jj = int(j) + dj;
            if (jj < 0 || jj >= int(push.rows)) {
                continue;
            }
            uint first = row_start(uint(jj));
            uint n = row_start(uint(jj) + 1u) - first;
            // HvlGrid::neighbours: the cell of row jj under this cell's centre
            uint c = dj == 0 ? index - first : min((lo.x + hi.x) * n / (2u * push.rsm_size), n - 1u);
            for (int di = -1; di <= 1; ++di) {
                int ii = int(c) + di;
                if ((dj == 0 && di == 0) || ii < 0 || ii >= int(n)) {
                    continue;
                }
                uint m = first + uint(ii);
                if (source.h[m].flux.a == 0.0) {
                    continue;
                }
                // eq. 23, paper 003 (shine_sh::hvl::radius_r1)
                float w = 1.0 / (abs(d - source.h[m].normal_distance.w) + HVL_R1_EPSILON);
                num += w * distance(p, source.h[m].position_radius.xyz);
                den += w;
            }
        }
        float r = den > 0.0 ? num / den : 0.0;
        if (!(r > 0.0)) {
            r = r2_radius(d);
        }
        position_radius.w = r * push.radius_scale;
    }
    hvls.h[index].position_radius = position_radius;
    hvls.h[index].normal_distance = source.h[index].normal_distance;
    hvls.h[index].flux = source.h[index].flux;
    for (int l = 0; l < HVL_EMISSION_MAX_BANDS; ++l) {
        hvls.h[index].emission[l] = source.h[index].emission[l];
    }
    hvls.h[index].light = source.h[index].light;
    hvls.h[index].sample_index = source.h[index].sample_index;
    hvls.h[index].light_samples = source.h[index].light_samples;
#endif
}
