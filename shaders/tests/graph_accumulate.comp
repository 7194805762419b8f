// Render-graph GPU test: current = previous + (frame + 1) * i, over a ping-pong history.
#version 460

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Previous {
    float v[];
} previous;

layout(set = 0, binding = 1, std430) buffer Current {
    float v[];
} current;

layout(push_constant) uniform Push {
    uint count;
    uint frame;
    uint has_history;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= push.count) {
        return;
    }
    float before = push.has_history != 0u ? previous.v[i] : 0.0;
    current.v[i] = before + float((push.frame + 1u) * i);
}
