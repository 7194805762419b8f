// The scene as the host draws it: uploading shine's flattened geometry, and the camera.

#include "scene.hpp"

#include "errors.hpp"

#include <cstring>

namespace capi_host {

HostScene upload_scene(const HostDevice& host, ShineScene scene) {
    ShineGeometry geometry{};
    check_shine(shine_scene_flatten(scene, 0.0f, &geometry), "shine_scene_flatten");
    if (geometry.vertex_count == 0 || geometry.index_count == 0) fail("the scene has no geometry");
    const VkDeviceSize vertex_bytes = VkDeviceSize(geometry.vertex_count) * 6 * sizeof(float);
    const VkDeviceSize index_bytes = VkDeviceSize(geometry.index_count) * sizeof(uint32_t);
    HostScene s;
    s.vertices = create_host_buffer(host, vertex_bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    std::memcpy(s.vertices.mapped, geometry.vertices, vertex_bytes);
    s.indices = create_host_buffer(host, index_bytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
    std::memcpy(s.indices.mapped, geometry.indices, index_bytes);
    // The arrays belong to the scene: copy the draws before anything else touches it.
    s.draws.assign(geometry.draws, geometry.draws + geometry.draw_count);
    return s;
}

void destroy_scene(const HostDevice& host, HostScene& s) {
    destroy_buffer(host, s.vertices);
    destroy_buffer(host, s.indices);
}

Mat4 multiply(const Mat4& a, const Mat4& b) {
    Mat4 m{};
    for (int col = 0; col < 4; ++col) {
        for (int row = 0; row < 4; ++row) {
            float sum = a[0 * 4 + row] * b[col * 4 + 0];
            sum = sum + a[1 * 4 + row] * b[col * 4 + 1];
            sum = sum + a[2 * 4 + row] * b[col * 4 + 2];
            sum = sum + a[3 * 4 + row] * b[col * 4 + 3];
            m[col * 4 + row] = sum;
        }
    }
    return m;
}

Camera scene_camera(ShineScene scene, uint32_t width, uint32_t height) {
    Camera c{};
    check_shine(
        shine_scene_camera(scene, 0, 0.0f, width, height, c.view.data(), c.projection.data()),
        "shine_scene_camera");
    return c;
}

}  // namespace capi_host
