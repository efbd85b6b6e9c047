#include "app/viewer/viewer.h"

#include <chrono>
#include <cstring>
#include <filesystem>

#include <GLFW/glfw3.h>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "app/output_files.h"
#include "app/viewer/camera_control.h"
#include "app/viewer/scene_editor.h"
#include "app/viewer/viewer_input.h"
#include "app/viewer/viewer_ui.h"
#include "app/viewer/window.h"
#include "bake/bake.h"
#include "core/error.h"
#include "core/log.h"
#include "render/renderer.h"
#include "render/shadel/decoupled.h"
#include "render/view_density.h"
#include "rhi/gpu.h"
#include "rhi/pipeline_cache.h"
#include "rhi/shader_reload.h"
#include "scene/load.h"

namespace shadel {

namespace {

// The scene as `shadel render` prepares it for a static camera (view-driven density, large
// meshes split, baked), so both modes can be switched to and the first frame matches a render.
struct ViewerScene {
    Scene scene;
    Camera camera;
    Aabb bounds;
    GpuScene gpu;
};

void prepareScene(Gpu& gpu, const ViewOptions& o, ViewerScene& v) {
    v.scene = loadScene(
        o.scene, {.allowExternalFiles = o.allowExternalFiles, .addDefaultSun = o.addDefaultSun});
    v.camera = findCamera(v.scene, o.camera);
    v.bounds = v.scene.worldBounds();
    RunViews views = runViews(v.camera, CameraPath::Static, 1, v.bounds, o.width, o.height);
    ViewDensity density = viewDrivenDensity(v.scene, views, {});
    v.scene = std::move(density.scene);
    BakeSettings bs;
    bs.cacheLimitBytes = o.cacheLimitBytes;
    std::vector<BakedMesh> baked =
        bakeScene(v.scene, bs, usableCacheFolder(o.cacheDir), nullptr, density.meshDensity);
    uploadScene(gpu, v.scene, v.gpu, &baked);
}

RenderSettings settingsFor(const ViewOptions& o, const ViewerPanel& p, const Gpu& gpu) {
    RenderSettings s = o; // the command line's, then the panel's choices
    s.mode = p.mode == 1 ? RenderMode::Decoupled : RenderMode::Forward;
    s.visualize = p.mode == 1 ? parseVisualize(kVisualizeNames[p.visualize]) : Visualize::None;
    s.timing = defaultTimingMode(gpu);
    s.recordingThreads = o.threads ? o.threads : defaultRecordingThreads();
    s.materialRate = p.materialRate;
    s.aa = p.taa ? AntiAliasing::Taa : AntiAliasing::None;
    return s;
}

std::vector<std::string> statLines(const Renderer& r, const FrameResult& f) {
    std::vector<std::string> lines;
    lines.push_back(format("frame %.1f ms, cpu %.1f ms", f.frameMs, f.cpuFrameMs));
    lines.push_back(format("%llu px covered of %ux%u", (unsigned long long)f.pixelsCovered,
                           r.settings.width, r.settings.height));
    if (r.decoupled) {
        nlohmann::json s = nlohmann::json::object();
        s["pixels_covered"] = f.pixelsCovered;
        decoupledStats(r, s);
        for (const char* key :
             {"chunks_allocated", "chunks_capacity", "shadels_per_pixel", "shading_bias",
              "objects_rate_biased", "reconstruction_misses", "reuse_fraction"})
            if (s.contains(key)) lines.push_back(format("%s: %s", key, s[key].dump().c_str()));
    }
    return lines;
}

// The renderer's RGBA8 frame into the swapchain image's byte order.
void copyPixels(const std::vector<uint8_t>& rgba, bool bgra, uint8_t* out) {
    if (!bgra) {
        std::memcpy(out, rgba.data(), rgba.size());
        return;
    }
    for (size_t i = 0; i < rgba.size(); i += 4) {
        out[i] = rgba[i + 2];
        out[i + 1] = rgba[i + 1];
        out[i + 2] = rgba[i];
        out[i + 3] = 255;
    }
}

// The viewer's keys that act once per press: Esc quits (returns true), Tab switches orbit and
// fly, F frames the scene, R returns to the scene's camera.
bool applyViewerKeys(const ViewerInput& input, GLFWwindow* window, CameraControl& camera,
                     ViewerPanel& panel, const ViewerScene& scene) {
    if (input.uiWantsKeyboard) return false;
    for (int key : input.pressed) {
        if (key == GLFW_KEY_ESCAPE) {
            SHADEL_INFO("shadel view: Esc: quit");
            glfwSetWindowShouldClose(window, GLFW_TRUE);
            return true;
        }
        if (key == GLFW_KEY_TAB) panel.orbit = !panel.orbit;
        if (key == GLFW_KEY_F) {
            frameScene(camera, scene.bounds);
            SHADEL_INFO("shadel view: F: the scene framed, %s", cameraArguments(camera).c_str());
        }
        if (key == GLFW_KEY_R) {
            bool orbit = camera.orbit;
            camera = makeCameraControl(scene.camera, scene.bounds);
            camera.orbit = orbit;
            SHADEL_INFO("shadel view: R: the scene's camera, %s", cameraArguments(camera).c_str());
        }
    }
    return false;
}

// Shows the renderer's frame in the window: copied into the swapchain image, the panel drawn
// over it, read back first when `screenshot` (written to --screenshot); returns once presented.
void presentFrame(Gpu& gpu, ViewerWindow& window, ViewerUi& ui, const ViewOptions& o,
                  BufferHandle upload, BufferHandle readback, const FrameResult& result,
                  bool screenshot) {
    VkDevice dev = gpu.device.device;
    uint32_t image = 0;
    VkResult acquired = vkAcquireNextImageKHR(dev, window.swapchain, UINT64_MAX, window.acquired,
                                              VK_NULL_HANDLE, &image);
    if (acquired != VK_SUCCESS && acquired != VK_SUBOPTIMAL_KHR)
        throw DeviceError(
            format("shadel view: cannot acquire a swapchain image (%d)", int(acquired)));
    copyPixels(result.rgba, window.bgra, static_cast<uint8_t*>(mapped(gpu, upload)));
    VkCommandBuffer cmd = window.cmd;
    VK_CHECK(vkResetCommandBuffer(cmd, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    beginLabel(gpu, cmd, "present");
    VkImage target = window.images[image];
    imageBarrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, 0, VK_PIPELINE_STAGE_2_COPY_BIT,
                 VK_ACCESS_2_TRANSFER_WRITE_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {o.width, o.height, 1};
    vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, upload), target, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                           1, &copy);
    VkImageLayout layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_COPY_BIT;
    VkAccessFlags2 access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    if (ui.enabled) {
        imageBarrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, layout,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, stage, access,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        recordUi(ui, cmd, image, window.extent); // leaves PRESENT_SRC
        layout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
        stage = VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT;
        access = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
    }
    if (screenshot) { // what the window shows, read back before it is presented
        imageBarrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, layout,
                     VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, stage, access,
                     VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        vkCmdCopyImageToBuffer(cmd, target, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                               vkBuffer(gpu, readback), 1, &copy);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        layout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
        stage = VK_PIPELINE_STAGE_2_COPY_BIT;
        access = 0;
    }
    if (layout != VK_IMAGE_LAYOUT_PRESENT_SRC_KHR)
        imageBarrier(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, layout,
                     VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, stage, access,
                     VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT, 0);
    endLabel(gpu, cmd);
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    wait.semaphore = window.acquired;
    wait.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
    signal.semaphore = window.presentReady[image];
    signal.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cbi.commandBuffer = cmd;
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    si.waitSemaphoreInfoCount = 1;
    si.pWaitSemaphoreInfos = &wait;
    si.signalSemaphoreInfoCount = 1;
    si.pSignalSemaphoreInfos = &signal;
    si.commandBufferInfoCount = 1;
    si.pCommandBufferInfos = &cbi;
    VK_CHECK(vkResetFences(dev, 1, &window.done));
    VK_CHECK(vkQueueSubmit2(gpu.device.queue, 1, &si, window.done));
    VkPresentInfoKHR pi{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    pi.waitSemaphoreCount = 1;
    pi.pWaitSemaphores = &window.presentReady[image];
    pi.swapchainCount = 1;
    pi.pSwapchains = &window.swapchain;
    pi.pImageIndices = &image;
    VkResult presented = vkQueuePresentKHR(gpu.device.queue, &pi);
    if (presented != VK_SUCCESS && presented != VK_SUBOPTIMAL_KHR)
        throw DeviceError(format("shadel view: present failed (%d)", int(presented)));
    VK_CHECK(vkWaitForFences(dev, 1, &window.done, VK_TRUE, UINT64_MAX));

    if (screenshot) {
        std::vector<uint8_t> pixels(size_t(o.width) * o.height * 4);
        copyPixels(
            std::vector<uint8_t>(static_cast<uint8_t*>(mapped(gpu, readback)),
                                 static_cast<uint8_t*>(mapped(gpu, readback)) + pixels.size()),
            window.bgra, pixels.data());
        writePng(o.screenshot, pixels, o.width, o.height);
        SHADEL_INFO("shadel view: screenshot -> %s", o.screenshot.c_str());
    }
}

} // namespace

int runViewer(const ViewOptions& o, DeviceDesc deviceDesc) {
    if (o.width < 16 || o.height < 16 || o.width > 8192 || o.height > 8192)
        throw InputError(
            format("--size %ux%u: the window must be 16..8192 per side", o.width, o.height));
    if (!o.screenshot.empty()) requireCreatableOutput("--screenshot", o.screenshot);
    ViewerPanel panel;
    SceneEditor editor; // lights, sun and materials the user edits
    panel.mode = o.mode == RenderMode::Decoupled ? 1 : 0;
    panel.materialRate = o.materialRate;
    panel.taa = o.aa != AntiAliasing::None; // (auto: TAA in the viewer)

    ViewerWindow window;
    ViewerInput input;
    Gpu gpu;
    ViewerUi ui;
    ViewerScene scene;
    Renderer renderer;
    BufferHandle upload, readback;
    uint64_t frame = 0;
    auto cleanup = [&] {
        if (gpu.device.device) {
            vkDeviceWaitIdle(gpu.device.device);
            destroyRenderer(renderer);
            if (upload) destroy(gpu, upload);
            if (readback) destroy(gpu, readback);
            destroyScene(gpu, scene.gpu);
            destroyUi(ui, gpu);
        }
        destroyWindow(window, &gpu);
        destroyGpu(gpu);
    };
    try {
        deviceDesc.instanceExtensions =
            openWindow(window, o.width, o.height, "shadel view: " + o.scene);
        deviceDesc.swapchain = true;
        createGpu(gpu, deviceDesc);
        if (!o.pipelineCacheFolder.empty()) keepPipelineCacheIn(gpu, o.pipelineCacheFolder);
        createSwapchain(window, gpu);
        bool hotReload = !o.shaderSource.empty() && std::filesystem::is_directory(o.shaderSource);
        if (hotReload) enableShaderHotReload(gpu, o.shaderSource); // before any pipeline
        std::string reloadStatus =
            hotReload ? "hot reload: watching " + o.shaderSource : "hot reload: off";
        if (window.extent.width != o.width || window.extent.height != o.height)
            throw DeviceError(format("shadel view: asked for a %ux%u window, got %ux%u", o.width,
                                     o.height, window.extent.width, window.extent.height));
        // Ours first: ImGui's backend chains to the callbacks it finds installed.
        installViewerInput(window.window, input);
        if (!o.noUi) initUi(ui, window, gpu);
        prepareScene(gpu, o, scene);
        initRenderer(renderer, gpu, settingsFor(o, panel, gpu), scene.gpu);
        VkDeviceSize bytes = VkDeviceSize(o.width) * o.height * 4;
        upload = createBuffer(gpu, {"viewer.frameUpload", bytes, 0, MemoryKind::Upload});
        readback = createBuffer(gpu, {"viewer.screenshot", bytes, 0, MemoryKind::Readback});
        if (!upload || !readback) throw DeviceError("out of host memory for the viewer");

        CameraControl camera = makeCameraControl(scene.camera, scene.bounds);
        VkDevice dev = gpu.device.device;
        auto last = std::chrono::steady_clock::now();
        auto lastPoll = last;
        while (!glfwWindowShouldClose(window.window)) {
            nextFrameInput(input);
            glfwPollEvents();
            auto now = std::chrono::steady_clock::now();
            float dt = std::chrono::duration<float>(now - last).count();
            last = now;
            input.uiWantsKeyboard = uiWantsKeyboard(ui);
            if (applyViewerKeys(input, window.window, camera, panel, scene)) break;
            camera.orbit = panel.orbit;
            updateCamera(camera, window.window, dt, !uiWantsMouse(ui), input);
            panel.cameraArguments = cameraArguments(camera);

            if (hotReload && now - lastPoll > std::chrono::milliseconds(500)) {
                lastPoll = now;
                ShaderReloadResult reload = pollShaderReload(gpu);
                // Material programs (decoupled): their .shmat and stage files.
                uint32_t programs = pollMaterialPrograms(renderer, reload.errors);
                if (programs)
                    reloadStatus = format("hot reload: %u material program(s) swapped", programs);
                if (!reload.errors.empty())
                    reloadStatus = "hot reload failed, old pipeline kept:\n" + reload.errors[0];
                else if (reload.pipelinesSwapped)
                    reloadStatus =
                        format("hot reload: %u pipeline(s) swapped", reload.pipelinesSwapped);
                // A swapped shadow pass (forward.vert, depth.frag) changes what the kept
                // shadow maps hold.
                if (reload.pipelinesSwapped) forgetKeptShadowMaps(renderer);
            }
            FrameResult result =
                renderFrame(renderer, scene.gpu, makeCameraView(camera.camera, o.width, o.height));
            bool lastFrame = o.frames && frame + 1 >= o.frames;
            if (ui.enabled) {
                panel.passes = result.passes;
                panel.frameMsHistory.push_back(float(result.frameMs));
                if (panel.frameMsHistory.size() > 120) panel.frameMsHistory.pop_front();
                panel.statLines = statLines(renderer, result);
                panel.statLines.push_back(reloadStatus);
                buildUi(ui, panel, [&] { buildSceneEditor(editor, renderer, scene.gpu); });
            }
            bool screenshot = !o.screenshot.empty() && (lastFrame || panel.screenshotRequested);

            presentFrame(gpu, window, ui, o, upload, readback, result, screenshot);
            ++frame;
            if (lastFrame) break;
            if (panel.modeChanged || panel.cameraModeChanged || panel.visualizeChanged ||
                panel.taaChanged) {
                // A new renderer: the decoupled path and TAA own their state.
                if (panel.modeChanged || panel.taaChanged) {
                    vkDeviceWaitIdle(dev);
                    destroyRenderer(renderer);
                    renderer = Renderer{};
                    initRenderer(renderer, gpu, settingsFor(o, panel, gpu), scene.gpu);
                    reapplySceneEdits(editor, renderer, scene.gpu);
                } else {
                    renderer.settings.visualize = settingsFor(o, panel, gpu).visualize;
                }
            }
            // Read by the decoupled frontend every frame: no new renderer needed.
            if (panel.materialRateChanged) renderer.settings.materialRate = panel.materialRate;
        }
    } catch (...) {
        cleanup();
        throw;
    }
    uint64_t asserts = renderer.messages.totalAsserts;
    uint32_t validationErrors = gpu.device.validationErrors.load();
    std::printf("shadel view: %llu frame(s), %llu shader asserts, %u validation errors%s%s\n",
                (unsigned long long)frame, (unsigned long long)asserts, validationErrors,
                o.screenshot.empty() ? "" : " -> ", o.screenshot.c_str());
    cleanup();
    return asserts || validationErrors ? 4 : 0;
}

} // namespace shadel
