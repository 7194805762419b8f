// vpl_sh (paper 000 §3, steps 1-2): each pixel's incident radiance from the VPLs of its
// interleaved set, with shadow rays through the BVH, projected to SH (variants o2, o3, o4: SH
// order = bands) or, for classic IGI (variant irr), reduced to the irradiance about the shading
// normal and the glossy radiance about the reflected direction. Output: `vpl_sh`, per pixel
// SH_OUT coefficients of rgb as two uints (packHalf2x16(r, g), packHalf2x16(b, 0)), row-major
// pixels, coefficient-minor. CPU twin: shine::reference::igi::vpl_sh.
//
// Pixel px uses set s = igi_set(px): the VPLs whose identity puts them in set s
// (igi_sample_set of the record's sample index, shaders/include/sample_identity.glsl), so a VPL
// keeps its set when the records reorder (issue 43), walked in record order from the list
// igi_sets.comp groups them in. Each contribution is scaled by n m: the
// discontinuity filter (sh_filter.comp) counts every set of the pattern equally, so the
// filtered sum is the sum over all VPLs.
//! variant o2 SH_BANDS=2
//! variant o3 SH_BANDS=3
//! variant o4 SH_BANDS=4
//! variant irr SH_BANDS=1 IGI_IRRADIANCE=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "igi.glsl"
#include "amortise.glsl"
#include "hvl.glsl"
#include "sample_identity.glsl"
#include "hvl_near.glsl"
#define TRACE_NODES_BINDING 6
#define TRACE_TRIANGLES_BINDING 7
#define TRACE_TOP_BINDING 8
#define TRACE_INSTANCES_BINDING 9
#include "trace.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_geometric_normal;
#ifdef IGI_IRRADIANCE
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D gb_normal;
layout(set = 0, binding = 3, rgba8) readonly uniform image2D gb_material;
#endif

layout(set = 0, binding = 4, std430) readonly buffer Vpls {
    Hvl h[];
} vpls;

// igi_sets.comp: first[s]..first[s + 1] index the records of set s.
layout(set = 0, binding = 11, std430) readonly buffer Sets {
    uint first[IGI_SETS_MAX + 1u];
    uint index[];
} sets;

layout(set = 0, binding = 5, std430) buffer VplSh {
    uint c[];
} vpl_sh;

// Slice AMORTISE_REGATHER_SLICE: the pixels to gather, alpha -1 (igi_reproject); not read by
// the other slices.
layout(set = 0, binding = 10, rgba16f) readonly uniform image2D marks;

#ifdef IGI_IRRADIANCE
#define SH_OUT 2
#else
#define SH_OUT SH_COEFFS
#endif

// shine::passes::igi::VplShPush
layout(push_constant) uniform Push {
    // xyz: camera position; w: clamp distance d_min (metres)
    vec4 camera_clamp;
    // image size
    uvec2 extent;
    // interleaving pattern n, m
    uvec2 pattern;
    // VPL count M (igi_sets holds the records' grouping)
    uint vpl_count;
    // footprint k: each VPL evaluated no closer than k r_j
    // (shine::passes::igi::IgiParams::footprint)
    float footprint;
    // 0: every pixel; 1 + k: the pixel at (k & 1, k >> 1) of every 2x2 cell;
    // AMORTISE_REGATHER_SLICE: the pixels `marks` marks (amortised frames,
    // src/passes/amortise.rs); each pixel gathers its own set
    uint slice;
    // R of the traced near field (world units; 0: none): each VPL's light times
    // hvl_far_weight of its distance, the near field pass (hvl_near.comp) gives the rest
    float near_range;
} push;

// A ray to a VPL stops this fraction short of it (the VPL lies on a surface).
const float IGI_SHADOW_END = 0.999;

void store(uint base, int k, vec3 v) {
    v = clamp(v, vec3(-65504.0), vec3(65504.0));
    vpl_sh.c[base + 2u * uint(k)] = packHalf2x16(v.rg);
    vpl_sh.c[base + 2u * uint(k) + 1u] = packHalf2x16(vec2(v.b, 0.0));
}

void main() {
    ivec2 px = amortise_pixel(gl_GlobalInvocationID.xy, push.slice);
    if (px.x >= int(push.extent.x) || px.y >= int(push.extent.y)) {
        return;
    }
    if (push.slice == AMORTISE_REGATHER_SLICE && imageLoad(marks, px).a >= 0.0) {
        return;
    }
    uint base = (uint(px.y) * push.extent.x + uint(px.x)) * uint(SH_OUT) * 2u;
    vec3 acc[SH_OUT];
    for (int k = 0; k < SH_OUT; ++k) {
        acc[k] = vec3(0.0);
    }
    vec4 position = imageLoad(gb_position, px);
    if (position.w != 0.0) {
        vec3 x = position.xyz;
        vec3 ng = normalize(imageLoad(gb_geometric_normal, px).xyz);
        vec3 origin = trace_offset(x, ng);
#ifdef IGI_IRRADIANCE
        vec3 n = normalize(imageLoad(gb_normal, px).xyz);
        vec3 wo = normalize(push.camera_clamp.xyz - x);
        vec3 r = reflect(-wo, n);
        float exponent = igi_phong_exponent(imageLoad(gb_material, px).r);
        float lobe_norm = (exponent + 1.0) / (2.0 * IGI_PI);
#endif
        uint s = igi_set(px, push.pattern);
        // Each set's sum stands for all the VPLs: the filter over whole pattern tiles counts
        // every set equally, so n m times each set's sum totals the full sum there.
        float scale = float(push.pattern.x * push.pattern.y);
        uint end = sets.first[s + 1u];
        for (uint i = sets.first[s]; i < end; ++i) {
            uint j = sets.index[i];
            // Field by field: naga cannot read a whole-struct copy out of a buffer.
            vec4 position_radius = vpls.h[j].position_radius;
            vec4 flux = vpls.h[j].flux;
            vec3 v = position_radius.xyz - x;
            float dist = length(v);
            if (!(dist > 0.0)) {
                continue;
            }
            vec3 w = v / dist;
            // Light from below the geometric surface cannot reach x.
            if (dot(w, ng) <= 0.0) {
                continue;
            }
            float footprint = push.footprint * position_radius.w;
            vec3 e = igi_vpl_irradiance(flux.rgb, vpls.h[j].normal_distance.xyz, w, dist, push.camera_clamp.w, footprint)
                * (scale * hvl_far_weight(dist, push.near_range));
            if (all(equal(e, vec3(0.0)))) {
                continue;
            }
            if (trace_occluded(origin, w, 0.0, length(position_radius.xyz - origin) * IGI_SHADOW_END)) {
                continue;
            }
#ifdef IGI_IRRADIANCE
            acc[0] += e * max(0.0, dot(n, w));
            acc[1] += e * (lobe_norm * pow(max(0.0, dot(r, w)), exponent));
#else
            float y[SH_COEFFS];
            sh_basis(w, y);
            for (int k = 0; k < SH_COEFFS; ++k) {
                acc[k] += e * y[k];
            }
#endif
        }
    }
    for (int k = 0; k < SH_OUT; ++k) {
        store(base, k, acc[k]);
    }
}
