// Render-graph GPU test: passes the triangle's value to the fragment shader unchanged.
#version 460

layout(location = 0) in vec4 position;
layout(location = 0) flat out float value;

void main() {
    value = position.z;
    gl_Position = vec4(position.xy, 0.0, 1.0);
}
