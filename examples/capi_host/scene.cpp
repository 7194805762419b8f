// The scene as the host draws it: uploading shine's flattened geometry, and the camera.

#include "scene.hpp"

#include "errors.hpp"

#include <cstring>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace capi_host {

HostScene upload_scene(const HostDevice& host, ShineScene scene) {
    ShineGeometry geometry{};
    check_shine(shine_scene_flatten(scene, 0.0f, &geometry), "shine_scene_flatten");
    if (geometry.vertex_count == 0 || geometry.index_count == 0) fail("the scene has no geometry");
    const VkDeviceSize vertex_bytes = VkDeviceSize(geometry.vertex_count) * 6 * sizeof(float);
    const VkDeviceSize index_bytes = VkDeviceSize(geometry.index_count) * sizeof(uint32_t);
    HostScene s;
    // TRANSFER_SRC: shine reads the buffers back once when they are registered.
    s.vertices = create_host_buffer(
        host, vertex_bytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(s.vertices.mapped, geometry.vertices, vertex_bytes);
    s.indices = create_host_buffer(
        host, index_bytes, VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    s.vertex_count = geometry.vertex_count;
    s.index_count = geometry.index_count;
    std::memcpy(s.indices.mapped, geometry.indices, index_bytes);
    // The arrays belong to the scene: copy the draws before anything else touches it.
    s.draws.assign(geometry.draws, geometry.draws + geometry.draw_count);
    return s;
}

void destroy_scene(const HostDevice& host, HostScene& s) {
    destroy_buffer(host, s.vertices);
    destroy_buffer(host, s.indices);
}

namespace {

// The mesh of one draw of the host's buffers (all vertices, the draw's indices).
ShineHostMesh mesh_of(const HostScene& s, const ShineDraw& draw) {
    const uint32_t vertex_bytes = 6 * sizeof(float);
    ShineHostMesh mesh{};
    mesh.version = SHINE_HOST_MESH_VERSION;
    mesh.vertices.buffer = reinterpret_cast<uint64_t>(s.vertices.buffer);
    mesh.vertices.size = uint64_t(s.vertex_count) * vertex_bytes;
    mesh.vertex_stride = vertex_bytes;
    mesh.vertex_count = s.vertex_count;
    mesh.position_format = SHINE_POSITION_FLOAT3;
    mesh.normal_offset = 3 * sizeof(float);
    mesh.indices.buffer = reinterpret_cast<uint64_t>(s.indices.buffer);
    mesh.indices.size = uint64_t(s.index_count) * sizeof(uint32_t);
    mesh.indices.offset = uint64_t(draw.first_index) * sizeof(uint32_t);
    mesh.index_format = SHINE_INDEX_UINT32;
    mesh.index_count = draw.index_count;
    std::memcpy(mesh.material.base_color, draw.base_color, sizeof draw.base_color);
    mesh.material.roughness = draw.roughness;
    mesh.material.metallic = draw.metallic;
    std::memcpy(mesh.material.emissive, draw.emissive, sizeof draw.emissive);
    mesh.material.double_sided = draw.double_sided;
    return mesh;
}

// A vertex buffer stated one byte too small for its vertices is refused with
// SHINE_RESULT_ERROR_INVALID_ARGUMENT and a message, and registers nothing.
void check_bad_mesh_is_refused(ShineContext context, const HostScene& s) {
    ShineHostMesh mesh = mesh_of(s, s.draws.front());
    mesh.vertices.size -= 1;
    uint32_t id = 0;
    const ShineResult result = shine_context_register_mesh(context, &mesh, &id);
    const std::string message = shine_last_error();
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT || message.empty()) {
        fail(std::string("a too-small vertex buffer was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "too-small buffer refused: " << shine_result_name(result) << ": " << message
              << "\n";
}

// A new shape for a mesh registered rigid (deformable = 0) is refused with
// SHINE_RESULT_ERROR_INVALID_ARGUMENT and a message, and changes nothing.
void check_rigid_mesh_is_not_deformed(ShineContext context, uint32_t mesh, uint32_t vertex_count) {
    const std::vector<float> positions(size_t(vertex_count) * 3, 0.0f);
    const ShineResult result =
        shine_context_deform_mesh(context, mesh, positions.data(), nullptr, vertex_count);
    const std::string message = shine_last_error();
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT ||
        message.find("rigid") == std::string::npos) {
        fail(std::string("deforming a rigid mesh was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "rigid mesh deformation refused: " << shine_result_name(result) << ": "
              << message << "\n";
}

// A NaN scene time is refused with SHINE_RESULT_ERROR_INVALID_ARGUMENT and a message; a
// finite one is taken.
void check_nan_time_is_refused(ShineContext context) {
    const ShineResult result =
        shine_context_set_time(context, std::numeric_limits<float>::quiet_NaN());
    const std::string message = shine_last_error();
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT || message.empty()) {
        fail(std::string("a NaN scene time was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "NaN time refused: " << shine_result_name(result) << ": " << message << "\n";
    check_shine(shine_context_set_time(context, 0.0f), "shine_context_set_time");
}

}  // namespace

void register_with_shine(ShineContext context, ShineScene scene, const HostScene& s) {
    check_bad_mesh_is_refused(context, s);
    std::vector<ShineHostInstance> instances;
    for (const ShineDraw& draw : s.draws) {
        const ShineHostMesh mesh = mesh_of(s, draw);
        ShineHostInstance instance{};
        check_shine(shine_context_register_mesh(context, &mesh, &instance.mesh),
                    "shine_context_register_mesh");
        for (int row = 0; row < 3; ++row) instance.transform[row][row] = 1.0f;
        instances.push_back(instance);
    }
    uint32_t light_count = 0;
    check_shine(shine_scene_lights(scene, 0.0f, nullptr, 0, &light_count), "shine_scene_lights");
    std::vector<ShineLight> lights(light_count);
    check_shine(shine_scene_lights(scene, 0.0f, lights.data(), light_count, &light_count),
                "shine_scene_lights");
    check_shine(shine_context_set_instances(context, instances.data(), uint32_t(instances.size()),
                                            lights.data(), light_count),
                "shine_context_set_instances");
    check_rigid_mesh_is_not_deformed(context, instances.front().mesh, s.vertex_count);
    check_nan_time_is_refused(context);
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
