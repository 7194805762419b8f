// `host gbuffer`: a host engine's G-buffer (depth, normals, albedo, roughness/metallic and
// optional motion, in the host's own formats and encodings) turned into the G-buffer images
// the GI techniques read (docs/frame.md), at display size or, for a context's internal
// resolution, smaller: each pixel then takes the host texel under its centre.
// src/passes/host_gbuffer.rs; encodings in docs/embedding.md.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "grid.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

// The host's images, sampled (any layout the graph moves them to; depth through a depth-only
// view).
layout(set = 0, binding = 0) uniform texture2D host_depth;
layout(set = 0, binding = 1) uniform texture2D host_normal;
layout(set = 0, binding = 2) uniform texture2D host_albedo;
layout(set = 0, binding = 3) uniform texture2D host_material;
layout(set = 0, binding = 4) uniform texture2D host_motion;
layout(set = 0, binding = 5) uniform sampler host_sampler;

// shine::passes::host_gbuffer::HostFrame
layout(set = 0, binding = 6, std430) readonly buffer Frame {
    // Clip (with the frame's jitter) to world: undoes the projection the host rasterised with.
    mat4 inverse_view_proj;
    // World to clip without jitter, now and in the previous frame (motion vectors).
    mat4 view_proj;
    mat4 previous_view_proj;
    // Linear view depth of world point p: dot(depth_plane.xyz, p) + depth_plane.w.
    vec4 depth_plane;
    // Eye position (xyz).
    vec4 eye;
    // Host normal n = normalize(texel.xyz * x + y).
    vec4 normal_unpack;
    // x: the depth of an empty pixel (1, or 0 with reversed Z); y, z: host motion scale (shine
    // motion = texel.xy * (y, z)); w: 1 when the host's material holds roughness squared.
    vec4 params;
    // x: roughness channel, y: metallic channel (4: none), z: 1 when host motion is bound,
    // w: unused.
    uvec4 channels;
    // Display width and height (z, w unused).
    uvec4 extent;
} frame;

// shine::passes::host_gbuffer::HostGbufferPush
layout(push_constant) uniform Push {
    // Width and height of the G-buffer written (the display's, or the internal resolution's).
    uvec2 extent;
} push;

layout(set = 0, binding = 7, rgba32f) writeonly uniform image2D gb_position;
layout(set = 0, binding = 8, rgba16f) writeonly uniform image2D gb_normal;
layout(set = 0, binding = 9, rgba8) writeonly uniform image2D gb_albedo;
layout(set = 0, binding = 10, rgba8) writeonly uniform image2D gb_material;
layout(set = 0, binding = 11, rgba16f) writeonly uniform image2D gb_geometric_normal;
layout(set = 0, binding = 12, rg16f) writeonly uniform image2D gb_motion;

// The channel `c` of `v` (0 when c is 4: "none").
float channel(vec4 v, uint c) {
    return c < 4u ? v[c] : 0.0;
}

void main() {
    uvec2 q = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(q, push.extent))) {
        return;
    }
    // The host texel under this pixel's centre (itself at the display size).
    uvec2 xy = texel_under_centre(q, push.extent, frame.extent.xy);
    ivec2 p = ivec2(xy);
    ivec2 out_p = ivec2(q);
    float depth = texelFetch(sampler2D(host_depth, host_sampler), p, 0).r;
    if (abs(depth - frame.params.x) < 1e-7) {
        // Background: every G-buffer image holds 0 there (docs/frame.md).
        imageStore(gb_position, out_p, vec4(0.0));
        imageStore(gb_normal, out_p, vec4(0.0));
        imageStore(gb_albedo, out_p, vec4(0.0));
        imageStore(gb_material, out_p, vec4(0.0));
        imageStore(gb_geometric_normal, out_p, vec4(0.0));
        imageStore(gb_motion, out_p, vec4(0.0));
        return;
    }
    vec2 ndc = (vec2(xy) + 0.5) / vec2(frame.extent.xy) * 2.0 - 1.0;
    vec4 world = frame.inverse_view_proj * vec4(ndc, depth, 1.0);
    vec3 position = world.xyz / world.w;
    float linear_depth = dot(frame.depth_plane.xyz, position) + frame.depth_plane.w;

    vec3 encoded = texelFetch(sampler2D(host_normal, host_sampler), p, 0).xyz;
    vec3 n = encoded * frame.normal_unpack.x + frame.normal_unpack.y;
    n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 1.0, 0.0);
    // The geometric normal faces the camera (IGI's discontinuity filter reads it).
    vec3 facing = dot(n, frame.eye.xyz - position) < 0.0 ? -n : n;

    vec4 material = texelFetch(sampler2D(host_material, host_sampler), p, 0);
    float roughness = clamp(channel(material, frame.channels.x), 0.0, 1.0);
    if (frame.params.w > 0.5) {
        roughness = sqrt(roughness);
    }
    float metallic = clamp(channel(material, frame.channels.y), 0.0, 1.0);

    vec2 motion;
    if (frame.channels.z != 0u) {
        motion = texelFetch(sampler2D(host_motion, host_sampler), p, 0).xy * frame.params.yz;
    } else {
        // The camera's motion alone: where this world point was under the previous camera.
        vec4 now = frame.view_proj * vec4(position, 1.0);
        vec4 then = frame.previous_view_proj * vec4(position, 1.0);
        motion = 0.5 * (now.xy / now.w - then.xy / then.w);
    }

    imageStore(gb_position, out_p, vec4(position, linear_depth));
    imageStore(gb_normal, out_p, vec4(n, 0.0));
    imageStore(gb_albedo, out_p, vec4(texelFetch(sampler2D(host_albedo, host_sampler), p, 0).rgb, 1.0));
    imageStore(gb_material, out_p, vec4(roughness, metallic, 0.0, 0.0));
    imageStore(gb_geometric_normal, out_p, vec4(facing, 0.0));
    imageStore(gb_motion, out_p, vec4(motion, 0.0, 0.0));
}
