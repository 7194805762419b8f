// Render-graph GPU test: reads the splatted image and writes 2 * texel + 1 per pixel.
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D splats;

layout(set = 0, binding = 1, std430) buffer Result {
    vec4 r[];
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
    vec4 c = imageLoad(splats, ivec2(p));
    result.r[p.y * push.width + p.x] = c * 2.0 + vec4(1.0);
}
