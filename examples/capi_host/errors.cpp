// Errors: reporting a failed Vulkan or shine call and exiting.

#include "errors.hpp"

#include <cstdlib>
#include <iostream>

namespace capi_host {

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

void check_shine(ShineResult result, const char* function) {
    if (result != SHINE_RESULT_SUCCESS) {
        fail(std::string(function) + " failed: " + shine_result_name(result) + " (" +
             std::to_string(static_cast<int>(result)) + "): " + shine_last_error());
    }
}

}  // namespace capi_host
