// Roofline micro-kernel (shine::profile::roofline): the device's fp32 multiply-add peak. Each
// invocation runs push.iterations loop iterations of 8 steps of 4 independent vec4 FMA chains
// (256 flops an iteration): enough independent work to fill the FMA pipelines of a GPU or of
// llvmpipe's SIMD lanes without spilling (16 chains per lane), and few loop iterations, which
// llvmpipe counts against its loop limit. The sum is stored so nothing is optimised away.
#version 460
#extension GL_EXT_control_flow_attributes : require

layout(local_size_x = 256) in;

layout(set = 0, binding = 0, std430) buffer Sink {
    float v[];
} sink;

// shine::profile::roofline::FmaPush
layout(push_constant) uniform Push {
    // loop iterations per invocation (at most 65535: llvmpipe's loop limit)
    uint iterations;
    // multiplier and addend of every step (values the compiler cannot fold)
    float a;
    float b;
    uint pad;
} push;

void main() {
    uint id = gl_GlobalInvocationID.x;
    // Four different lanes: a compiler cannot merge them into one.
    vec4 x0 = vec4(float(id) * 1e-9) + vec4(0.0, 0.25, 0.5, 0.75);
    vec4 x1 = x0 + 1.0;
    vec4 x2 = x0 + 2.0;
    vec4 x3 = x0 + 3.0;
    vec4 a = vec4(push.a);
    vec4 b = vec4(push.b);
    for (uint i = 0u; i < push.iterations; ++i) {
        [[unroll]] for (int k = 0; k < 8; ++k) {
            x0 = fma(x0, a, b);
            x1 = fma(x1, a, b);
            x2 = fma(x2, a, b);
            x3 = fma(x3, a, b);
        }
    }
    vec4 s = x0 + x1 + x2 + x3;
    sink.v[id] = s.x + s.y + s.z + s.w;
}
