// The scene as the host draws it: world-space geometry from shine_scene_flatten in the host's
// buffers, and shine's camera for it, so the host rasterises what shine lights.

#pragma once

#include "resources.hpp"
#include "vulkan_host.hpp"

#include "shine.h"

#include <array>
#include <cstdint>
#include <vector>

namespace capi_host {

struct HostScene {
    HostBuffer vertices;  // 6 floats per vertex: position, normal.
    HostBuffer indices;   // uint32 triangle list.
    uint32_t vertex_count = 0;
    uint32_t index_count = 0;
    std::vector<ShineDraw> draws;
};

// The scene's geometry at time 0 copied into host-visible buffers, with its draws.
HostScene upload_scene(const HostDevice& host, ShineScene scene);

void destroy_scene(const HostDevice& host, HostScene& s);

// Hands shine the host's own geometry: one mesh per draw registered from the host's vertex and
// index buffers, placed where they are (the identity), lit by the scene's lights at time 0.
void register_with_shine(ShineContext context, ShineScene scene, const HostScene& s);

// Column-major 4x4 matrices, as in shine.h and GLSL.
using Mat4 = std::array<float, 16>;

// a * b, summed in the order glam's SSE2 Mat4 product sums (column j of the result is
// ((a0 * b0j + a1 * b1j) + a2 * b2j) + a3 * b3j with a_k a's columns, no fused multiply-add),
// so view_proj is bit-identical to the Rust host's `projection * view`.
Mat4 multiply(const Mat4& a, const Mat4& b);

struct Camera {
    Mat4 view;        // world to view
    Mat4 projection;  // view to clip, Vulkan convention (y down, depth 0..1)
};

// The scene's first camera at time 0, for a `width` x `height` image.
Camera scene_camera(ShineScene scene, uint32_t width, uint32_t height);

}  // namespace capi_host
