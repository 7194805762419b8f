// The host's own Vulkan objects: creating and destroying its instance, messenger, device,
// queue, pool and cache, and submitting its one command buffer.

#include "vulkan_host.hpp"

#include "errors.hpp"

#include <cstring>
#include <iostream>

namespace capi_host {
namespace {

const char* const kValidationLayer = "VK_LAYER_KHRONOS_validation";

// The messenger's callback: prints each warning and error and records it in the log.
VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    const VkDebugUtilsMessageSeverityFlagsEXT counted =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    if ((severity & counted) != 0) {
        const std::string text = data != nullptr && data->pMessage != nullptr ? data->pMessage : "";
        std::cerr << "[host validation] " << text << "\n";
        auto* log = static_cast<ValidationLog*>(user);
        std::lock_guard<std::mutex> lock(log->mutex);
        log->messages.push_back(text);
    }
    return VK_FALSE;
}

bool has_instance_layer(const char* name) {
    uint32_t count = 0;
    const char* call = "vkEnumerateInstanceLayerProperties";
    check_vk(vkEnumerateInstanceLayerProperties(&count, nullptr), call);
    std::vector<VkLayerProperties> layers(count);
    check_vk(vkEnumerateInstanceLayerProperties(&count, layers.data()), call);
    for (const auto& layer : layers) {
        if (std::strcmp(layer.layerName, name) == 0) return true;
    }
    return false;
}

// Whether the loader, or `layer` when not null, offers instance extension `name`.
bool has_instance_extension(const char* layer, const char* name) {
    uint32_t count = 0;
    const char* call = "vkEnumerateInstanceExtensionProperties";
    check_vk(vkEnumerateInstanceExtensionProperties(layer, &count, nullptr), call);
    std::vector<VkExtensionProperties> extensions(count);
    check_vk(vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data()), call);
    for (const auto& extension : extensions) {
        if (std::strcmp(extension.extensionName, name) == 0) return true;
    }
    return false;
}

}  // namespace

void create_instance(HostDevice& host, ValidationLog& log) {
    host.validation = has_instance_layer(kValidationLayer);
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    host.debug_utils = has_instance_extension(nullptr, extension) ||
                       (host.validation && has_instance_extension(kValidationLayer, extension));

    VkApplicationInfo app{};
    app.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO;
    app.pApplicationName = "capi_host";
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO;
    info.pApplicationInfo = &app;
    info.enabledLayerCount = host.validation ? 1 : 0;
    info.ppEnabledLayerNames = &kValidationLayer;
    info.enabledExtensionCount = host.debug_utils ? 1 : 0;
    info.ppEnabledExtensionNames = &extension;
    check_vk(vkCreateInstance(&info, nullptr, &host.instance), "vkCreateInstance");
    if (!host.validation) std::cout << "validation layer not installed: running without it\n";
    if (!host.debug_utils) return;

    VkDebugUtilsMessengerCreateInfoEXT messenger{};
    messenger.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT;
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                            VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    messenger.pfnUserCallback = on_validation_message;
    messenger.pUserData = &log;
    // An extension function: the loader's library does not export it.
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(host.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create == nullptr) fail("vkCreateDebugUtilsMessengerEXT is not available");
    check_vk(create(host.instance, &messenger, nullptr, &host.messenger),
             "vkCreateDebugUtilsMessengerEXT");
}

void pick_physical_device(HostDevice& host) {
    uint32_t count = 0;
    const char* call = "vkEnumeratePhysicalDevices";
    check_vk(vkEnumeratePhysicalDevices(host.instance, &count, nullptr), call);
    std::vector<VkPhysicalDevice> devices(count);
    check_vk(vkEnumeratePhysicalDevices(host.instance, &count, devices.data()), call);
    const VkQueueFlags wanted = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
    for (VkPhysicalDevice device : devices) {
        VkPhysicalDeviceProperties properties;
        vkGetPhysicalDeviceProperties(device, &properties);
        if (properties.apiVersion < VK_API_VERSION_1_3) continue;
        uint32_t families = 0;
        vkGetPhysicalDeviceQueueFamilyProperties(device, &families, nullptr);
        std::vector<VkQueueFamilyProperties> family_properties(families);
        vkGetPhysicalDeviceQueueFamilyProperties(device, &families, family_properties.data());
        for (uint32_t f = 0; f < families; ++f) {
            const auto& family = family_properties[f];
            if ((family.queueFlags & wanted) == wanted && family.timestampValidBits > 0) {
                host.physical = device;
                host.family = f;
                vkGetPhysicalDeviceMemoryProperties(device, &host.memory);
                std::cout << "device: " << properties.deviceName << "\n";
                return;
            }
        }
    }
    fail("no Vulkan 1.3 device with a graphics+compute queue family that has timestamps");
}

