// capi_host: a C++ host engine that uses shine as its GI pass through the C API (shine.h).
//
// The host owns everything Vulkan: its instance (validation on where installed), device,
// queue, command pool, pipeline cache, G-buffer images and raster pipeline. It lends the
// device to shine, rasterises its own G-buffer each frame, records shine's dispatch into its
// own command buffer, submits, and reads the GI image back to a raw float file.
//
// The G-buffer is rasterised exactly as the Rust host of examples/host_gbuffer/host does
// (same shaders, formats, raster state, push constants and image states), so both hosts
// hand shine the same inputs and get the same GI.
//
// Usage: capi_host <scene> <width> <height> <frames> <out.raw> <shader_dir>

#include <vulkan/vulkan.h>

#include "shine.h"

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <mutex>
#include <string>
#include <vector>

namespace {

// ---------------------------------------------------------------------------------------------
// Errors: every failure is fatal for this example; it says what failed and exits 1.

[[noreturn]] void fail(const std::string& what) {
    std::cerr << "capi_host: " << what << "\n";
    std::exit(1);
}

void check_vk(VkResult result, const char* call) {
    if (result != VK_SUCCESS) {
        fail(std::string(call) + " failed with VkResult " + std::to_string(result));
    }
}

const char* shine_result_name(ShineResult result) {
    switch (result) {
        case SHINE_RESULT_SUCCESS: return "SHINE_RESULT_SUCCESS";
        case SHINE_RESULT_ERROR_NULL_HANDLE: return "SHINE_RESULT_ERROR_NULL_HANDLE";
        case SHINE_RESULT_ERROR_STALE_HANDLE: return "SHINE_RESULT_ERROR_STALE_HANDLE";
        case SHINE_RESULT_ERROR_INVALID_ARGUMENT: return "SHINE_RESULT_ERROR_INVALID_ARGUMENT";
        case SHINE_RESULT_ERROR_VERSION_MISMATCH: return "SHINE_RESULT_ERROR_VERSION_MISMATCH";
        case SHINE_RESULT_ERROR_MISSING_FEATURES: return "SHINE_RESULT_ERROR_MISSING_FEATURES";
        case SHINE_RESULT_ERROR_VULKAN: return "SHINE_RESULT_ERROR_VULKAN";
        case SHINE_RESULT_ERROR_SCENE: return "SHINE_RESULT_ERROR_SCENE";
        case SHINE_RESULT_ERROR_INTERNAL: return "SHINE_RESULT_ERROR_INTERNAL";
    }
    return "unknown ShineResult";
}

// A shine call's result: on failure, the function, the code and shine's message.
void check_shine(ShineResult result, const char* function) {
    if (result != SHINE_RESULT_SUCCESS) {
        fail(std::string(function) + " failed: " + shine_result_name(result) + " (" +
             std::to_string(static_cast<int>(result)) + "): " + shine_last_error());
    }
}

// ---------------------------------------------------------------------------------------------
// Validation: the messenger records every warning and error; any of them fails the run.

struct ValidationLog {
    std::mutex mutex;  // shine may call Vulkan from other threads.
    std::vector<std::string> messages;
};

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

// ---------------------------------------------------------------------------------------------
// The host's device: instance, messenger, physical device, device, queue, pool, cache.

const char* const kValidationLayer = "VK_LAYER_KHRONOS_validation";

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

// A Vulkan 1.3 instance with the validation layer and VK_EXT_debug_utils where available, and
// a messenger that records warnings and errors into `log`.
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

// The first Vulkan 1.3 physical device with a queue family that does graphics, compute and
// timestamps (what shine needs of the queue it is lent).
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

// The device with what both the host and shine need: Vulkan 1.3 synchronization2 (shine) and
// dynamicRendering (the host's raster and shine); then its queue, pool and pipeline cache.
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

// shine's handle on the host's device: the host keeps every object alive until it is gone.
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

// ---------------------------------------------------------------------------------------------
// Memory, buffers and images: one allocation per object, which is plenty for an example.

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

// A buffer in host-visible, coherent memory, mapped for its whole life.
struct HostBuffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    void* mapped = nullptr;
};

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

// ---------------------------------------------------------------------------------------------
// The G-buffer, direct-light and GI images (the Rust host's `Targets`).

const VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
const VkFormat kNormalFormat = VK_FORMAT_A2B10G10R10_UNORM_PACK32;  // n * 0.5 + 0.5
const VkFormat kAlbedoFormat = VK_FORMAT_R8G8B8A8_SRGB;             // decoded to linear on reads
const VkFormat kMaterialFormat = VK_FORMAT_R8G8B8A8_UNORM;          // r roughness, g metallic
const VkFormat kRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;     // direct and GI light

