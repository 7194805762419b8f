// Errors: every failure is fatal for this example; it says what failed and exits 1.
// Every module checks its Vulkan and shine calls through these.

#pragma once

#include <vulkan/vulkan.h>

#include "shine.h"

#include <string>

namespace capi_host {

[[noreturn]] void fail(const std::string& what);

void check_vk(VkResult result, const char* call);

const char* shine_result_name(ShineResult result);

// A shine call's result: on failure, the function, the code and shine's message.
void check_shine(ShineResult result, const char* function);

}  // namespace capi_host
