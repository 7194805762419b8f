// `*_resolve` (paper 001 §"GI need not update every frame"; src/passes/amortise.rs): a
// technique's light refreshed at one pixel of every 2×2 cell per frame (HVL's gather, the
// proxies, IGI, AAF; receiver or full resolution, `recv_*` names the surfaces either way), the
// others carried over from the previous frame's resolved light, reprojected with the
// G-buffer's motion vectors. History is rejected where the pixel was not visible then
// (disocclusion: linear depth off by more than RESOLVE_DEPTH_TOLERANCE, or normals apart by
// more than acos RESOLVE_NORMAL_COS).
//
// Variant `mask` (`*_regather_mask`) runs between the technique's two dispatches: it marks every
// pixel that is not refreshed and either not covered by its history or in a changed cell whose
// refreshed pixel shows another surface (it, or the refreshed pixels of the cells beside it,
// changed by more than RESOLVE_CHANGE_LIMIT: a light or object moved) (alpha -1 in `fresh`; 0
// elsewhere), and the second dispatch (slice AMORTISE_REGATHER_SLICE) shades exactly those:
// paper 001's priority refresh of what moved. Variant `resolve` then blends: refreshed pixels
// mix the fresh value into valid history with weight RESOLVE_ALPHA, or take it where it changed
// by more than RESOLVE_CHANGE_LIMIT; the others keep their history, changed by the change their
// cell's refreshed pixel makes where it shows the same surface, or take that pixel's light
// where it changed beyond the limit, or, where they were shaded again, their own fresh value.
// CPU twin: shine::reference::resolve::resolve_cpu.
//
// Variant `records` (`*_reproject`) amortises a technique's per-pixel records instead of its
// light (IGI's gathered SH, AAF's sums and widths; `words` uints per pixel): after the
// refreshed pixels gathered theirs, every other pixel copies its history's records where they
// show its surface and its block did not change (with `signal`: the summed signals of the
// block's refreshed records, now against their history), and is marked (alpha -1 in `fresh`)
// for the regather otherwise; it writes the geometry history of every pixel. CPU twin:
// shine::reference::resolve::reproject_cpu.
//! variant mask RESOLVE_MASK=1 RESOLVE_RECORDS=0
//! variant resolve RESOLVE_MASK=0 RESOLVE_RECORDS=0
//! variant records RESOLVE_MASK=0 RESOLVE_RECORDS=1
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "amortise.glsl"

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D recv_position;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D recv_normal;
// Full-resolution motion (uv now minus uv then).
layout(set = 0, binding = 3, rg16f) readonly uniform image2D gb_motion;
// The previous frame's (normal, linear depth).
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D history_geometry;
#if RESOLVE_MASK
// This frame's light, valid at the refreshed pixels: the others are marked here.
layout(set = 0, binding = 2, rgba16f) uniform image2D fresh;
// The previous frame's resolved light (the change test).
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D history_light;
#elif RESOLVE_RECORDS
// The marks of the regather (alpha -1), written at every pixel.
layout(set = 0, binding = 2, rgba16f) writeonly uniform image2D fresh;
layout(set = 0, binding = 7, rgba16f) writeonly uniform image2D resolved_geometry;
// The previous frame's records, and this frame's (the refreshed pixels' written already).
layout(set = 0, binding = 8, std430) readonly buffer HistoryRecords {
    uint w[];
} history_records;
layout(set = 0, binding = 9, std430) buffer Records {
    uint w[];
} records;
#else
// This frame's light: at every pixel the resolve takes fresh light from.
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D fresh;
// The previous frame's resolved light.
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D history_light;
// This frame's resolved light and geometry (next frame's history).
layout(set = 0, binding = 6, rgba16f) uniform image2D resolved;
layout(set = 0, binding = 7, rgba16f) uniform image2D resolved_geometry;
#endif

// shine::passes::amortise::ResolvePush
layout(push_constant) uniform Push {
    // image size
    uvec2 extent;
    // full-resolution size (gb_motion)
    uvec2 full_extent;
    // 1 + k: the refreshed pixel of every cell is at (k & 1, k >> 1); 0: every pixel
    // was gathered this frame (no history yet): the fresh light passes through
    uint slice;
    // 1 when the history holds the previous frame
    uint has_history;
    // uints per pixel of the records (variant records)
    uint words;
    // What the change test compares of a record (variant records): 0 nothing, 1 an rgb value
    // as two words of packed halves, 2 an rgb sum and its count as four floats
    uint signal;
} push;

