// Memory, buffers and images: one allocation per object, which is plenty for an example.
// The scene's buffers, the G-buffer's images and the readback's buffer are all made here.

#pragma once

#include "vulkan_host.hpp"

#include <vulkan/vulkan.h>

#include <cstdint>

namespace capi_host {

// A buffer in host-visible, coherent memory, mapped for its whole life.
struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

HostBuffer create_host_buffer(const HostDevice& host, VkDeviceSize size, VkBufferUsageFlags usage);

void destroy_buffer(const HostDevice& host, HostBuffer& b);

// A 2D device-local image of one mip and layer, with a view of all of it.
struct HostImage {
    VkImage image = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkImageView view = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
    VkImageUsageFlags usage = 0;
    uint32_t width = 0;
    uint32_t height = 0;
};

// All of an image's one mip and layer, for `aspect`.
VkImageSubresourceRange whole(VkImageAspectFlags aspect);

HostImage create_image(const HostDevice& host, VkFormat format, uint32_t width, uint32_t height,
                       VkImageUsageFlags usage);

void destroy_image(const HostDevice& host, HostImage& i);

}  // namespace capi_host
