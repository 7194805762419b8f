// `gbuffer history`: this frame's geometric normal and linear view depth kept for the next frame
// (src/passes/history.rs), where temporal passes and hosts read them as the previous frame's.
#version 460

layout(local_size_x = 8, local_size_y = 8) in;

layout(set = 0, binding = 0, rgba32f) readonly uniform image2D gb_position;
// The interpolated vertex normal, facing the camera: unlike the normal-mapped shading normal,
// it does not change when a jittered sample lands on another texel of a normal map.
layout(set = 0, binding = 1, rgba16f) readonly uniform image2D gb_geometric_normal;
// xyz: geometric normal, w: linear view depth (0 on the background).
layout(set = 0, binding = 2, rgba32f) uniform image2D history;

// shine::passes::history::HistoryPush
layout(push_constant) uniform Push {
    uvec2 extent;
} push;

void main() {
    uvec2 xy = gl_GlobalInvocationID.xy;
    if (any(greaterThanEqual(xy, push.extent))) {
        return;
    }
    ivec2 p = ivec2(xy);
    imageStore(history, p, vec4(imageLoad(gb_geometric_normal, p).xyz, imageLoad(gb_position, p).w));
}