// Whether pixel p is refreshed this frame.
bool refreshed(ivec2 p) {
    return amortise_refreshed(p, push.slice);
}

// Where p's history is (reprojected with the motion vectors), and whether it shows p's
// surface.
bool history_at(ivec2 p, float depth, vec3 n, out ivec2 q) {
    ivec2 full = ivec2((vec2(p) + 0.5) * vec2(push.full_extent) / vec2(push.extent));
    full = min(full, ivec2(push.full_extent) - 1);
    vec2 uv = (vec2(p) + 0.5) / vec2(push.extent);
    vec2 then_uv = uv - imageLoad(gb_motion, full).xy;
    q = ivec2(floor(then_uv * vec2(push.extent)));
    if (push.has_history == 0u || any(lessThan(q, ivec2(0)))
        || any(greaterThanEqual(q, ivec2(push.extent)))) {
        return false;
    }
    vec4 g = imageLoad(history_geometry, q);
    return resolve_same_surface(depth, n, g.w, g.xyz);
}

#if RESOLVE_RECORDS
// The rgb signal of the record at pixel index i of `records` or `history_records`: push.signal
// 1, two words of packed halves; 2, a sum of rgb samples and their count as four floats (its
// mean).
vec3 record_signal(uint i, bool history) {
    uint at = i * push.words;
    uint n = push.signal == 1u ? 2u : 4u;
    uvec4 w = uvec4(0u);
    for (uint k = 0u; k < n; ++k) {
        w[k] = history ? history_records.w[at + k] : records.w[at + k];
    }
    if (push.signal == 1u) {
        return vec3(unpackHalf2x16(w.x), unpackHalf2x16(w.y).x);
    }
    vec4 sum = uintBitsToFloat(w);
    return sum.w > 0.0 ? sum.rgb / sum.w : vec3(0.0);
}
#endif

// Refreshed pixel c's value now and in its history (the light, or the records' signal) and
// its position and normal; false where it has no history.
bool refreshed_value(ivec2 c, out vec4 cp, out vec3 cn, out vec4 now, out vec4 then) {
    now = vec4(0.0);
    then = vec4(0.0);
    cp = imageLoad(recv_position, c);
    cn = normalize(imageLoad(recv_normal, c).xyz);
    ivec2 cq;
    if (!refreshed(c) || !history_at(c, cp.w, cn, cq)) {
        return false;
    }
#if RESOLVE_RECORDS
    now.rgb = record_signal(uint(c.y) * push.extent.x + uint(c.x), false);
    then.rgb = record_signal(uint(cq.y) * push.extent.x + uint(cq.x), true);
#else
    now = imageLoad(fresh, c);
    then = imageLoad(history_light, cq);
#endif
    return true;
}