struct Targets {
    HostImage depth, normal, albedo, material, direct, gi;
};

Targets create_targets(const HostDevice& host, uint32_t width, uint32_t height) {
    const VkImageUsageFlags sampled = VK_IMAGE_USAGE_SAMPLED_BIT;
    const VkImageUsageFlags color = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | sampled;
    Targets t;
    t.depth = create_image(host, kDepthFormat, width, height,
                           VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | sampled);
    t.normal = create_image(host, kNormalFormat, width, height, color);
    t.albedo = create_image(host, kAlbedoFormat, width, height, color);
    t.material = create_image(host, kMaterialFormat, width, height, color);
    t.direct = create_image(host, kRadianceFormat, width, height,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    // shine blits into it, the host copies it out (and would sample it in a composite).
    t.gi = create_image(host, kRadianceFormat, width, height,
                        VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                            VK_IMAGE_USAGE_SAMPLED_BIT);
    return t;
}

void destroy_targets(const HostDevice& host, Targets& t) {
    for (HostImage* i : {&t.depth, &t.normal, &t.albedo, &t.material, &t.direct, &t.gi}) {
        destroy_image(host, *i);
    }
}

// ---------------------------------------------------------------------------------------------
// The scene as the host draws it: world-space geometry from shine_scene_flatten.

struct HostScene {
    HostBuffer vertices;  // 6 floats per vertex: position, normal.
    HostBuffer indices;   // uint32 triangle list.
    std::vector<ShineDraw> draws;
};

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

// Column-major 4x4 matrices, as in shine.h and GLSL.
using Mat4 = std::array<float, 16>;

// a * b, summed in the order glam's SSE2 Mat4 product sums (column j of the result is
// ((a0 * b0j + a1 * b1j) + a2 * b2j) + a3 * b3j with a_k a's columns, no fused multiply-add),
// so view_proj is bit-identical to the Rust host's `projection * view`.
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

struct Camera {
    Mat4 view;        // world to view
    Mat4 projection;  // view to clip, Vulkan convention (y down, depth 0..1)
};

Camera scene_camera(ShineScene scene, uint32_t width, uint32_t height) {
    Camera c{};
    check_shine(
        shine_scene_camera(scene, 0, 0.0f, width, height, c.view.data(), c.projection.data()),
        "shine_scene_camera");
    return c;
}

// ---------------------------------------------------------------------------------------------
// The G-buffer raster pipeline (the Rust host's `Raster`), with dynamic rendering.

// The shaders' push constants (128 bytes, std430-compatible layout of the GLSL block).
struct DrawConstants {
    Mat4 view_proj;
    std::array<float, 4> base_color_roughness;
    std::array<float, 4> light_position_metallic;
    std::array<float, 4> light_intensity;
    std::array<float, 4> light_direction_cos_outer;
};
static_assert(sizeof(DrawConstants) == 128, "the shaders' push-constant block is 128 bytes");

const VkShaderStageFlags kPushStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

struct Raster {
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkPipeline pipeline = VK_NULL_HANDLE;
};

VkShaderModule load_shader(const HostDevice& host, const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) fail("cannot open " + path);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(file)),
                                  std::istreambuf_iterator<char>());
    if (bytes.empty() || bytes.size() % 4 != 0) fail(path + " is not SPIR-V");
    std::vector<uint32_t> code(bytes.size() / 4);
    std::memcpy(code.data(), bytes.data(), bytes.size());
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = bytes.size();
    info.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    check_vk(vkCreateShaderModule(host.device, &info, nullptr, &module), "vkCreateShaderModule");
    return module;
}

