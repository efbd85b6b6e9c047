#pragma once
// Vulkan include + the check macro used across the backend.
#include <vulkan/vulkan.h>

#include "core/error.h"

namespace shadel {

const char* vkResultName(VkResult r);
[[noreturn]] void throwVkError(VkResult r, const char* call, const char* file, int line);

} // namespace shadel

// Vulkan failures other than the ones a caller handles explicitly are unrecoverable here:
// they become a DeviceError with the call and the result name.
#define VK_CHECK(call)                                                                             \
    do {                                                                                           \
        VkResult vkCheckResult_ = (call);                                                          \
        if (vkCheckResult_ != VK_SUCCESS) [[unlikely]]                                             \
            ::shadel::throwVkError(vkCheckResult_, #call, __FILE__, __LINE__);                     \
    } while (0)
