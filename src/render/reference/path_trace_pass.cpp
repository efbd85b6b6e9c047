// The `referencePathTrace` pass (render/reference/reference.h): --spp paths per pixel folded
// into the accumulated mean, which also goes into the scene colour for the tonemap.
#include "reference/reference_types.h"
#include "render/reference/reference.h"
#include "render/reference/reference_state.h"
#include "render/renderer.h"
#include "rhi/rendering.h"

namespace shadel {

void recordReferencePathTrace(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    ReferenceState& s = *r.reference;
    const ReferenceSettings& settings = r.settings.reference;
    // The mean is read and written in GENERAL layout; its first frame only writes it.
    imageBarrier(cmd, vkImage(gpu, s.accumulation), VK_IMAGE_ASPECT_COLOR_BIT,
                 s.laidOut ? VK_IMAGE_LAYOUT_GENERAL : VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_READ_BIT,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    s.laidOut = true;
    // The scene colour: every pixel written here (last frame's reads were the tonemap's).
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    gpu::ReferencePush push{};
    push.frame = frame;
    push.accumulationSlot = slot(gpu, s.accumulationWrite).value;
    push.hdrSlot = slot(gpu, s.hdrWrite).value;
    push.width = r.internalWidth;
    push.height = r.internalHeight;
    push.samplesBefore = s.samplesAccumulated;
    push.samples = settings.samplesPerFrame;
    push.maxBounces = settings.maxBounces;
    push.rouletteStart = settings.rouletteStart;
    push.seed = settings.seed;
    push.flags = s.alpha ? REFERENCE_FLAG_ALPHA : 0u;
    bind(gpu, cmd, s.pathTrace);
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, (r.internalWidth + REFERENCE_GROUP_SIZE - 1) / REFERENCE_GROUP_SIZE,
                  (r.internalHeight + REFERENCE_GROUP_SIZE - 1) / REFERENCE_GROUP_SIZE, 1);
    s.samplesAccumulated += settings.samplesPerFrame;
    // The scene colour to the passes after (the tonemap reads it as the visibility resolve
    // leaves it: from COLOR_ATTACHMENT_OPTIMAL).
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
    // The mean to the capture's copy after the frame.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
}

} // namespace shadel
