// The host's own Vulkan: instance (validation on where installed), messenger, physical device,
// device, queue, command pool and pipeline cache, and the one command buffer and fence every
// submission reuses. Nothing here knows shine; shine is lent this device (lending.hpp).

#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace capi_host {

// Validation: the messenger records every warning and error; any of them fails the run.
struct ValidationLog {
    std::mutex mutex;  // shine may call Vulkan from other threads.
    std::vector<std::string> messages;
};

// The host's device and what it was created with, owned by the host for the whole run.
struct HostDevice {
    VkInstance instance = VK_NULL_HANDLE;
    bool validation = false;
    bool debug_utils = false;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkPhysicalDeviceMemoryProperties memory{};
    uint32_t family = 0;
    // What the device was created with: shine_device_create reads it (the chain points into
    // this struct, which is therefore never copied).
    float queue_priority = 1.0f;
    VkDeviceQueueCreateInfo queue_info{};
    VkPhysicalDeviceVulkan13Features features13{};
    VkDeviceCreateInfo device_info{};
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkPipelineCache cache = VK_NULL_HANDLE;

    HostDevice() = default;
    HostDevice(const HostDevice&) = delete;
    HostDevice& operator=(const HostDevice&) = delete;
};

// A Vulkan 1.3 instance with the validation layer and VK_EXT_debug_utils where available, and
// a messenger that records warnings and errors into `log`.
void create_instance(HostDevice& host, ValidationLog& log);

// The first Vulkan 1.3 physical device with a queue family that does graphics, compute and
// timestamps (what shine needs of the queue it is lent).
void pick_physical_device(HostDevice& host);

// The device with what both the host and shine need: Vulkan 1.3 synchronization2 (shine) and
// dynamicRendering (the host's raster and shine); then its queue, pool and pipeline cache.
void create_device(HostDevice& host);

void destroy_host_device(HostDevice& host);

// Submission: one command buffer and one fence, reused by every submission.
struct Submitter {
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
};

Submitter create_submitter(const HostDevice& host);

void destroy_submitter(const HostDevice& host, Submitter& s);

// Resets the command buffer (whatever it held) and begins it for one submission.
void begin(const Submitter& s);

// Ends the command buffer, submits it to the host's queue and waits for it.
void submit_and_wait(const HostDevice& host, const Submitter& s);

}  // namespace capi_host
