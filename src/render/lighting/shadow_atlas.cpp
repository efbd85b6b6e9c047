#include "render/lighting/shadow_atlas.h"

#include <string>

#include "core/error.h"
#include "rhi/gpu.h"
#include "rhi/rendering.h"
#include "rhi/resources.h"

namespace shadel {

ShadowAtlas createShadowAtlas(Gpu& gpu, const char* name, uint32_t width, uint32_t height,
                              const char* vertexShader, bool alphaMasked) {
    ShadowAtlas a;
    a.width = width;
    a.height = height;
    TextureDesc desc;
    desc.name = std::string(name) + "Atlas";
    desc.format = VK_FORMAT_D32_SFLOAT;
    desc.width = width;
    desc.height = height;
    desc.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    a.texture = createTexture(gpu, desc);
    if (!a.texture) throw DeviceError(std::string("out of GPU memory for the ") + desc.name);
    a.target = createDepthTargetView(gpu, a.texture);
    a.read = createReadView(gpu, a.texture);

    GraphicsPipelineDesc pass;
    pass.name = name;
    pass.vertexShader = vertexShader;
    pass.fragmentShader = alphaMasked ? "forward_depth.frag.spv" : "";
    pass.depthFormat = VK_FORMAT_D32_SFLOAT;
    pass.depthCompare = VK_COMPARE_OP_LESS_OR_EQUAL;
    pass.cullMode = VK_CULL_MODE_NONE;
    pass.depthClamp = true;
    pass.depthBias = true;
    a.pass = createGraphicsPipeline(gpu, pass);
    return a;
}

void destroyShadowAtlas(Gpu& gpu, ShadowAtlas& a) {
    destroy(gpu, a.pass);
    destroy(gpu, a.target);
    destroy(gpu, a.read);
    destroy(gpu, a.texture);
    a = {};
}

// The stages that sample the maps: fragment and compute shading, and the vertex shaders of
// particles lit per vertex (shaders/particles: shadeParticle).
constexpr VkPipelineStageFlags2 kShadowReaders = VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                                                 VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                                                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;

void beginShadowAtlas(Gpu& gpu, VkCommandBuffer cmd, const ShadowAtlas& a, VkBuffer sceneIndices) {
    // Last frame's shading sampled it; its old contents are cleared.
    imageBarrier(cmd, vkImage(gpu, a.texture), VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, kShadowReaders, 0,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
    // Cleared to the far plane (shadow maps are not reversed Z); the viewport is the whole
    // atlas until a map's own is set.
    beginRendering(cmd, a.width, a.height, {}, {vkView(gpu, a.target), true, 1.0f});
    bind(gpu, cmd, a.pass);
    vkCmdSetDepthBias(cmd, 1.25f, 0.0f, 1.75f);
    vkCmdBindIndexBuffer(cmd, sceneIndices, 0, VK_INDEX_TYPE_UINT32);
}

void setShadowMapViewport(VkCommandBuffer cmd, uint32_t x, uint32_t y, uint32_t size) {
    VkViewport vp{float(x), float(y), float(size), float(size), 0, 1};
    VkRect2D scissor{{int32_t(x), int32_t(y)}, {size, size}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void endShadowAtlas(Gpu& gpu, VkCommandBuffer cmd, const ShadowAtlas& a) {
    vkCmdEndRendering(cmd);
    imageBarrier(cmd, vkImage(gpu, a.texture), VK_IMAGE_ASPECT_DEPTH_BIT,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, kShadowReaders,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

} // namespace shadel
