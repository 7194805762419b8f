// HVL gather's records (shine's, not the paper's): each HVL of the cache as hvl_gather.comp
// reads it, with what depends on the HVL alone computed once here instead of once per receiver:
// the unit normal, eq. 21's 1 / (pi r^2), and the sender's emission ZH (eq. 20) as a polynomial
// in the cosine at the sender (hvl_zh_poly, push.emission_bands bands), and its identity. An
// empty cell keeps radius 0, which the gather skips. CPU twin: shine::reference::hvl::gather_records.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define SH_LOOP_ATTRIBUTES 1
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Hvls {
    Hvl h[];
} hvls;

// GatherHvl records, HVL_RECORD_TEXELS texels each (hvl_record_texel).
layout(set = 0, binding = 1, rgba32f) writeonly uniform image2D hvl_records;

// shine::passes::hvl::PrepPush
layout(push_constant) uniform Push {
    // HVLs in the cache
    uint count;
    // bands of the HVL emission reconstructed (1-5)
    uint emission_bands;
} push;

void main() {
    uint j = gl_GlobalInvocationID.x;
    if (j >= push.count) {
        return;
    }
    // Field by field: naga cannot read the OpCopyLogical of a whole-struct load or store.
    vec4 position_radius = hvls.h[j].position_radius;
    float r = position_radius.w;
    float emission[8];
    SH_UNROLL for (int l = 0; l < 8; ++l) {
        emission[l] = 0.0;
    }
    SH_UNROLL for (int l = 0; l < HVL_EMISSION_MAX_BANDS; ++l) {
        emission[l] = hvls.h[j].emission[l];
    }
    float a[HVL_EMISSION_MAX_BANDS];
    hvl_zh_poly(emission, int(push.emission_bands), a);
    bool valid = r > 0.0;
    vec3 n = hvls.h[j].normal_distance.xyz;
    imageStore(hvl_records, hvl_record_texel(j, HVL_RECORD_POSITION_RADIUS), valid ? position_radius : vec4(0.0));
    imageStore(hvl_records, hvl_record_texel(j, HVL_RECORD_NORMAL_AREA), valid ? vec4(normalize(n), hvl_geometric_factor_of(1.0, 1.0, r)) : vec4(0.0));
    imageStore(hvl_records, hvl_record_texel(j, HVL_RECORD_FLUX_E0), vec4(hvls.h[j].flux.rgb, a[0]));
    imageStore(hvl_records, hvl_record_texel(j, HVL_RECORD_EMISSION), vec4(a[1], a[2], a[3], a[4]));
    imageStore(hvl_records, hvl_record_texel(j, HVL_RECORD_IDENTITY), vec4(float(hvls.h[j].light), float(hvls.h[j].sample_index), float(hvls.h[j].light_samples), 0.0));
}
