#pragma once
// The viewer's window: GLFW (no client API), a Vulkan surface and a FIFO swapchain whose images
// take the renderer's finished RGBA8 frame by a buffer copy (the frame is rendered headless as
// always; the window only shows it), then the UI on top.
#include <cstdint>
#include <string>
#include <vector>

#include "rhi/vk.h"

struct GLFWwindow;

namespace shadel {

struct Gpu;

struct ViewerWindow {
    GLFWwindow* window = nullptr;
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    VkSwapchainKHR swapchain = VK_NULL_HANDLE;
    VkFormat format = VK_FORMAT_UNDEFINED;
    bool bgra = false; // swapchain bytes are B, G, R, A
    VkExtent2D extent{};
    std::vector<VkImage> images;
    std::vector<VkImageView> views;
    VkSemaphore acquired = VK_NULL_HANDLE;
    std::vector<VkSemaphore> presentReady; // one per swapchain image
    VkFence done = VK_NULL_HANDLE;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
};

// Opens the window (throws DeviceError when there is no display). Call before createGpu: it
// returns the instance extensions the surface needs.
std::vector<std::string> openWindow(ViewerWindow& w, uint32_t width, uint32_t height,
                                    const std::string& title);
// After createGpu: surface, swapchain, sync objects. Throws DeviceError when the device's queue
// cannot present to the window.
void createSwapchain(ViewerWindow& w, Gpu& gpu);
void destroyWindow(ViewerWindow& w, Gpu* gpu);

} // namespace shadel
