// debug_view: what a GI context's techniques see, drawn at the display size for the host's
// debug output (src/passes/debug_view.rs, docs/embedding.md "Debug view"). Every variant but
// `points` writes each display pixel p from the source texel under its centre,
// q = floor((p + 0.5) · source / extent) (nearest: a source texel is a visible block).
// - receiver_normals, receiver_albedo: the receiver of q (the block of `scale`² internal
//   pixels it stands for): rgb 0.5 n + 0.5 or the albedo, alpha 1 (0 and black on background).
// - rsm: the primary light's RSM flux, fitted into the centred square of side min(W, H): the
//   mean flux of the texels under the pixel (at most 8×8 of them, evenly spread) times the
//   texel count S² (W: what the map would reflect were every texel like these), alpha 1 inside
//   the square, 0 and black outside.
// - background: the light points' background, the frame's indirect radiance L dimmed to
//   0.5 L / (1 + L) (below 0.5: the dots' largest channel is 1), alpha 0.
// - points: one thread per light record (shine::passes::hvl::Hvl: HVLs, or IGI's VPLs): its
//   centre projected by `view_proj` onto the display, a 3×3 dot around the pixel it falls in,
//   rgb its flux over its largest channel, alpha 1. Records marked empty and points behind the
//   camera draw nothing; no depth test (every light the GI uses is drawn).
// - samples: AAF's samples per pixel n as a heat map, t = (n − spp_range.x) / (spp_range.y −
//   spp_range.x) from blue (t = 0) through green to red (t = 1), alpha n (0 and black on
//   background).
//! variant receiver_normals DEBUG_RECEIVERS=1 DEBUG_NORMALS=1
//! variant receiver_albedo DEBUG_RECEIVERS=1
//! variant rsm DEBUG_RSM=1
//! variant background DEBUG_BACKGROUND=1
//! variant points DEBUG_POINTS=1
//! variant samples DEBUG_SAMPLES=1
#version 460
#extension GL_GOOGLE_include_directive : require
#include "grid.glsl"

#ifdef DEBUG_POINTS
#define SH_BANDS 5
#include "sh.glsl"
#include "hvl.glsl"
layout(local_size_x = 64) in;
#else
layout(local_size_x = 8, local_size_y = 8) in;
#endif

// shine::passes::debug_view::DebugPush (96 bytes).
layout(push_constant) uniform Push {
    // points: world to clip of the frame's camera.
    mat4 view_proj;
    // The display size W×H (the debug image's).
    uvec2 extent;
    // The source's size: the internal size (receivers, background, samples), S×S (rsm).
    uvec2 source;
    // samples: the least and largest samples per pixel AAF takes.
    vec2 spp_range;
    // receivers: the block size s.
    uint scale;
    // points: the light records.
    uint count;
} push;

layout(set = 0, binding = 0, rgba16f) uniform image2D debug;

#ifdef DEBUG_RECEIVERS
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D recv_position;
#ifdef DEBUG_NORMALS
layout(set = 0, binding = 2, rgba16f) readonly uniform image2D recv_normal;
#else
layout(set = 0, binding = 2, rgba8) readonly uniform image2D recv_albedo;
#endif
#endif
#ifdef DEBUG_RSM
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D rsm_flux;
#endif
#ifdef DEBUG_BACKGROUND
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D indirect;
#endif
#ifdef DEBUG_POINTS
layout(set = 0, binding = 1, std430) readonly buffer Hvls {
    Hvl h[];
} lights;
#endif
#ifdef DEBUG_SAMPLES
layout(set = 0, binding = 1, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 2, std430) readonly buffer Filter {
    vec2 f[];
} filter_widths;
#endif

// The source texel under the centre of display pixel p.
ivec2 source_texel(uvec2 p) {
    return ivec2(texel_under_centre(p, push.extent, push.source));
}

// Blue, cyan, green, yellow, red as t goes from 0 to 1.
vec3 heat(float t) {
    return clamp(vec3(4.0 * t - 2.0, 2.0 - abs(4.0 * t - 2.0), 2.0 - 4.0 * t), 0.0, 1.0);
}

void main() {
#ifdef DEBUG_POINTS
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count || lights.h[i].flux.a == 0.0) {
        return;
    }
    vec4 clip = push.view_proj * vec4(lights.h[i].position_radius.xyz, 1.0);
    if (clip.w <= 0.0) {
        return;
    }
    vec2 pixel = (clip.xy / clip.w * 0.5 + 0.5) * vec2(push.extent);
    // Far outside the image (or not finite): nothing to draw, and no integer overflow.
    if (!(all(greaterThan(pixel, vec2(-2.0))) && all(lessThan(pixel, vec2(push.extent) + 2.0)))) {
        return;
    }
    ivec2 centre = ivec2(floor(pixel));
    vec3 flux = max(lights.h[i].flux.rgb, vec3(0.0));
    vec3 colour = flux / max(max(flux.r, max(flux.g, flux.b)), 1e-30);
    for (int dy = -1; dy <= 1; dy++) {
        for (int dx = -1; dx <= 1; dx++) {
            ivec2 q = centre + ivec2(dx, dy);
            if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, ivec2(push.extent)))) {
                imageStore(debug, q, vec4(colour, 1.0));
            }
        }
    }
#else
    uvec2 p = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(p, push.extent))) {
        return;
    }
    vec4 value = vec4(0.0);
#ifdef DEBUG_RECEIVERS
    ivec2 r = source_texel(p) / int(push.scale);
    if (imageLoad(recv_position, r).w > 0.0) {
#ifdef DEBUG_NORMALS
        value = vec4(0.5 * imageLoad(recv_normal, r).xyz + 0.5, 1.0);
#else
        value = vec4(imageLoad(recv_albedo, r).rgb, 1.0);
#endif
    }
#endif
#ifdef DEBUG_RSM
    uint side = min(push.extent.x, push.extent.y);
    uvec2 corner = (push.extent - uvec2(side)) / 2u;
    if (all(greaterThanEqual(p, corner)) && all(lessThan(p, corner + side))) {
        uint size = push.source.x;
        uvec2 u = p - corner;
        uvec2 first = u * size / side;
        uvec2 last = max((u + 1u) * size / side, first + 1u);
        uvec2 step = max((last - first) / 8u, uvec2(1u));
        vec3 sum = vec3(0.0);
        float n = 0.0;
        for (uint y = first.y; y < last.y; y += step.y) {
            for (uint x = first.x; x < last.x; x += step.x) {
                sum += imageLoad(rsm_flux, ivec2(x, y)).rgb;
                n += 1.0;
            }
        }
        value = vec4(sum / n * float(size) * float(size), 1.0);
    }
#endif
#ifdef DEBUG_BACKGROUND
    vec3 light = max(imageLoad(indirect, source_texel(p)).rgb, vec3(0.0));
    value = vec4(0.5 * light / (1.0 + light), 0.0);
#endif
#ifdef DEBUG_SAMPLES
    ivec2 q = source_texel(p);
    if (imageLoad(gb_position, q).w > 0.0) {
        float n = filter_widths.f[uint(q.y) * push.source.x + uint(q.x)].y;
        float t = (n - push.spp_range.x) / max(push.spp_range.y - push.spp_range.x, 1e-6);
        value = vec4(heat(clamp(t, 0.0, 1.0)), n);
    }
#endif
    imageStore(debug, ivec2(p), value);
#endif
}
