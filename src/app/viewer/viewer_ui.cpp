#include "app/viewer/viewer_ui.h"

#include <algorithm>

#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#include <imgui.h>

#include "core/error.h"
#include "core/log.h"
#include "rhi/gpu.h"

namespace shadel {

const char* const kVisualizeNames[] = {"none",  "marking",        "mips", "chunks",
                                       "sheet", "layer:material", "reuse"};
const int kVisualizeCount = 7;

static void checkVk(VkResult r) {
    if (r != VK_SUCCESS) SHADEL_ERROR("ImGui Vulkan backend: VkResult %d", int(r));
}

void initUi(ViewerUi& ui, ViewerWindow& w, Gpu& gpu) {
    VkDevice dev = gpu.device.device;
    // Loads what the frame copy left (TRANSFER_DST -> COLOR_ATTACHMENT by the caller) and hands
    // the image to presentation.
    VkAttachmentDescription colour{};
    colour.format = w.format;
    colour.samples = VK_SAMPLE_COUNT_1_BIT;
    colour.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    colour.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    colour.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    colour.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    colour.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    colour.finalLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.colorAttachmentCount = 1;
    sub.pColorAttachments = &ref;
    VkSubpassDependency dep{};
    dep.srcSubpass = VK_SUBPASS_EXTERNAL;
    dep.dstSubpass = 0;
    dep.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
    dep.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
    VkRenderPassCreateInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    rp.attachmentCount = 1;
    rp.pAttachments = &colour;
    rp.subpassCount = 1;
    rp.pSubpasses = &sub;
    rp.dependencyCount = 1;
    rp.pDependencies = &dep;
    VK_CHECK(vkCreateRenderPass(dev, &rp, nullptr, &ui.renderPass));
    setName(gpu.device, ui.renderPass, VK_OBJECT_TYPE_RENDER_PASS, "viewer.ui");
    for (VkImageView view : w.views) {
        VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        fb.renderPass = ui.renderPass;
        fb.attachmentCount = 1;
        fb.pAttachments = &view;
        fb.width = w.extent.width;
        fb.height = w.extent.height;
        fb.layers = 1;
        VkFramebuffer f;
        VK_CHECK(vkCreateFramebuffer(dev, &fb, nullptr, &f));
        ui.framebuffers.push_back(f);
    }
    VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 16}};
    VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dp.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
    dp.maxSets = 16;
    dp.poolSizeCount = 1;
    dp.pPoolSizes = sizes;
    VK_CHECK(vkCreateDescriptorPool(dev, &dp, nullptr, &ui.descriptors));

    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr; // no imgui.ini next to the user's files
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForVulkan(w.window, true);
    ImGui_ImplVulkan_InitInfo info{};
    info.Instance = gpu.device.instance;
    info.PhysicalDevice = gpu.device.physical;
    info.Device = dev;
    info.QueueFamily = gpu.device.queueFamily;
    info.Queue = gpu.device.queue;
    info.DescriptorPool = ui.descriptors;
    info.MinImageCount = 2;
    info.ImageCount = uint32_t(std::max<size_t>(w.images.size(), 2));
    info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
    info.CheckVkResultFn = checkVk;
    if (!ImGui_ImplVulkan_Init(&info, ui.renderPass))
        throw DeviceError("shadel view: the ImGui Vulkan backend failed to start");
    immediateSubmit(gpu, [](VkCommandBuffer cmd) { ImGui_ImplVulkan_CreateFontsTexture(cmd); });
    ImGui_ImplVulkan_DestroyFontUploadObjects();
    ui.enabled = true;
}

