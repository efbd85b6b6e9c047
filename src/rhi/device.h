#pragma once
// The Vulkan device: instance, physical device choice, queue, required-feature checks,
// validation and debug-utils naming.
#include <atomic>
#include <string>
#include <vector>

#include "rhi/vk.h"

namespace shadel {

struct DeviceDesc {
    std::string selection = "auto"; // auto | cpu | gpu | INDEX
    bool validation = false;        // Khronos validation layer; errors are counted
    bool printValidation = true;
    // A window (shadel view): the surface's instance extensions and VK_KHR_swapchain.
    std::vector<std::string> instanceExtensions;
    bool swapchain = false;
};

struct DeviceFeatures { // optional features, used when present
    bool meshShader = false;
    bool rayQuery = false;
    bool computeDerivatives = false;
    // sparseBinding + sparseResidencyImage2D, on a queue with sparse binding (--streaming sparse)
    bool sparseResidency = false;
    // BC1-7 sampling (texture streaming's block-compressed files, --texture-compression bc)
    bool textureCompressionBC = false;
};

struct Device {
    VkInstance instance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
    VkPhysicalDevice physical = VK_NULL_HANDLE;
    VkDevice device = VK_NULL_HANDLE;
    VkQueue queue = VK_NULL_HANDLE; // one graphics+compute queue: headless rendering needs no more
    uint32_t queueFamily = 0;
    VkPhysicalDeviceProperties properties{};
    VkPhysicalDeviceMemoryProperties memory{};
    DeviceFeatures optional;
    std::string name;
    std::string driver;
    bool isCpu = false; // lavapipe or another software rasterizer
    bool validation = false;
    float timestampPeriodNs = 1.0f;
    std::atomic<uint32_t> validationErrors{0};
    std::atomic<uint32_t> validationWarnings{0};
    bool printValidation = true;

    // Debug-utils entry points (null when the extension is absent).
    PFN_vkSetDebugUtilsObjectNameEXT setObjectName = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT cmdBeginLabel = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT cmdEndLabel = nullptr;
};

// Creates the instance and device. Throws DeviceError with one line naming what is missing.
void createDevice(Device& device, const DeviceDesc& desc);
void destroyDevice(Device& device);

// Prints device, driver, features and limits (`shadel info`).
std::string describeDevice(const Device& device);
// Lists the physical devices the loader sees (for `shadel info` and --device errors).
std::string listPhysicalDevices();

template <typename T>
void setName(const Device& device, T handle, VkObjectType type, const std::string& name) {
    if (!device.setObjectName || handle == VK_NULL_HANDLE) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = uint64_t(handle);
    info.pObjectName = name.c_str();
    device.setObjectName(device.device, &info);
}

} // namespace shadel
