// `accumulate` (issue 23, "history"; src/passes/accumulate.rs): the frame's indirect light
// (and, as the `taa` pass, its jittered direct light) accumulated over frames. Each pixel's history is reprojected with the G-buffer's motion
// vectors (a bilinear footprint whose taps count only where they show the pixel's surface:
// `resolve_same_surface`, the amortised HVL's disocclusion test), clipped to the current 3×3
// neighbourhood's mean ± clip·σ per channel (variance clipping, as TAA does; the box widened to
// hold the pixel's own light, so a static image keeps its history), and blended with
// weight 1/n, where n is the history's length (alpha), capped at `max_frames`: an exponential
// history that converges where nothing changes, restarts where the surface was not visible
// (n = 1) and follows at once where the light leaves the clip box. The indirect light's
// history is Holt's linear exponential smoothing: the level plus its trend (push.trend, an EMA
// of the level's change) is the forecast that is clipped and blended, and the clip box is at
// least the pixel's temporal noise (push.temporal: the innovations' σ, state.a), so smooth
// light that pops as a whole keeps its history. With `geometry` 0 it is
// TAA: every pixel counts, the background too, a still pixel keeps history of any surface of
// its 3×3 neighbourhood (jittered silhouettes) while a pixel near motion keeps only its own
// surface's and at most TAA_MOVING_FRAMES, and the blend is in the space x / (1 + luma) so
// that bright history cannot bleed into dark surfaces. CPU twin:
// shine::reference::accumulate::accumulate_cpu.
#version 460
#extension GL_GOOGLE_include_directive : require

layout(local_size_x = 8, local_size_y = 8) in;

#include "accumulate.glsl"
#include "amortise.glsl"

// This frame's light (indirect; direct under TAA).
layout(set = 0, binding = 0, rgba16f) readonly uniform image2D current;
// World position, w: linear depth (0 on the background).
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D gb_position;
// The geometric normal (what `gbuffer history` keeps).
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D gb_geometric_normal;
// uv now minus uv then.
layout(set = 0, binding = 3, rg16f) readonly uniform image2D gb_motion;
// The previous frame's (normal, linear depth): `gbuffer history`.
layout(set = 0, binding = 4, rgba32f) readonly uniform image2D history_geometry;
// The previous frame's accumulated light; alpha: its history length.
layout(set = 0, binding = 5, rgba16f) readonly uniform image2D history_light;
// This frame's accumulated light (next frame's history).
layout(set = 0, binding = 6, rgba16f) uniform image2D accumulated;
// The previous frame's filter state: rgb Holt's trend (the level's change per frame), a the
// variance of the innovations (luminance²). Zero under TAA.
layout(set = 0, binding = 7, rgba16f) readonly uniform image2D history_state;
// This frame's filter state (next frame's history_state).
layout(set = 0, binding = 8, rgba16f) writeonly uniform image2D state;

// shine::passes::accumulate::AccumulatePush
layout(push_constant) uniform Push {
    uvec2 extent;
    // 1 when the history holds the previous frame
    uint has_history;
    // longest history n: the blend weight never falls below 1/max_frames
    float max_frames;
    // half-width of the clip box in standard deviations (0: no clipping)
    float clip;
    // 1: the indirect light's history (linear; the background passes through); 0: TAA of the
    // direct light (blend space, the background accumulates, still pixels take any nearby
    // surface's history)
    uint geometry;
    // β of Holt's trend (0: none; the indirect light's history only)
    float trend;
    // 1: the clip box widens to the pixel's own temporal noise (the indirect light's only)
    uint temporal;
} push;

// Whether p is inside the image.
bool inside(ivec2 p) {
    return all(greaterThanEqual(p, ivec2(0))) && all(lessThan(p, ivec2(push.extent)));
}

// The space TAA blends in: x / (1 + luma(x)) (Karis 2014), so that a bright background's
// history cannot bleed into a dark object over it, as it does in linear HDR; the indirect
// light's history blends linear radiance (energy-true). `from_blend` inverts `to_blend`.
vec3 to_blend(vec3 x) {
    return push.geometry != 0u ? x : x / (1.0 + luminance(x));
}

vec3 from_blend(vec3 x) {
    return push.geometry != 0u ? x : x / max(1.0 - luminance(x), TAA_MIN_INVERSE);
}

// TAA's disocclusion test at a pixel: whether history geometry `g` (normal, linear depth; 0:
// the background) shows the surface the pixel shows now (`depth`, `n`), the background
// included.
bool taa_same_surface(float depth, vec3 n, vec4 g) {
    return g.w == 0.0 ? depth == 0.0 : (depth > 0.0 && resolve_same_surface(depth, n, g.w, g.xyz));
}

