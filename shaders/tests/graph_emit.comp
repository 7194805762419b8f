// Render-graph GPU test: writes T full-viewport triangles whose vertices carry the value t + 1.
#version 460

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) buffer Vertices {
    vec4 v[];
} vertices;

layout(push_constant) uniform Push {
    uint triangles;
} push;

void main() {
    uint t = gl_GlobalInvocationID.x;
    if (t >= push.triangles) {
        return;
    }
    float value = float(t + 1u);
    vertices.v[3u * t + 0u] = vec4(-1.0, -1.0, value, 0.0);
    vertices.v[3u * t + 1u] = vec4(3.0, -1.0, value, 0.0);
    vertices.v[3u * t + 2u] = vec4(-1.0, 3.0, value, 0.0);
}
