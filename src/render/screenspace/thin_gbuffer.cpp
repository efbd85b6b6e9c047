#include "render/screenspace/thin_gbuffer.h"

#include "core/error.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"
#include "rhi/rendering.h"

namespace shadel {

ThinGBuffer createThinGBuffer(Renderer& r) {
    Gpu& gpu = *r.gpu;
    ThinGBuffer g;
    TextureDesc desc;
    desc.name = "gbuffer.normalRoughness";
    desc.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    desc.width = r.internalWidth;
    desc.height = r.internalHeight;
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
                 VK_IMAGE_USAGE_TRANSFER_SRC_BIT; // --capture
    g.normalRoughness = createTexture(gpu, desc);
    desc.name = "gbuffer.flags";
    desc.format = VK_FORMAT_R8_UNORM; // PIXEL_* bits and the class, as n / 255
    g.flags = createTexture(gpu, desc);
    if (!g.normalRoughness || !g.flags) throw DeviceError("out of GPU memory for the G-buffer");
    g.normalTarget = createRenderTargetView(gpu, g.normalRoughness);
    g.flagsTarget = createRenderTargetView(gpu, g.flags);
    g.normalRead = createReadView(gpu, g.normalRoughness);
    g.flagsRead = createReadView(gpu, g.flags);

    GraphicsPipelineDesc p;
    p.name = "thinGBuffer";
    p.vertexShader = "forward_forward.vert.spv";
    p.fragmentShader = "screenspace_gbuffer.frag.spv";
    p.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R8_UNORM};
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthWrite = false;
    p.depthCompare = VK_COMPARE_OP_EQUAL; // the prepass resolved visibility
    p.dynamicCulling = true;              // per list side (drawCameraList), as the prepass
    g.pipeline = createGraphicsPipeline(gpu, p);
    return g;
}

void destroyThinGBuffer(Renderer& r, ThinGBuffer& g) {
    Gpu& gpu = *r.gpu;
    destroy(gpu, g.pipeline);
    destroy(gpu, g.normalTarget);
    destroy(gpu, g.flagsTarget);
    destroy(gpu, g.normalRead);
    destroy(gpu, g.flagsRead);
    destroy(gpu, g.normalRoughness);
    destroy(gpu, g.flags);
    g = {};
}

void recordThinGBuffer(Renderer& r, ThinGBuffer& g, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    for (TextureHandle t : {g.normalRoughness, g.flags})
        imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    // Cleared to 0: flags 0 is sky.
    beginRendering(cmd, r.internalWidth, r.internalHeight,
                   {{vkView(gpu, g.normalTarget), true}, {vkView(gpu, g.flagsTarget), true}},
                   {vkView(gpu, r.depthTarget)});
    bind(gpu, cmd, g.pipeline);
    pushConstants(gpu, cmd, RasterPush{frame, 0});
    drawCameraList(r, cmd, DRAW_LIST_OPAQUE);
    drawCameraList(r, cmd, DRAW_LIST_DECOUPLED);
    vkCmdEndRendering(cmd);
    for (TextureHandle t : {g.normalRoughness, g.flags})
        imageBarrier(
            cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

} // namespace shadel