// TAA's test where nothing moves: whether `g` shows a surface some pixel of p's 3×3
// neighbourhood shows now. A still silhouette pixel, whose jittered samples alternate between
// two surfaces, keeps its history. (Where things move, only the pixel's own surface counts:
// the wider test let a thin moving figure's edges, and so most of it, take in the background.)
bool taa_seen_nearby(ivec2 p, vec4 g) {
    for (int y = -1; y <= 1; ++y) {
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = p + ivec2(x, y);
            if (inside(q)) {
                float d = imageLoad(gb_position, q).w;
                vec3 nq = normalize(imageLoad(gb_geometric_normal, q).xyz);
                if (taa_same_surface(d, nq, g)) {
                    return true;
                }
            }
        }
    }
    return false;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (!inside(p)) {
        return;
    }
    vec3 radiance = imageLoad(current, p).rgb;
    vec3 light = to_blend(radiance);
    float depth = imageLoad(gb_position, p).w;
    bool geometry = push.geometry != 0u;
    bool background = geometry && depth == 0.0;
    if (background || push.has_history == 0u) {
        imageStore(accumulated, p, vec4(radiance, background ? 0.0 : 1.0));
        imageStore(state, p, vec4(0.0));
        return;
    }
    vec3 n = normalize(imageLoad(gb_geometric_normal, p).xyz);

    // The history: bilinear over the taps that show this surface.
    vec2 uv = (vec2(p) + 0.5) / vec2(push.extent);
    vec2 motion = imageLoad(gb_motion, p).xy;
    vec2 then_px = (uv - motion) * vec2(push.extent) - 0.5;
    // TAA's "still": nothing in the 3×3 neighbourhood moves (a still pixel beside a moving
    // figure must not take the figure's light into its history: the figure would take it back).
    // The indirect light's history never asks, so its loop is skipped.
    bool still = true;
    for (int y = -1; y <= 1 && !geometry; ++y) {
        for (int x = -1; x <= 1; ++x) {
            ivec2 q = p + ivec2(x, y);
            if (inside(q) && length(imageLoad(gb_motion, q).xy * vec2(push.extent)) >= TAA_STILL_PIXELS) {
                still = false;
            }
        }
    }
    ivec2 base = ivec2(floor(then_px));
    vec2 f = then_px - vec2(base);
    vec4 history = vec4(0.0);
    vec4 filter_state = vec4(0.0);
    float weight = 0.0;
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
            ivec2 q = base + ivec2(i, j);
            if (!inside(q)) {
                continue;
            }
            vec4 g = imageLoad(history_geometry, q);
            bool valid = geometry ? resolve_same_surface(depth, n, g.w, g.xyz)
                                  : taa_same_surface(depth, n, g) || (still && taa_seen_nearby(p, g));
            if (!valid) {
                continue;
            }
            float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
            vec4 h = imageLoad(history_light, q);
            history += w * vec4(to_blend(h.rgb), h.a);
            filter_state += w * imageLoad(history_state, q);
            weight += w;
        }
    }
    if (weight < ACCUMULATE_MIN_WEIGHT) {
        // Disoccluded: the history restarts here.
        imageStore(accumulated, p, vec4(radiance, 1.0));
        imageStore(state, p, vec4(0.0));
        return;
    }
    history /= weight;
    filter_state /= weight;
    // Whether the view holds still here. A moving pixel's history is a reprojection, which the
    // clip judges on its own: restarting it there would show the raw frame, and a trend or a
    // temporal noise measured elsewhere would let the moving surface's history trail. There
    // the history is the plain one and the filter's state starts again.
    bool view_still = length(motion * vec2(push.extent)) < TAA_STILL_PIXELS;
    bool still_indirect = geometry && view_still;
    // Holt's forecast: the previous level moved on by its trend (never below black).
    vec3 level = history.rgb;
    vec3 trend = still_indirect && push.trend > 0.0 ? filter_state.rgb : vec3(0.0);
    float noise = still_indirect ? filter_state.a : 0.0;
    history.rgb = max(level + trend, vec3(0.0));
    vec3 forecast = history.rgb;

    bool restarted = false;
    if (push.clip > 0.0) {
        // Mean and standard deviation of the current light over the 3×3 neighbourhood's
        // foreground pixels.
        vec3 sum = vec3(0.0);
        vec3 sum2 = vec3(0.0);
        float count = 0.0;
        for (int y = -1; y <= 1; ++y) {
            for (int x = -1; x <= 1; ++x) {
                ivec2 q = p + ivec2(x, y);
                if (!inside(q) || (geometry && imageLoad(gb_position, q).w == 0.0)) {
                    continue;
                }
                vec3 c = to_blend(imageLoad(current, q).rgb);
                sum += c;
                sum2 += c * c;
                count += 1.0;
            }
        }
        vec3 mean = sum / count;
        vec3 sigma = sqrt(max(sum2 / count - mean * mean, vec3(0.0)));
        if (still_indirect && push.temporal != 0u) {
            // The pixel's own noise from frame to frame, spread over the channels as the
            // neighbourhood's colour: smooth light pops as a whole, which the 3×3 σ misses.
            sigma = max(sigma, sqrt(noise) * mean / max(luminance(mean), ACCUMULATE_MIN_LUMINANCE));
        }
        // The box always holds the pixel's own light: where nothing changes, history is kept.
        vec3 lo = min(light, mean - push.clip * sigma);
        vec3 hi = max(light, mean + push.clip * sigma);
        vec3 clipped = clamp(history.rgb, lo, hi);
        float moved = luminance(abs(history.rgb - clipped));
        if (still_indirect && moved > ACCUMULATE_CHANGE * max(luminance(clipped), luminance(light))) {
            history.a = 0.0;
            restarted = true;
        }
        history.rgb = clipped;
    }
    // A moving pixel under TAA keeps a short history: its jittered edges alternate between
    // surfaces, and a long history would carry one surface's light onto the other.
    float longest = geometry || still ? push.max_frames : min(push.max_frames, TAA_MOVING_FRAMES);
    float frames = min(history.a + 1.0, longest);
    vec3 blended = mix(history.rgb, light, 1.0 / frames);
    imageStore(accumulated, p, vec4(from_blend(blended), frames));
    // The next frame's state: the trend an EMA (β) of the level's change, the innovations'
    // variance an EMA (1/n) of this frame's; both restart with the history and where the view
    // moves.
    float innovation = luminance(radiance) - luminance(forecast);
    vec4 next = vec4(mix(trend, blended - level, push.trend), mix(noise, innovation * innovation, 1.0 / frames));
    imageStore(state, p, still_indirect && !restarted ? accumulate_storable(next) : vec4(0.0));
}
