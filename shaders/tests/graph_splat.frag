// Render-graph GPU test: splats (v, v*x, v*y, 1), summed by additive blending.
#version 460

layout(location = 0) flat in float value;
layout(location = 0) out vec4 color;

void main() {
    color = vec4(value, value * gl_FragCoord.x, value * gl_FragCoord.y, 1.0);
}
