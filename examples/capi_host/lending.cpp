// What the host lends shine: its device, its images and their states, and each frame's
// dispatch description.

#include "lending.hpp"

#include "errors.hpp"

#include <cstring>

namespace capi_host {
namespace {

ShineImageState state(VkPipelineStageFlags2 stage, VkAccessFlags2 access, VkImageLayout layout) {
    return ShineImageState{stage, access, static_cast<int32_t>(layout)};
}

// Where the raster leaves a colour target.
ShineImageState color_written() {
    return state(VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL);
}

// Where the raster leaves the depth target.
ShineImageState depth_written() {
    return state(VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL);
}

// Where shine leaves the inputs: read by shaders (the next frame starts them from UNDEFINED).
ShineImageState sampled_after() {
    return state(VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT,
                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
}

}  // namespace

ShineDevice lend_to_shine(const HostDevice& host) {
    ShineDeviceDesc desc{};
    desc.version = SHINE_DEVICE_DESC_VERSION;
    // The header declares its own function pointer types; the ABI is Vulkan's.
    desc.get_instance_proc_addr =
        reinterpret_cast<ShinePfnGetInstanceProcAddr>(vkGetInstanceProcAddr);
    desc.instance = host.instance;
    desc.physical_device = host.physical;
    desc.device = host.device;
    desc.queue_family_index = host.family;
    desc.queue = host.queue;
    desc.device_create_info = &host.device_info;
    desc.api_version = VK_API_VERSION_1_3;
    desc.debug_utils = host.debug_utils ? 1 : 0;
    desc.pipeline_cache = reinterpret_cast<ShineVkPipelineCache>(host.cache);
    ShineDevice device = nullptr;
    check_shine(shine_device_create(&desc, &device), "shine_device_create");
    return device;
}

ShineImageState copy_source() {
    return state(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

ShineImageState undefined_state() {
    return state(VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_IMAGE_LAYOUT_UNDEFINED);
}

ShineImage lend(const HostImage& i, ShineImageState before, ShineImageState after) {
    ShineImage s{};
    // Non-dispatchable handles are 64-bit on every platform shine supports.
    s.image = reinterpret_cast<ShineVkImage>(i.image);
    s.view = reinterpret_cast<ShineVkImageView>(i.view);
    s.format = static_cast<int32_t>(i.format);
    s.width = i.width;
    s.height = i.height;
    s.usage = i.usage;
    s.before = before;
    s.after = after;
    return s;
}

ShineDispatchDesc dispatch_desc(uint64_t frame, const Camera& camera, const Targets& t,
                                const ShineImage* diffuse) {
    ShineDispatchDesc d{};
    d.version = SHINE_DISPATCH_DESC_VERSION;
    d.frame_index = frame;
    // A still camera: the previous frame's matrices are this frame's.
    const size_t matrix = sizeof(d.camera.view);
    std::memcpy(d.camera.view, camera.view.data(), matrix);
    std::memcpy(d.camera.projection, camera.projection.data(), matrix);
    std::memcpy(d.camera.previous_view, camera.view.data(), matrix);
    std::memcpy(d.camera.previous_projection, camera.projection.data(), matrix);
    d.depth = lend(t.depth, depth_written(), sampled_after());
    d.depth_reversed = 0;
    d.normals = lend(t.normal, color_written(), sampled_after());
    d.normal_mul = 2.0f;  // UNORM: n = texel * 2 - 1
    d.normal_add = -1.0f;
    d.albedo = lend(t.albedo, color_written(), sampled_after());
    d.material = lend(t.material, color_written(), sampled_after());
    d.roughness_channel = 0;
    d.metallic_channel = 1;
    d.roughness_squared = 0;
    d.motion = nullptr;
    d.environment = nullptr;
    d.diffuse = diffuse;
    d.specular = nullptr;
    return d;
}

}  // namespace capi_host
