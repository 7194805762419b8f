// Render-graph GPU test: positions straight from the vertex buffer (a depth-only pass).
#version 460

layout(location = 0) in vec4 position;

void main() {
    gl_Position = vec4(position.xyz, 1.0);
}
