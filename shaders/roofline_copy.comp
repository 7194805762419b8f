// Roofline micro-kernel (shine::profile::roofline): the device's memory bandwidth, one vec4 read
// and one written per invocation over buffers far larger than any cache.
#version 460

layout(local_size_x = 256) in;

layout(set = 0, binding = 0, std430) readonly buffer Source {
    vec4 v[];
} source;

layout(set = 0, binding = 1, std430) buffer Target {
    vec4 v[];
} target;

// shine::profile::roofline::CopyPush
layout(push_constant) uniform Push {
    // vec4 elements copied
    uint count;
} push;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < push.count) {
        target.v[i] = source.v[i];
    }
}