// World-space vertices (position, normal), no culling, depth test LESS_OR_EQUAL with writes,
// four colour targets (normal, albedo, material, direct) without blending.
Raster create_raster(const HostDevice& host, const std::string& shader_dir) {
    Raster r;
    VkPushConstantRange push{kPushStages, 0, sizeof(DrawConstants)};
    VkPipelineLayoutCreateInfo layout{};
    layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    check_vk(vkCreatePipelineLayout(host.device, &layout, nullptr, &r.layout),
             "vkCreatePipelineLayout");

    const VkShaderModule vert = load_shader(host, shader_dir + "/gbuffer.vert.spv");
    const VkShaderModule frag = load_shader(host, shader_dir + "/gbuffer.frag.spv");
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    for (auto& stage : stages) {
        stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stage.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag;

    const VkVertexInputBindingDescription binding{0, 6 * sizeof(float),
                                                  VK_VERTEX_INPUT_RATE_VERTEX};
    const std::array<VkVertexInputAttributeDescription, 2> attributes{{
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},                  // position
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)},  // normal
    }};
    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    vertex_input.vertexBindingDescriptionCount = 1;
    vertex_input.pVertexBindingDescriptions = &binding;
    vertex_input.vertexAttributeDescriptionCount = uint32_t(attributes.size());
    vertex_input.pVertexAttributeDescriptions = attributes.data();

    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;

    VkPipelineViewportStateCreateInfo viewport{};  // Viewport and scissor are dynamic.
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;

    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;

    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

    VkPipelineDepthStencilStateCreateInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;

    std::array<VkPipelineColorBlendAttachmentState, 4> blend{};
    for (auto& attachment : blend) {
        attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                    VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    }
    VkPipelineColorBlendStateCreateInfo blend_state{};
    blend_state.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blend_state.attachmentCount = uint32_t(blend.size());
    blend_state.pAttachments = blend.data();

    const std::array<VkDynamicState, 2> dynamic_states{VK_DYNAMIC_STATE_VIEWPORT,
                                                       VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{};
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = uint32_t(dynamic_states.size());
    dynamic.pDynamicStates = dynamic_states.data();

    // Dynamic rendering: the attachments' formats instead of a render pass.
    const std::array<VkFormat, 4> formats{kNormalFormat, kAlbedoFormat, kMaterialFormat,
                                          kRadianceFormat};
    VkPipelineRenderingCreateInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    rendering.colorAttachmentCount = uint32_t(formats.size());
    rendering.pColorAttachmentFormats = formats.data();
    rendering.depthAttachmentFormat = kDepthFormat;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.pNext = &rendering;
    info.stageCount = uint32_t(stages.size());
    info.pStages = stages.data();
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend_state;
    info.pDynamicState = &dynamic;
    info.layout = r.layout;
    check_vk(vkCreateGraphicsPipelines(host.device, host.cache, 1, &info, nullptr, &r.pipeline),
             "vkCreateGraphicsPipelines");
    vkDestroyShaderModule(host.device, vert, nullptr);
    vkDestroyShaderModule(host.device, frag, nullptr);
    return r;
}

void destroy_raster(const HostDevice& host, Raster& r) {
    vkDestroyPipeline(host.device, r.pipeline, nullptr);
    vkDestroyPipelineLayout(host.device, r.layout, nullptr);
}

// A barrier taking `image` (contents discarded) from any earlier use to its attachment layout.
VkImageMemoryBarrier2 to_attachment(const HostImage& image, VkPipelineStageFlags2 stage,
                                    VkAccessFlags2 access, VkImageLayout layout,
                                    VkImageAspectFlags aspect) {
    VkImageMemoryBarrier2 b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2;
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstStageMask = stage;
    b.dstAccessMask = access;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image.image;
    b.subresourceRange = whole(aspect);
    return b;
}