void destroyUi(ViewerUi& ui, Gpu& gpu) {
    if (!ui.renderPass) return;
    VkDevice dev = gpu.device.device;
    vkDeviceWaitIdle(dev);
    if (ui.enabled) {
        ImGui_ImplVulkan_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    for (VkFramebuffer f : ui.framebuffers) vkDestroyFramebuffer(dev, f, nullptr);
    vkDestroyDescriptorPool(dev, ui.descriptors, nullptr);
    vkDestroyRenderPass(dev, ui.renderPass, nullptr);
    ui = ViewerUi{};
}

bool uiWantsMouse(const ViewerUi& ui) {
    return ui.enabled && ImGui::GetIO().WantCaptureMouse;
}

bool uiWantsKeyboard(const ViewerUi& ui) {
    return ui.enabled && ImGui::GetIO().WantCaptureKeyboard;
}

void buildUi(ViewerUi& ui, ViewerPanel& p, const std::function<void()>& sections) {
    (void)ui;
    p.modeChanged = p.visualizeChanged = p.cameraModeChanged = p.screenshotRequested = false;
    p.materialRateChanged = false;
    ImGui_ImplVulkan_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowBgAlpha(0.8f);
    ImGui::Begin("shadel");
    const char* modes[] = {"forward", "decoupled"};
    p.modeChanged = ImGui::Combo("mode", &p.mode, modes, 2);
    if (p.mode == 1) {
        p.visualizeChanged =
            ImGui::Combo("debug view", &p.visualize, kVisualizeNames, kVisualizeCount);
        // Plain rough materials shaded up to a MIP coarser (render/shadel/material_rate.h).
        p.materialRateChanged = ImGui::Checkbox("material shading rate", &p.materialRate);
    }
    p.cameraModeChanged = ImGui::Checkbox("orbit camera (Tab)", &p.orbit);
    ImGui::TextUnformatted(p.orbit ? "left drag: turn, wheel: zoom"
                                   : "WASD/QE: move, right drag: look, shift: fast");
    if (!p.frameMsHistory.empty()) {
        std::vector<float> history(p.frameMsHistory.begin(), p.frameMsHistory.end());
        float worst = *std::max_element(history.begin(), history.end());
        ImGui::PlotLines("frame ms", history.data(), int(history.size()), 0, nullptr, 0.0f,
                         worst * 1.1f, ImVec2(0, 50));
    }
    if (!p.passes.empty()) {
        std::vector<float> ms;
        float worst = 0.0f;
        for (const PassTiming& t : p.passes) {
            ms.push_back(float(t.gpuMs));
            worst = std::max(worst, float(t.gpuMs));
        }
        ImGui::PlotHistogram("passes (gpu ms)", ms.data(), int(ms.size()), 0, nullptr, 0.0f,
                             worst * 1.1f, ImVec2(0, 60));
        if (ImGui::BeginTable("passes", 2)) {
            for (const PassTiming& t : p.passes) {
                ImGui::TableNextRow();
                ImGui::TableNextColumn();
                ImGui::TextUnformatted(t.name.c_str());
                ImGui::TableNextColumn();
                ImGui::Text("%8.2f ms", t.gpuMs);
            }
            ImGui::EndTable();
        }
    }
    for (const std::string& line : p.statLines) ImGui::TextUnformatted(line.c_str());
    if (!p.cameraArguments.empty()) {
        ImGui::TextWrapped("camera: %s", p.cameraArguments.c_str());
        if (ImGui::Button("copy camera as render arguments"))
            ImGui::SetClipboardText(p.cameraArguments.c_str());
        ImGui::TextUnformatted("keys: F frame, R reset, Tab orbit/fly, [ ] speed, Esc quit");
    }
    if (sections) sections();
    p.screenshotRequested = ImGui::Button("capture screenshot");
    ImGui::End();
    ImGui::Render();
}

void recordUi(ViewerUi& ui, VkCommandBuffer cmd, uint32_t image, VkExtent2D extent) {
    VkRenderPassBeginInfo bi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    bi.renderPass = ui.renderPass;
    bi.framebuffer = ui.framebuffers[image];
    bi.renderArea.extent = extent;
    vkCmdBeginRenderPass(cmd, &bi, VK_SUBPASS_CONTENTS_INLINE);
    ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), cmd);
    vkCmdEndRenderPass(cmd);
}

} // namespace shadel
