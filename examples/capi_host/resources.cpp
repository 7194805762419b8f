// Memory, buffers and images: creating and destroying them on the host's device.

#include "resources.hpp"

#include "errors.hpp"

namespace capi_host {
namespace {

// Device memory of a type that `requirements` allows and that has `properties`.
VkDeviceMemory allocate(const HostDevice& host, const VkMemoryRequirements& requirements,
                        VkMemoryPropertyFlags properties) {
    for (uint32_t i = 0; i < host.memory.memoryTypeCount; ++i) {
        const bool allowed = (requirements.memoryTypeBits & (1u << i)) != 0;
        if (allowed && (host.memory.memoryTypes[i].propertyFlags & properties) == properties) {
            VkMemoryAllocateInfo info{};
            info.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
            info.allocationSize = requirements.size;
            info.memoryTypeIndex = i;
            VkDeviceMemory memory = VK_NULL_HANDLE;
            check_vk(vkAllocateMemory(host.device, &info, nullptr, &memory), "vkAllocateMemory");
            return memory;
        }
    }
    fail("no memory type with the properties needed");
}

}  // namespace

HostBuffer create_host_buffer(const HostDevice& host, VkDeviceSize size, VkBufferUsageFlags usage) {
    HostBuffer b;
    VkBufferCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
    info.size = size;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    check_vk(vkCreateBuffer(host.device, &info, nullptr, &b.buffer), "vkCreateBuffer");
    VkMemoryRequirements requirements;
    vkGetBufferMemoryRequirements(host.device, b.buffer, &requirements);
    b.memory = allocate(host, requirements,
                        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    check_vk(vkBindBufferMemory(host.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
    check_vk(vkMapMemory(host.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
    return b;
}

void destroy_buffer(const HostDevice& host, HostBuffer& b) {
    vkDestroyBuffer(host.device, b.buffer, nullptr);
    vkFreeMemory(host.device, b.memory, nullptr);  // Unmaps it.
}

VkImageSubresourceRange whole(VkImageAspectFlags aspect) {
    return VkImageSubresourceRange{aspect, 0, 1, 0, 1};
}

HostImage create_image(const HostDevice& host, VkFormat format, uint32_t width, uint32_t height,
                       VkImageUsageFlags usage) {
    HostImage i;
    i.format = format;
    i.usage = usage;
    i.width = width;
    i.height = height;
    VkImageCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = VkExtent3D{width, height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    check_vk(vkCreateImage(host.device, &info, nullptr, &i.image), "vkCreateImage");
    VkMemoryRequirements requirements;
    vkGetImageMemoryRequirements(host.device, i.image, &requirements);
    i.memory = allocate(host, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    check_vk(vkBindImageMemory(host.device, i.image, i.memory, 0), "vkBindImageMemory");

    VkImageViewCreateInfo view{};
    view.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO;
    view.image = i.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = whole(format == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT
                                                                 : VK_IMAGE_ASPECT_COLOR_BIT);
    check_vk(vkCreateImageView(host.device, &view, nullptr, &i.view), "vkCreateImageView");
    return i;
}

void destroy_image(const HostDevice& host, HostImage& i) {
    vkDestroyImageView(host.device, i.view, nullptr);
    vkDestroyImage(host.device, i.image, nullptr);
    vkFreeMemory(host.device, i.memory, nullptr);
}

}  // namespace capi_host
