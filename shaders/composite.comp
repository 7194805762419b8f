// Composite (docs/frame.md, "Direct light and composition"): direct + indirect_full radiance,
// times exposure, into the linear HDR frame, and tonemapped + sRGB-encoded into the LDR frame.
//! variant with_indirect INDIRECT=1
//! variant direct_only INDIRECT=0
#version 460
#extension GL_GOOGLE_include_directive : require
#include "tonemap.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) uniform readonly image2D direct;
#if INDIRECT
layout(set = 0, binding = 1, rgba16f) uniform readonly image2D indirect_full;
#endif
layout(set = 0, binding = 2, rgba32f) uniform writeonly image2D hdr;
layout(set = 0, binding = 3, rgba8) uniform writeonly image2D ldr;

// CompositePush in src/passes/composite.rs.
layout(push_constant) uniform Push {
    uvec2 extent;
    float exposure;
    uint op;
} push;

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, push.extent))) {
        return;
    }
    ivec2 p = ivec2(pixel);
    vec3 radiance = imageLoad(direct, p).rgb;
#if INDIRECT
    radiance += imageLoad(indirect_full, p).rgb;
#endif
    vec3 exposed = radiance * push.exposure;
    imageStore(hdr, p, vec4(exposed, 1.0));
    imageStore(ldr, p, encode_ldr(push.op, exposed));
}
