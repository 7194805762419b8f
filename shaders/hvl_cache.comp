// HVL cache (paper 003 §5.2-5.3): distributes M = K*K Harmonics Virtual Lights over the RSM.
//
// `build`: the S*S RSM is cut into a regular K*K grid of cells (cell c covers texels
// [c*S/K, (c+1)*S/K) on each axis). Each cell gives one HVL: its position and normal are those
// of the cell's valid texel nearest the cell centre (first in row-major order on a tie), its
// flux is the sum of the flux of every valid texel of the cell (so the light's reflected power
// is conserved for any M), its emission is the sender's F' (Lambert: cap ZH of the hemisphere
// / pi, eq. 20). Radius r2 (eq. 24-26) here; with r1 the radius is left 0 for the `r1` stage.
// A cell without a valid texel is an empty HVL (flux.a = 0, radius 0): the gather skips it.
//
// `r1`: radius heuristic r1 (eq. 23) over the 8-connected valid neighbours in the K*K grid;
// an HVL without a usable neighbour falls back to r2. Both stages apply the user scale.
// CPU twin: shine::hvl_reference::build_cache.
//! variant build HVL_STAGE_BUILD=1
//! variant r1 HVL_STAGE_R1=1
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

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
    // xyz: primary light position; w: RSM field of view lambda (radians)
    vec4 light_position_fov;
    // RSM side S
    uint rsm_size;
    // HVL grid side K (M = K*K)
    uint grid;
    // 1: r2 in the build stage; 0: the r1 stage sets the radius
    uint use_r2;
    // user radius scale k (1-2, paper 003 §5.3)
    float radius_scale;
} push;

// eq. 23, paper 003: epsilon of the weights w_n = 1 / (|d - d_n| + epsilon), metres
const float HVL_R1_EPSILON = 1e-3;

float r2_radius(float light_distance) {
    return hvl_radius_r2(light_distance, push.light_position_fov.w, float(push.grid * push.grid));
}

void main() {
    uvec2 c = gl_GlobalInvocationID.xy;
    uint k = push.grid;
    if (c.x >= k || c.y >= k) {
        return;
    }
    uint index = c.y * k + c.x;
#ifdef HVL_STAGE_BUILD
    uint s = push.rsm_size;
    uvec2 lo = c * s / k;
    uvec2 hi = (c + 1u) * s / k;
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
        float d = distance(p, push.light_position_fov.xyz);
        float r = push.use_r2 != 0u ? r2_radius(d) * push.radius_scale : 0.0;
        position_radius = vec4(p, r);
        normal_distance = vec4(n, d);
        flux_valid = vec4(flux, 1.0);
        emission_scale = 1.0;
    }
    hvls.h[index].position_radius = position_radius;
    hvls.h[index].normal_distance = normal_distance;
    hvls.h[index].flux = flux_valid;
    // eq. 20: F' of the Lambert sender (albedo in the flux) = hemisphere cap ZH / pi
    float zh[SH_BANDS];
    sh_cap_zh(0.0, zh);
    for (int l = 0; l < 8; ++l) {
        hvls.h[index].emission[l] = l < HVL_EMISSION_MAX_BANDS ? emission_scale * zh[l] / SH_PI : 0.0;
    }
#else
    vec4 position_radius = source.h[index].position_radius;
    float d = source.h[index].normal_distance.w;
    if (source.h[index].flux.a != 0.0) {
        vec3 p = position_radius.xyz;
        float num = 0.0;
        float den = 0.0;
        for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
                ivec2 q = ivec2(c) + ivec2(dx, dy);
                if ((dx == 0 && dy == 0) || q.x < 0 || q.y < 0 || q.x >= int(k) || q.y >= int(k)) {
                    continue;
                }
                uint m = uint(q.y) * k + uint(q.x);
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
    for (int l = 0; l < 8; ++l) {
        hvls.h[index].emission[l] = source.h[index].emission[l];
    }
#endif
}
