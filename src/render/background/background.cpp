#include "render/background/background.h"

#include "render/forward/forward_passes.h"
#include "render/renderer.h"

namespace shadel {

static GraphicsPipelineDesc backgroundPipeline(bool display) {
    GraphicsPipelineDesc desc;
    desc.name = display ? "backgroundDisplay" : "background";
    desc.vertexShader = "oit_fullscreen.vert.spv";
    desc.fragmentShader = "background_background.frag.spv";
    desc.colorFormats = {display ? VK_FORMAT_R8G8B8A8_UNORM : VK_FORMAT_R16G16B16A16_SFLOAT};
    desc.depthFormat = VK_FORMAT_D32_SFLOAT;
    desc.depthWrite = false;
    desc.depthCompare = VK_COMPARE_OP_EQUAL; // the far plane (0, reversed Z): nothing drawn there
    desc.cullMode = VK_CULL_MODE_NONE;
    desc.specialization = {{0u, display ? 1u : 0u}};
    return desc;
}

void createBackgroundPipelines(Renderer& r) {
    if (!r.settings.backgroundEnvironment) return;
    r.background = createGraphicsPipeline(*r.gpu, backgroundPipeline(false));
    if (r.display) r.backgroundDisplay = createGraphicsPipeline(*r.gpu, backgroundPipeline(true));
}

void destroyBackgroundPipelines(Renderer& r) {
    destroy(*r.gpu, r.background);
    destroy(*r.gpu, r.backgroundDisplay);
}

void recordBackground(Renderer& r, VkCommandBuffer cmd, uint64_t frame, bool display) {
    if (!r.settings.backgroundEnvironment) return;
    bind(*r.gpu, cmd, display ? r.backgroundDisplay : r.background);
    pushConstants(*r.gpu, cmd, RasterPush{frame, 0});
    vkCmdDraw(cmd, 3, 1, 0, 0);
}

} // namespace shadel
