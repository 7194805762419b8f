// Render-graph GPU test: samples a depth image at texel centres into a buffer.
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0) uniform texture2D depth;
layout(set = 0, binding = 1) uniform sampler nearest;

layout(set = 0, binding = 2, std430) buffer Result {
    float r[];
} result;

layout(push_constant) uniform Push {
    uint width;
    uint height;
} push;

void main() {
    uvec2 p = gl_GlobalInvocationID.xy;
    if (p.x >= push.width || p.y >= push.height) {
        return;
    }
    vec2 uv = (vec2(p) + 0.5) / vec2(push.width, push.height);
    result.r[p.y * push.width + p.x] = textureLod(sampler2D(depth, nearest), uv, 0.0).r;
}
