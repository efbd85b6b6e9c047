#include "render/post/tonemap.h"

#include <algorithm>
#include <cmath>

#include "render/oit/oit.h"
#include "render/renderer.h"

namespace shadel {

namespace {
struct TonemapPush {
    uint64_t frame;
    uint64_t pixels;
    uint32_t hdrSlot;
    uint32_t depthSlot;
    uint32_t width;
    uint32_t height;
    uint32_t ssaa;
};
} // namespace

void createTonemapPipeline(Renderer& r) {
    r.tonemap = createComputePipeline(*r.gpu, "tonemap", "post_tonemap.comp.spv");
}

void recordSceneTargetsForComputeReads(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    // A target that also allows storage (the visibility resolve) is read in GENERAL layout.
    VkImageLayout hdrLayout = (desc(gpu, r.hdr).usage & VK_IMAGE_USAGE_STORAGE_BIT)
                                  ? VK_IMAGE_LAYOUT_GENERAL
                                  : VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, hdrLayout,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    imageBarrier(cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void recordTonemap(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    if (!r.taa) recordSceneTargetsForComputeReads(r, cmd); // (with TAA the resolve did)
    bind(gpu, cmd, r.tonemap);
    TonemapPush push{frame,
                     address(gpu, r.pixels),
                     r.taa ? taaDisplaySlot(r) : slot(gpu, r.hdrRead).value,
                     slot(gpu, r.depthRead).value,
                     r.settings.width,
                     r.settings.height,
                     r.settings.ssaa};
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, (r.settings.width + TONEMAP_GROUP_X - 1) / TONEMAP_GROUP_X,
                  (r.settings.height + TONEMAP_GROUP_Y - 1) / TONEMAP_GROUP_Y, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

bool forwardMayFuseTonemap(const Renderer& r) {
    return r.settings.fuseTonemap && r.settings.ssaa == 1 &&
           r.settings.mode == RenderMode::Forward && !usesTileShading(r) &&
           !taaEnabled(r.settings); // (TAA reads the scene colour)
}

bool tonemapFusedThisFrame(const Renderer& r) {
    // The opaque shading pass that writes display pixels: forward shading (not the tile path),
    // or the decoupled compute resolve (not the raster reconstruction).
    bool fusingPass = r.settings.mode == RenderMode::Forward
                          ? forwardMayFuseTonemap(r)
                          : r.settings.fuseTonemap && r.settings.ssaa == 1 && r.visibility;
    // Every pass declared after it that draws into or reads the scene colour.
    bool drawnAfter = r.particles || r.screenSpace || r.stencilEffects || r.pointsLines ||
                      r.debugLines || transparencyThisFrame(r) || transmissionThisFrame(r) || r.taa;
    return fusingPass && !drawnAfter;
}

void recordDisplayReadback(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    imageBarrier(cmd, vkImage(gpu, r.display), VK_IMAGE_ASPECT_COLOR_BIT,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                 VK_ACCESS_2_TRANSFER_READ_BIT);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = {r.settings.width, r.settings.height, 1};
    vkCmdCopyImageToBuffer(cmd, vkImage(gpu, r.display), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           vkBuffer(gpu, r.pixels), 1, &copy);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
}

} // namespace shadel
