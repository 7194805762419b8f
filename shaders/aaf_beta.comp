// AAF filter width and sampling rate per pixel (paper 004 eq. 15, 16, 21; src/passes/aaf/):
// from the first pass's nearest and farthest reflector distances and the pixel's world-space
// footprint d. z_min is clamped from below (a fraction of the scene's size) and z_max to at
// least z_min; the sample count is clamped to [spp_min, spp_max]. A pixel whose first rays all
// escaped takes its reflectors at the scene's size (z_min = z_max = S): the widest filter the
// formulas give inside the scene, and the fewest samples; a background pixel gets neither.
// Omega_h is the receiver's: the diffuse bandlimit blended towards its GGX lobe's Blinn-Phong
// bandlimit by metallic.
// CPU twin: shine::reference::aaf::beta_cpu.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"
#include "aaf.glsl"
#include "amortise.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
layout(set = 0, binding = 1, std430) readonly buffer Depths {
    vec2 z[];
} depths;
// x: beta (world units), y: samples per pixel.
layout(set = 0, binding = 3, rgba8) readonly uniform image2D gb_material;
layout(set = 0, binding = 2, std430) buffer Filter {
    vec2 f[];
} filter_widths;

// shine::passes::aaf::BetaPush (64 bytes).
layout(push_constant) uniform Push {
    uvec2 extent;
    // d = linear depth * footprint.x + footprint.y.
    vec2 footprint;
    // x: Omega_h, y: alpha, z: mu, w: gamma.
    vec4 paper;
    // x: lower clamp of z_min, y: spp_min, z: spp_max, w: the scene's size S.
    vec4 clamps;
    // the pixels (aaf_sample.comp's config.z)
    uint slice;
    uint pad0;
    uint pad1;
    uint pad2;
} push;

// Slice AMORTISE_REGATHER_SLICE: the pixels to compute, alpha -1; not read by the others.
layout(set = 0, binding = 4, rgba16f) readonly uniform image2D marks;

void main() {
    uvec2 pixel = uvec2(amortise_pixel(gl_GlobalInvocationID.xy, push.slice));
    if (any(greaterThanEqual(pixel, push.extent))) {
        return;
    }
    if (push.slice == AMORTISE_REGATHER_SLICE && imageLoad(marks, ivec2(pixel)).a >= 0.0) {
        return;
    }
    uint p = pixel.y * push.extent.x + pixel.x;
    float depth = imageLoad(gb_position, ivec2(pixel)).w;
    vec2 z = depths.z[p];
    if (depth == 0.0) {
        filter_widths.f[p] = vec2(0.0);
        return;
    }
    if (z.y == 0.0) {
        z = vec2(push.clamps.w);
    }
    float d = depth * push.footprint.x + push.footprint.y;
    float z_min = max(z.x, push.clamps.x);
    float z_max = max(z.y, z_min);
    vec2 roughness_metallic = imageLoad(gb_material, ivec2(pixel)).rg;
    float omega_h = aaf_receiver_bandlimit(push.paper.x, roughness_metallic.x, roughness_metallic.y);
    float omega_r = aaf_filter_bandwidth(omega_h, z_min, d, push.paper.y, push.paper.z);
    float n = aaf_samples_per_pixel(omega_h, z_min, z_max, d, push.paper.y, push.paper.z, push.paper.w);
    filter_widths.f[p] = vec2(aaf_filter_width(omega_r), clamp(ceil(n), push.clamps.y, push.clamps.z));
}
