// Sum of two receiver-resolution GI images (`--gi hvl,proxy`: HVL indirect + proxy-shadowed
// environment and proxy indirect), before one bilateral upsample. docs/frame.md, "Proxy GI".
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba16f) readonly uniform image2D first;
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D second;
layout(set = 0, binding = 2, rgba16f) uniform image2D sum;

// shine::passes::gi_add::AddPush
layout(push_constant) uniform Push {
    uvec2 extent;
} push;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 ixy = ivec2(xy);
    imageStore(sum, ixy, imageLoad(first, ixy) + imageLoad(second, ixy));
}
