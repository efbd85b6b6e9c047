#pragma once
// The viewer's Dear ImGui overlay (GLFW + Vulkan backends): a render pass that loads the
// swapchain image the frame was copied into and draws the panel over it.
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <vector>

#include "app/viewer/window.h"
#include "rhi/frame.h"

namespace shadel {

struct ViewerUi {
    bool enabled = false;
    VkRenderPass renderPass = VK_NULL_HANDLE;
    std::vector<VkFramebuffer> framebuffers;
    VkDescriptorPool descriptors = VK_NULL_HANDLE;
};

// What the panel shows and what the user changed this frame.
struct ViewerPanel {
    // In: the last frame.
    std::vector<PassTiming> passes;
    std::deque<float> frameMsHistory;
    std::vector<std::string> statLines;
    std::string cameraArguments; // "--from X,Y,Z --look-at X,Y,Z" (app/viewer/camera_control.h)
    // In/out: the choices.
    int mode = 0;      // 0 forward, 1 decoupled
    int visualize = 0; // index into kVisualizeNames
    bool orbit = false;
    bool materialRate = true; // decoupled: --material-rate
    // Out: events.
    bool modeChanged = false, visualizeChanged = false, cameraModeChanged = false;
    bool materialRateChanged = false;
    bool screenshotRequested = false;
};

extern const char* const
    kVisualizeNames[]; // none, marking, mips, chunks, sheet, layer:material, reuse
extern const int kVisualizeCount;

void initUi(ViewerUi& ui, ViewerWindow& w, Gpu& gpu);
void destroyUi(ViewerUi& ui, Gpu& gpu);
bool uiWantsMouse(const ViewerUi& ui);
bool uiWantsKeyboard(const ViewerUi& ui);
// Builds this frame's panel (ImGui NewFrame .. Render); `sections` adds more to the window
// (the scene editor) before the capture button.
void buildUi(ViewerUi& ui, ViewerPanel& panel, const std::function<void()>& sections = {});
// Records the overlay into the swapchain image (COLOR_ATTACHMENT_OPTIMAL in, PRESENT_SRC out).
void recordUi(ViewerUi& ui, VkCommandBuffer cmd, uint32_t image, VkExtent2D extent);

} // namespace shadel
