// Each sample's own history (issue 43, item 2): the HVL and VPL records carry identities
// (light, sample index), so a sample can be filtered in sample space, across frames, with no
// neighbourhood clip. Record m of this frame's cache finds its identity's record of the last
// frame and, unless a stated change resets it, blends its flux and its normal (the axis of its
// SH emission) towards this frame's by the weight `weight`; its position and radius are this
// frame's, so a sample that slides with its light does not trail it. What steps at once where
// a sample crosses a crease of the scene (its normal turns, its colour changes) then turns over
// a few frames. The filtered record is written back in place and, by identity, into this
// frame's history. CPU twin: shine::reference::sample_history::filter (same rule, same order).
//
// A sample starts over (this frame's record as it is) where:
// - there is no last frame (`has_history` 0: the first frame, a reset, another layout);
// - its identity held no record last frame (the history is cleared before this pass);
// - it moved more than `jump` times the larger of its two radii (it jumped to another
//   surface: an RSM depth step);
// - its flux changed by more than the ratio `ratio` either way (its light changed: switched,
//   cut, or the sample fading in from nothing);
// - its normal turned by more than acos(`min_cos`).
#version 460

layout(local_size_x = 64) in;

#define SH_BANDS 5
#extension GL_GOOGLE_include_directive : require
#include "sh.glsl"
#include "hvl.glsl"

layout(set = 0, binding = 0, std430) buffer Cache {
    Hvl h[];
} cache;
layout(set = 0, binding = 1, std430) readonly buffer Previous {
    Hvl h[];
} previous;
layout(set = 0, binding = 2, std430) buffer Current {
    Hvl h[];
} current;

// shine::passes::sample_history::SampleHistoryPush
layout(push_constant) uniform Push {
    // records in the cache (M), and identities per light in the history
    uint count;
    // lights the history holds (identities light * count + sample index)
    uint lights;
    // 1 when `previous` holds the last frame
    uint has_history;
    // weight of this frame in the blend (1: no history)
    float weight;
    // a sample moved more than `jump` radii starts over
    float jump;
    // a sample whose flux changed by more than this ratio starts over
    float ratio;
    // a sample whose normal turned past this cosine starts over
    float min_cos;
    uint pad;
} push;

// The flux's size: r + g + b.
float flux_sum(vec4 flux) {
    return flux.r + flux.g + flux.b;
}

// Whether a sample now at (p, n, flux a) continues its record of the last frame (q, m, b), both
// valid: the rule above.
bool continues(vec4 p, vec3 n, vec4 a, vec4 q, vec3 m, vec4 b) {
    float moved = distance(p.xyz, q.xyz);
    float reach = push.jump * max(p.w, q.w);
    float fa = flux_sum(a);
    float fb = flux_sum(b);
    return moved <= reach && fa <= push.ratio * fb && fb <= push.ratio * fa
        && dot(n, m) >= push.min_cos;
}

// Records are read and written field by field: naga cannot read the OpCopyLogical of a
// whole-struct load or store.
void main() {
    uint m = gl_GlobalInvocationID.x;
    if (m >= push.count) {
        return;
    }
    vec4 position = cache.h[m].position_radius;
    vec4 normal = cache.h[m].normal_distance;
    vec4 flux = cache.h[m].flux;
    uint light = cache.h[m].light;
    uint index = cache.h[m].sample_index;
    if (flux.w == 0.0 || light >= push.lights || index >= push.count) {
        return;
    }
    uint id = light * push.count + index;
    if (push.has_history != 0u) {
        vec4 last_flux = previous.h[id].flux;
        vec4 last_normal = previous.h[id].normal_distance;
        if (last_flux.w != 0.0
            && continues(position, normal.xyz, flux, previous.h[id].position_radius,
                last_normal.xyz, last_flux)) {
            flux.rgb = mix(last_flux.rgb, flux.rgb, push.weight);
            normal.xyz = normalize(mix(last_normal.xyz, normal.xyz, push.weight));
        }
    }
    cache.h[m].flux = flux;
    cache.h[m].normal_distance = normal;
    // The history keeps what the next frame's rule reads; the identity is the record's index.
    current.h[id].position_radius = position;
    current.h[id].normal_distance = normal;
    current.h[id].flux = flux;
}