#if RESOLVE_RECORDS
// Whether the records around p changed this frame: the signals of the refreshed pixels of p's
// block of AMORTISE_RECORD_BLOCK² pixels, summed, now against their history. A record's signal
// is one pixel's noisy estimate (IGI's VPL subset, AAF's samples); their sum over a block
// changes with the light, not with the noise.
bool block_changed(ivec2 p) {
    if (push.signal == 0u) {
        return false;
    }
    // Blocks cut by the image's edge are moved inside it (where the image is wide enough),
    // so each holds its full share of refreshed pixels.
    ivec2 origin = (p / AMORTISE_RECORD_BLOCK) * AMORTISE_RECORD_BLOCK;
    origin = max(min(origin, ivec2(push.extent) - AMORTISE_RECORD_BLOCK), ivec2(0));
    ivec2 offset = amortise_offset(push.slice);
    vec3 now = vec3(0.0);
    vec3 then = vec3(0.0);
    for (int j = 0; j < AMORTISE_RECORD_BLOCK; j += 2) {
        for (int i = 0; i < AMORTISE_RECORD_BLOCK; i += 2) {
            ivec2 c = origin + ivec2(i, j) + offset;
            vec4 cp, c_now, c_then;
            vec3 cn;
            if (all(lessThan(c, ivec2(push.extent)))
                && refreshed_value(c, cp, cn, c_now, c_then)) {
                now += c_now.rgb;
                then += c_then.rgb;
            }
        }
    }
    return amortise_changed(now, then);
}
#else
// Whether p's cell (p not refreshed, at `depth` with normal `n`) changed this frame: a light or
// object moved. Its refreshed pixel decides where it has history and shows p's surface, or
// changed by more than RESOLVE_CHANGE_LIMIT anyway (the light changed nearby); otherwise the
// refreshed pixels of the four cells beside it, changed (also where the image's odd edge cuts
// the cell and leaves it none). `on_surface`: the cell's refreshed pixel shows p's surface: p
// follows its change `now - then`, or takes `now` where it changed beyond the limit; a changed
// cell whose refreshed pixel shows another surface is shaded again.
bool cell_changed(ivec2 p, float depth, vec3 n, out bool on_surface, out vec4 now, out vec4 then) {
    on_surface = false;
    // The cell's refreshed pixel, clamped where an odd edge cuts the cell (it is then not
    // refreshed; the cells beside its unclamped place decide).
    ivec2 own = (p / 2) * 2 + amortise_offset(push.slice);
    ivec2 c = min(own, ivec2(push.extent) - 1);
    vec4 cp;
    vec3 cn;
    if (refreshed_value(c, cp, cn, now, then)) {
        on_surface = resolve_same_surface(depth, n, cp.w, cn);
        bool changed = amortise_changed(now.rgb, then.rgb);
        if (on_surface || changed) {
            return changed;
        }
    }
    const ivec2 beside[4] = ivec2[](ivec2(-2, 0), ivec2(2, 0), ivec2(0, -2), ivec2(0, 2));
    for (int i = 0; i < 4; ++i) {
        ivec2 s = own + beside[i];
        vec4 sp, s_now, s_then;
        vec3 sn;
        if (all(greaterThanEqual(s, ivec2(0))) && all(lessThan(s, ivec2(push.extent)))
            && refreshed_value(s, sp, sn, s_now, s_then)
            && amortise_changed(s_now.rgb, s_then.rgb)) {
            return true;
        }
    }
    return false;
}
#endif

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(uvec2(p), push.extent))) {
        return;
    }
    vec4 position = imageLoad(recv_position, p);
    vec3 n = normalize(imageLoad(recv_normal, p).xyz);
#if RESOLVE_RECORDS
    imageStore(resolved_geometry, p, position.w == 0.0 ? vec4(0.0) : vec4(n, position.w));
    ivec2 q;
    bool regather = false;
    if (push.slice != 0u && !refreshed(p) && position.w != 0.0) {
        regather = !history_at(p, position.w, n, q) || block_changed(p);
        if (!regather) {
            uint to = (uint(p.y) * push.extent.x + uint(p.x)) * push.words;
            uint from = (uint(q.y) * push.extent.x + uint(q.x)) * push.words;
            for (uint i = 0u; i < push.words; ++i) {
                records.w[to + i] = history_records.w[from + i];
            }
        }
    }
    imageStore(fresh, p, vec4(0.0, 0.0, 0.0, regather ? -1.0 : 0.0));
#elif RESOLVE_MASK
    if (push.slice == 0u || refreshed(p)) {
        return;
    }
    ivec2 q;
    bool on_surface;
    vec4 now, then;
    bool regather = position.w != 0.0
        && (!history_at(p, position.w, n, q)
            || (cell_changed(p, position.w, n, on_surface, now, then) && !on_surface));
    imageStore(fresh, p, vec4(0.0, 0.0, 0.0, regather ? -1.0 : 0.0));
#else
    if (position.w == 0.0) {
        imageStore(resolved, p, vec4(0.0));
        imageStore(resolved_geometry, p, vec4(0.0));
        return;
    }
    imageStore(resolved_geometry, p, vec4(n, position.w));
    if (push.slice == 0u) {
        imageStore(resolved, p, imageLoad(fresh, p));
        return;
    }
    ivec2 q;
    bool valid = history_at(p, position.w, n, q);
    vec4 light = imageLoad(fresh, p);
    if (valid) {
        vec4 history = imageLoad(history_light, q);
        if (refreshed(p)) {
            if (!amortise_changed(light.rgb, history.rgb)) {
                light = mix(history, light, RESOLVE_ALPHA);
            }
        } else {
            // The change the cell's refreshed pixel makes this frame, shared where it
            // shows the same surface: held pixels follow the light every frame instead of
            // stepping every fourth (and a static scene, whose change is 0, stays exact).
            // Where it changed by more than the limit the pixel takes the refreshed pixel's
            // light, or its own where it was shaded again.
            bool on_surface;
            vec4 now, then;
            if (cell_changed(p, position.w, n, on_surface, now, then)) {
                light = on_surface ? now : light;
            } else {
                light = on_surface ? max(history + RESOLVE_ALPHA * (now - then), vec4(0.0)) : history;
            }
        }
    }
    imageStore(resolved, p, light);
#endif
}