void create_device(HostDevice& host) {
    VkPhysicalDeviceVulkan13Features supported{};
    supported.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    VkPhysicalDeviceFeatures2 features{};
    features.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    features.pNext = &supported;
    vkGetPhysicalDeviceFeatures2(host.physical, &features);
    if (!supported.synchronization2 || !supported.dynamicRendering) {
        fail("the device lacks synchronization2 or dynamicRendering");
    }

    host.queue_info.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO;
    host.queue_info.queueFamilyIndex = host.family;
    host.queue_info.queueCount = 1;
    host.queue_info.pQueuePriorities = &host.queue_priority;
    host.features13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    host.features13.synchronization2 = VK_TRUE;
    host.features13.dynamicRendering = VK_TRUE;
    host.device_info.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO;
    host.device_info.pNext = &host.features13;
    host.device_info.queueCreateInfoCount = 1;
    host.device_info.pQueueCreateInfos = &host.queue_info;
    check_vk(vkCreateDevice(host.physical, &host.device_info, nullptr, &host.device),
             "vkCreateDevice");
    vkGetDeviceQueue(host.device, host.family, 0, &host.queue);

    VkCommandPoolCreateInfo pool{};
    pool.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO;
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;  // One buffer, reset per frame.
    pool.queueFamilyIndex = host.family;
    check_vk(vkCreateCommandPool(host.device, &pool, nullptr, &host.pool), "vkCreateCommandPool");
    VkPipelineCacheCreateInfo cache{};
    cache.sType = VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO;
    check_vk(vkCreatePipelineCache(host.device, &cache, nullptr, &host.cache),
             "vkCreatePipelineCache");
}

void destroy_host_device(HostDevice& host) {
    vkDestroyPipelineCache(host.device, host.cache, nullptr);
    vkDestroyCommandPool(host.device, host.pool, nullptr);
    vkDestroyDevice(host.device, nullptr);
    if (host.messenger != VK_NULL_HANDLE) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(host.instance, "vkDestroyDebugUtilsMessengerEXT"));
        destroy(host.instance, host.messenger, nullptr);
    }
    vkDestroyInstance(host.instance, nullptr);
}

Submitter create_submitter(const HostDevice& host) {
    Submitter s;
    VkCommandBufferAllocateInfo allocate_info{};
    allocate_info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO;
    allocate_info.commandPool = host.pool;
    allocate_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate_info.commandBufferCount = 1;
    check_vk(vkAllocateCommandBuffers(host.device, &allocate_info, &s.cb),
             "vkAllocateCommandBuffers");
    VkFenceCreateInfo fence{};
    fence.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO;
    check_vk(vkCreateFence(host.device, &fence, nullptr, &s.fence), "vkCreateFence");
    return s;
}

void destroy_submitter(const HostDevice& host, Submitter& s) {
    vkDestroyFence(host.device, s.fence, nullptr);
    vkFreeCommandBuffers(host.device, host.pool, 1, &s.cb);
}

void begin(const Submitter& s) {
    check_vk(vkResetCommandBuffer(s.cb, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo info{};
    info.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO;
    info.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    check_vk(vkBeginCommandBuffer(s.cb, &info), "vkBeginCommandBuffer");
}

void submit_and_wait(const HostDevice& host, const Submitter& s) {
    check_vk(vkEndCommandBuffer(s.cb), "vkEndCommandBuffer");
    VkSubmitInfo submit{};
    submit.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &s.cb;
    check_vk(vkQueueSubmit(host.queue, 1, &submit, s.fence), "vkQueueSubmit");
    check_vk(vkWaitForFences(host.device, 1, &s.fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    check_vk(vkResetFences(host.device, 1, &s.fence), "vkResetFences");
}

}  // namespace capi_host
