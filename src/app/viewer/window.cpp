#include "app/viewer/window.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "core/error.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

std::vector<std::string> openWindow(ViewerWindow& w, uint32_t width, uint32_t height,
                                    const std::string& title) {
    if (!glfwInit()) {
        const char* why = nullptr;
        glfwGetError(&why);
        throw DeviceError(format("shadel view: cannot open a window (%s); headless: run it under "
                                 "xvfb-run",
                                 why ? why : "no display"));
    }
    if (!glfwVulkanSupported()) throw DeviceError("shadel view: GLFW finds no Vulkan loader");
    glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE); // the renderer's targets have the window's size
    w.window = glfwCreateWindow(int(width), int(height), title.c_str(), nullptr, nullptr);
    if (!w.window) throw DeviceError("shadel view: cannot create the window");
    uint32_t count = 0;
    const char** names = glfwGetRequiredInstanceExtensions(&count);
    std::vector<std::string> extensions;
    for (uint32_t i = 0; i < count; ++i) extensions.push_back(names[i]);
    return extensions;
}

void createSwapchain(ViewerWindow& w, Gpu& gpu) {
    Device& d = gpu.device;
    if (glfwCreateWindowSurface(d.instance, w.window, nullptr, &w.surface) != VK_SUCCESS)
        throw DeviceError("shadel view: cannot create a Vulkan surface for the window");
    VkBool32 present = VK_FALSE;
    vkGetPhysicalDeviceSurfaceSupportKHR(d.physical, d.queueFamily, w.surface, &present);
    if (!present)
        throw DeviceError(
            format("shadel view: %s's queue cannot present to this window", d.name.c_str()));
    VkSurfaceCapabilitiesKHR caps{};
    vkGetPhysicalDeviceSurfaceCapabilitiesKHR(d.physical, w.surface, &caps);
    uint32_t n = 0;
    vkGetPhysicalDeviceSurfaceFormatsKHR(d.physical, w.surface, &n, nullptr);
    std::vector<VkSurfaceFormatKHR> formats(n);
    vkGetPhysicalDeviceSurfaceFormatsKHR(d.physical, w.surface, &n, formats.data());
    // UNORM: the renderer's bytes are already sRGB-encoded and go through unchanged.
    VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
    for (VkSurfaceFormatKHR f : formats)
        if (f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) {
            chosen = f;
            break;
        }
    if (chosen.format == VK_FORMAT_UNDEFINED)
        throw DeviceError("shadel view: the window offers no 8-bit UNORM swapchain format");
    w.format = chosen.format;
    w.bgra = chosen.format == VK_FORMAT_B8G8R8A8_UNORM;
    int fbw = 0, fbh = 0;
    glfwGetFramebufferSize(w.window, &fbw, &fbh);
    w.extent = caps.currentExtent.width != 0xFFFFFFFFu ? caps.currentExtent
                                                       : VkExtent2D{uint32_t(fbw), uint32_t(fbh)};
    VkImageUsageFlags usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                              VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    if ((caps.supportedUsageFlags & usage) != usage)
        throw DeviceError("shadel view: swapchain images cannot be copied to and from");
    VkSwapchainCreateInfoKHR ci{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
    ci.surface = w.surface;
    ci.minImageCount = std::max(caps.minImageCount, 2u);
    if (caps.maxImageCount) ci.minImageCount = std::min(ci.minImageCount, caps.maxImageCount);
    ci.imageFormat = chosen.format;
    ci.imageColorSpace = chosen.colorSpace;
    ci.imageExtent = w.extent;
    ci.imageArrayLayers = 1;
    ci.imageUsage = usage;
    ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
    ci.preTransform = caps.currentTransform;
    ci.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
    ci.presentMode = VK_PRESENT_MODE_FIFO_KHR; // always supported
    ci.clipped = VK_TRUE;
    VK_CHECK(vkCreateSwapchainKHR(d.device, &ci, nullptr, &w.swapchain));
    vkGetSwapchainImagesKHR(d.device, w.swapchain, &n, nullptr);
    w.images.resize(n);
    vkGetSwapchainImagesKHR(d.device, w.swapchain, &n, w.images.data());
    for (uint32_t i = 0; i < n; ++i) {
        VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        vi.image = w.images[i];
        vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
        vi.format = w.format;
        vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        VkImageView view;
        VK_CHECK(vkCreateImageView(d.device, &vi, nullptr, &view));
        w.views.push_back(view);
        setName(d, w.images[i], VK_OBJECT_TYPE_IMAGE, format("swapchain[%u]", i));
    }
    VkSemaphoreCreateInfo si{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(d.device, &si, nullptr, &w.acquired));
    w.presentReady.resize(n);
    for (VkSemaphore& s : w.presentReady) VK_CHECK(vkCreateSemaphore(d.device, &si, nullptr, &s));
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(d.device, &fi, nullptr, &w.done));
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pi.queueFamilyIndex = d.queueFamily;
    VK_CHECK(vkCreateCommandPool(d.device, &pi, nullptr, &w.pool));
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = w.pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(d.device, &ai, &w.cmd));
    setName(d, w.cmd, VK_OBJECT_TYPE_COMMAND_BUFFER, "viewer.present");
}

void destroyWindow(ViewerWindow& w, Gpu* gpu) {
    if (gpu && gpu->device.device) {
        VkDevice dev = gpu->device.device;
        vkDeviceWaitIdle(dev);
        if (w.pool) vkDestroyCommandPool(dev, w.pool, nullptr);
        if (w.done) vkDestroyFence(dev, w.done, nullptr);
        if (w.acquired) vkDestroySemaphore(dev, w.acquired, nullptr);
        for (VkSemaphore s : w.presentReady) vkDestroySemaphore(dev, s, nullptr);
        for (VkImageView v : w.views) vkDestroyImageView(dev, v, nullptr);
        if (w.swapchain) vkDestroySwapchainKHR(dev, w.swapchain, nullptr);
        if (w.surface) vkDestroySurfaceKHR(gpu->device.instance, w.surface, nullptr);
    }
    if (w.window) glfwDestroyWindow(w.window);
    w = ViewerWindow{};
    glfwTerminate();
}

} // namespace shadel
