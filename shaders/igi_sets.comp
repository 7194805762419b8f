// igi_sets (paper 000 §2.3, shine's): the VPL records grouped by interleaved set, so that
// vpl_sh.comp walks only its pixel's set. Thread s counts the valid records of set s
// (igi_sample_set of the sample identity, shaders/include/sample_identity.glsl), the counts are
// summed into each set's first slot, and thread s writes its records' indices in ascending
// order: a set's sum in vpl_sh runs in the record order of the CPU twin's scan
// (shine::reference::igi::vpl_sh), and the lanes of a subgroup, whose pixels lie in different
// sets, each walk their own list instead of all lanes waiting on every record (issue 43's 5.8x).
// Output: `igi_sets`, uint first[IGI_SETS_MAX + 1] (first[s]..first[s + 1] the indices of set
// s), then the record indices.
#version 460
#extension GL_GOOGLE_include_directive : require
#define SH_BANDS 2
#include "sh.glsl"
#include "hvl.glsl"
#include "sample_identity.glsl"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Vpls {
    Hvl h[];
} vpls;

layout(set = 0, binding = 1, std430) buffer Sets {
    uint first[IGI_SETS_MAX + 1u];
    uint index[];
} sets;

// shine::passes::igi::SetsPush
layout(push_constant) uniform Push {
    // VPL count M
    uint vpl_count;
    // sets n m of the pattern
    uint sets;
} push;

shared uint counts[IGI_SETS_MAX];

bool in_set(uint j, uint s) {
    return vpls.h[j].flux.a != 0.0 && igi_sample_set(vpls.h[j].sample_index, push.sets) == s;
}

void main() {
    uint s = gl_LocalInvocationID.x;
    uint count = 0u;
    if (s < push.sets) {
        for (uint j = 0u; j < push.vpl_count; ++j) {
            count += in_set(j, s) ? 1u : 0u;
        }
    }
    counts[s] = count;
    barrier();
    uint first = 0u;
    for (uint t = 0u; t < s; ++t) {
        first += counts[t];
    }
    if (s < push.sets) {
        sets.first[s] = first;
        if (s + 1u == push.sets) {
            sets.first[push.sets] = first + count;
        }
        uint k = first;
        for (uint j = 0u; j < push.vpl_count; ++j) {
            if (in_set(j, s)) {
                sets.index[k] = j;
                ++k;
            }
        }
    }
}
