// Readback and output: copying the GI image back, converting it, writing it, averaging it.

#include "readback.hpp"

#include "errors.hpp"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>

namespace capi_host {
namespace {

// IEEE 754 half to single precision (exact: every half is a float).
float half_to_float(uint16_t h) {
    const float sign = (h & 0x8000u) != 0 ? -1.0f : 1.0f;
    const int exponent = (h >> 10) & 0x1f;
    const int mantissa = h & 0x3ff;
    if (exponent == 0) return sign * std::ldexp(float(mantissa), -24);  // zero, subnormal
    if (exponent == 31) return mantissa == 0 ? sign * std::numeric_limits<float>::infinity()
                                             : std::numeric_limits<float>::quiet_NaN();
    return sign * std::ldexp(float(1024 + mantissa), exponent - 25);
}

}  // namespace

std::vector<float> read_rgba16f(const HostDevice& host, const Submitter& s,
                                const HostImage& image) {
    const size_t halves_count = size_t(image.width) * image.height * 4;
    HostBuffer buffer = create_host_buffer(host, halves_count * sizeof(uint16_t),
                                           VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    begin(s);
    // Orders the copy after shine's last use of the image (the state it was left in).
    VkImageMemoryBarrier2 barrier{};
    barrier.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2;
    barrier.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    barrier.srcAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT;
    barrier.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    barrier.dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT;
    barrier.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    barrier.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    barrier.image = image.image;
    barrier.subresourceRange = whole(VK_IMAGE_ASPECT_COLOR_BIT);
    VkDependencyInfo dependency{};
    dependency.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
    dependency.imageMemoryBarrierCount = 1;
    dependency.pImageMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(s.cb, &dependency);

    VkBufferImageCopy copy{};  // Tightly packed rows.
    copy.imageSubresource = VkImageSubresourceLayers{VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = VkExtent3D{image.width, image.height, 1};
    vkCmdCopyImageToBuffer(s.cb, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer.buffer,
                           1, &copy);

    // Makes the copy's writes visible to the host's reads after the fence.
    VkMemoryBarrier2 to_host{};
    to_host.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER_2;
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo host_dependency{};
    host_dependency.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
    host_dependency.memoryBarrierCount = 1;
    host_dependency.pMemoryBarriers = &to_host;
    vkCmdPipelineBarrier2(s.cb, &host_dependency);
    submit_and_wait(host, s);

    std::vector<uint16_t> halves(halves_count);
    std::memcpy(halves.data(), buffer.mapped, halves.size() * sizeof(uint16_t));
    destroy_buffer(host, buffer);
    std::vector<float> rgba(halves.size());
    for (size_t i = 0; i < halves.size(); ++i) rgba[i] = half_to_float(halves[i]);
    return rgba;
}

void write_raw(const std::string& path, const std::vector<float>& rgba) {
    std::vector<unsigned char> bytes(rgba.size() * 4);
    for (size_t i = 0; i < rgba.size(); ++i) {
        uint32_t bits;
        std::memcpy(&bits, &rgba[i], sizeof(bits));
        for (int b = 0; b < 4; ++b) bytes[4 * i + b] = static_cast<unsigned char>(bits >> (8 * b));
    }
    const std::string partial = path + ".partial";
    {
        std::ofstream file(partial, std::ios::binary | std::ios::trunc);
        file.write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
        if (!file) fail("cannot write " + partial);
    }
    if (std::rename(partial.c_str(), path.c_str()) != 0) {
        fail("cannot rename " + partial + " to " + path + ": " + std::strerror(errno));
    }
}

double mean_rgb(const std::vector<float>& rgba) {
    double sum = 0.0;
    for (size_t i = 0; i < rgba.size(); i += 4) {
        sum += (double(rgba[i]) + rgba[i + 1] + rgba[i + 2]) / 3.0;
    }
    return rgba.empty() ? 0.0 : sum / double(rgba.size() / 4);
}

}  // namespace capi_host
