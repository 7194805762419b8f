// The G-buffer: the host's render targets (the Rust host's `Targets`), its raster pipeline
// (the Rust host's `Raster`, with dynamic rendering) and the recording of one G-buffer pass.
// It matches examples/host_gbuffer/host in shaders, formats, raster state and push constants,
// so both hosts hand shine the same inputs.

#pragma once

#include "resources.hpp"
#include "scene.hpp"
#include "vulkan_host.hpp"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

namespace capi_host {

// The G-buffer, direct-light and GI images.
struct Targets {
    HostImage depth, normal, albedo, material, direct, gi;
};

Targets create_targets(const HostDevice& host, uint32_t width, uint32_t height);

void destroy_targets(const HostDevice& host, Targets& t);

struct Raster {
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

// World-space vertices (position, normal), no culling, depth test LESS_OR_EQUAL with writes,
// four colour targets (normal, albedo, material, direct) without blending.
// The shaders are `shader_dir`/gbuffer.vert.spv and gbuffer.frag.spv.
Raster create_raster(const HostDevice& host, const std::string& shader_dir);

void destroy_raster(const HostDevice& host, Raster& r);

// Records the G-buffer and direct light of `scene` seen through `view_proj` into `targets`,
// leaving colours in COLOR_ATTACHMENT_OPTIMAL and depth in DEPTH_ATTACHMENT_OPTIMAL.
void record_raster(VkCommandBuffer cb, const Raster& raster, const Targets& targets,
                   const HostScene& scene, const Mat4& view_proj);

}  // namespace capi_host
