// Composite (docs/frame.md, "Direct light and composition"): direct + indirect_full radiance,
// times exposure, into the linear HDR frame, and tonemapped + sRGB-encoded into the LDR frame.
// With supersampling (ssaa = N > 1) the inputs are N times the output's size and each output
// pixel is the box average of its N×N input pixels, before exposure and tonemapping. With
// AUTO_EXPOSURE the LDR frame is also multiplied by the frame's automatic exposure (the first
// float of `exposure`, src/passes/exposure.rs); the HDR frame keeps push.exposure only.
//! variant with_indirect INDIRECT=1 AUTO_EXPOSURE=0
//! variant direct_only INDIRECT=0 AUTO_EXPOSURE=0
//! variant with_indirect_auto INDIRECT=1 AUTO_EXPOSURE=1
//! variant direct_only_auto INDIRECT=0 AUTO_EXPOSURE=1
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
#if AUTO_EXPOSURE
layout(set = 0, binding = 4, std430) readonly buffer Exposure {
    float e[];
} exposure;
#endif

// CompositePush in src/passes/composite.rs.
layout(push_constant) uniform Push {
    // output size
    uvec2 extent;
    float exposure;
    uint op;
    // input pixels per output pixel along each axis
    uint ssaa;
    // 1 / ssaa², the box filter's weight
    float inv_samples;
    uint pad0;
    uint pad1;
} push;

void main() {
    uvec2 pixel = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(pixel, push.extent))) {
        return;
    }
    ivec2 p = ivec2(pixel);
    vec3 radiance = vec3(0.0);
    for (uint j = 0u; j < push.ssaa; ++j) {
        for (uint i = 0u; i < push.ssaa; ++i) {
            ivec2 q = p * int(push.ssaa) + ivec2(i, j);
            vec3 sample_radiance = imageLoad(direct, q).rgb;
#if INDIRECT
            sample_radiance += imageLoad(indirect_full, q).rgb;
#endif
            radiance += sample_radiance;
        }
    }
    vec3 exposed = radiance * push.inv_samples * push.exposure;
    imageStore(hdr, p, vec4(exposed, 1.0));
#if AUTO_EXPOSURE
    exposed *= exposure.e[0];
#endif
    imageStore(ldr, p, encode_ldr(push.op, exposed));
}