// Records the G-buffer and direct light of `scene` seen through `view_proj` into `targets`,
// leaving colours in COLOR_ATTACHMENT_OPTIMAL and depth in DEPTH_ATTACHMENT_OPTIMAL.
void record_raster(VkCommandBuffer cb, const Raster& raster, const Targets& targets,
                   const HostScene& scene, const Mat4& view_proj) {
    const std::array<const HostImage*, 4> colors{&targets.normal, &targets.albedo,
                                                 &targets.material, &targets.direct};
    std::array<VkImageMemoryBarrier2, 5> barriers{};
    std::array<VkRenderingAttachmentInfo, 4> attachments{};
    for (size_t i = 0; i < colors.size(); ++i) {
        barriers[i] = to_attachment(*colors[i], VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                    VK_IMAGE_ASPECT_COLOR_BIT);
        attachments[i].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        attachments[i].imageView = colors[i]->view;
        attachments[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // cleared to 0
        attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    }
    barriers[4] = to_attachment(targets.depth,
                                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                                    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                VK_IMAGE_ASPECT_DEPTH_BIT);
    VkRenderingAttachmentInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    depth.imageView = targets.depth.view;
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = VkClearDepthStencilValue{1.0f, 0};  // standard Z: far is 1

    VkDependencyInfo dependency{};
    dependency.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
    dependency.imageMemoryBarrierCount = uint32_t(barriers.size());
    dependency.pImageMemoryBarriers = barriers.data();
    vkCmdPipelineBarrier2(cb, &dependency);

    const VkRect2D area{{0, 0}, {targets.depth.width, targets.depth.height}};
    VkRenderingInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    rendering.renderArea = area;
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = uint32_t(attachments.size());
    rendering.pColorAttachments = attachments.data();
    rendering.pDepthAttachment = &depth;
    vkCmdBeginRendering(cb, &rendering);

    // Not flipped: the projection is already Vulkan's (y down).
    const VkViewport viewport{0.0f, 0.0f, float(area.extent.width), float(area.extent.height),
                              0.0f, 1.0f};
    vkCmdSetViewport(cb, 0, 1, &viewport);
    vkCmdSetScissor(cb, 0, 1, &area);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, raster.pipeline);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &scene.vertices.buffer, &offset);
    vkCmdBindIndexBuffer(cb, scene.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    for (const ShineDraw& draw : scene.draws) {
        // The C API does not expose the scene's lights, so the host draws without its direct
        // light, with the Rust host's no-light values (only the direct output depends on
        // them, and shine does not read it).
        DrawConstants c{};
        c.view_proj = view_proj;
        c.base_color_roughness = {draw.base_color[0], draw.base_color[1], draw.base_color[2],
                                  draw.roughness};
        c.light_position_metallic = {0.0f, 0.0f, 0.0f, draw.metallic};
        c.light_intensity = {0.0f, 0.0f, 0.0f, 0.0f};
        c.light_direction_cos_outer = {0.0f, -1.0f, 0.0f, -1.0f};  // pointing down, no cone
        vkCmdPushConstants(cb, raster.layout, kPushStages, 0, sizeof(c), &c);
        vkCmdDrawIndexed(cb, draw.index_count, 1, draw.first_index, 0, 0);
    }
    vkCmdEndRendering(cb);
}

// ---------------------------------------------------------------------------------------------
// What the host hands shine each frame (the Rust bench's `record_gbuffer`).

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

// Where shine leaves the GI image: ready for the host's copy to the CPU.
ShineImageState copy_source() {
    return state(VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
}

// No earlier use: contents discarded.
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

// Frame `frame`'s dispatch: a still camera, UNORM normals, glTF-style material channels, the
// indirect light into `diffuse` (which must outlive the dispatch call).
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

// ---------------------------------------------------------------------------------------------
// Submission: one command buffer and one fence, reused by every submission.

struct Submitter {
    VkCommandBuffer cb = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
};

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

// Resets the command buffer (whatever it held) and begins it for one submission.
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

// ---------------------------------------------------------------------------------------------
// The GI context's frames.

// A dispatch whose view matrix holds a NaN must be refused with INVALID_ARGUMENT and a
// message; its command buffer is reset, never submitted.
void check_bad_input_is_refused(ShineContext context, const Submitter& s,
                                ShineDispatchDesc desc) {
    desc.camera.view[5] = std::numeric_limits<float>::quiet_NaN();
    begin(s);
    const ShineResult result = shine_context_dispatch(context, s.cb, &desc);
    const std::string message = shine_last_error();
    check_vk(vkResetCommandBuffer(s.cb, 0), "vkResetCommandBuffer");
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT || message.empty()) {
        fail(std::string("a NaN camera was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "NaN camera refused: " << shine_result_name(result) << ": " << message << "\n";
}

// One frame: the host's G-buffer, then shine's GI into the gi image, submitted and waited for.
void render_frame(const HostDevice& host, const Submitter& s, ShineContext context,
                  const Raster& raster, const Targets& targets, const HostScene& scene,
                  const ShineDispatchDesc& desc, const Mat4& view_proj) {
    begin(s);
    record_raster(s.cb, raster, targets, scene, view_proj);
    check_shine(shine_context_dispatch(context, s.cb, &desc), "shine_context_dispatch");
    submit_and_wait(host, s);
}

// ---------------------------------------------------------------------------------------------
// Readback and output.

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

// The RGBA16F `image`, left by shine in copy_source(), as RGBA float texels, row by row.
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

// Writes `rgba` as little-endian float32 to `path`, through `path`.partial and a rename so no
// reader ever sees half a file.
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

// The mean over pixels of (r + g + b) / 3.
double mean_rgb(const std::vector<float>& rgba) {
    double sum = 0.0;
    for (size_t i = 0; i < rgba.size(); i += 4) {
        sum += (double(rgba[i]) + rgba[i + 1] + rgba[i + 2]) / 3.0;
    }
    return rgba.empty() ? 0.0 : sum / double(rgba.size() / 4);
}

// ---------------------------------------------------------------------------------------------
// Command line.

struct Options {
    std::string scene;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t frames = 0;
    std::string output;
    std::string shader_dir;
};

uint32_t positive(const char* text, const char* what) {
    char* end = nullptr;
    errno = 0;
    const unsigned long value = std::strtoul(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || value == 0 || value > 1u << 16) {
        fail(std::string(what) + " must be a whole number from 1 to 65536, not \"" + text + "\"");
    }
    return static_cast<uint32_t>(value);
}

Options parse(int argc, char** argv) {
    if (argc != 7) {
        fail("usage: capi_host <scene> <width> <height> <frames> <out.raw> <shader_dir>\n"
             "  e.g. capi_host builtin:cornell-box 64 64 3 gi.raw build");
    }
    Options o;
    o.scene = argv[1];
    o.width = positive(argv[2], "width");
    o.height = positive(argv[3], "height");
    o.frames = positive(argv[4], "frames");
    o.output = argv[5];
    o.shader_dir = argv[6];
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    ValidationLog validation;

    // The host's own Vulkan objects, then shine on its device.
    HostDevice host;
    create_instance(host, validation);
    pick_physical_device(host);
    create_device(host);
    ShineDevice shine_device = lend_to_shine(host);

    ShineScene scene = nullptr;
    check_shine(shine_scene_load(options.scene.c_str(), &scene), "shine_scene_load");
    HostScene host_scene = upload_scene(host, scene);
    const Camera camera = scene_camera(scene, options.width, options.height);
    const Mat4 view_proj = multiply(camera.projection, camera.view);
    Targets targets = create_targets(host, options.width, options.height);
    Raster raster = create_raster(host, options.shader_dir);
    Submitter submitter = create_submitter(host);

    // The GI context, with the settings of the Rust tests' `exact_desc` (no noise from the
    // frame index or the G-buffer's last bits).
    const char* settings[] = {"hvl.shadow_rays=0", "hvl.near_range=0"};
    ShineContextDesc context_desc{};
    context_desc.version = SHINE_CONTEXT_DESC_VERSION;
    context_desc.width = options.width;
    context_desc.height = options.height;
    context_desc.frames_in_flight = 2;
    context_desc.technique = "hvl";
    context_desc.settings = settings;
    context_desc.settings_count = 2;
    ShineContext context = nullptr;
    check_shine(shine_context_create(shine_device, &context_desc, &context),
                "shine_context_create");
    check_shine(shine_context_set_scene(context, scene, 0.0f), "shine_context_set_scene");
    check_shine(shine_context_warm_up(context, nullptr), "shine_context_warm_up");

    const ShineImage diffuse = lend(targets.gi, undefined_state(), copy_source());
    check_bad_input_is_refused(context, submitter, dispatch_desc(0, camera, targets, &diffuse));
    for (uint32_t k = 0; k < options.frames; ++k) {
        render_frame(host, submitter, context, raster, targets, host_scene,
                     dispatch_desc(k, camera, targets, &diffuse), view_proj);
        std::cout << "frame " << k + 1 << "/" << options.frames << "\n";
    }
    const std::vector<float> gi = read_rgba16f(host, submitter, targets.gi);
    write_raw(options.output, gi);
    std::cout << "wrote " << options.output << " (" << options.width << "x" << options.height
              << " RGBA float32)\n";
    std::cout << "mean radiance: indirect " << mean_rgb(gi) << "\n";

    // Teardown: the GPU is idle, shine's objects go first, then the host's, then its device.
    check_vk(vkDeviceWaitIdle(host.device), "vkDeviceWaitIdle");
    check_shine(shine_context_destroy(context), "shine_context_destroy");
    check_shine(shine_scene_destroy(scene), "shine_scene_destroy");
    check_shine(shine_device_destroy(shine_device), "shine_device_destroy");
    destroy_submitter(host, submitter);
    destroy_raster(host, raster);
    destroy_targets(host, targets);
    destroy_scene(host, host_scene);
    destroy_host_device(host);

    if (!validation.messages.empty()) {
        std::cerr << "capi_host: " << validation.messages.size() << " validation message(s):\n";
        for (const std::string& message : validation.messages) std::cerr << "  " << message << "\n";
        return 1;
    }
    if (!(mean_rgb(gi) > 0.0)) fail("the GI image is black");
    std::cout << "validation: clean\n";
    return 0;
}
