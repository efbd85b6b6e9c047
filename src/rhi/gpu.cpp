#include "rhi/gpu.h"

#include "rhi/pipeline.h"
#include "rhi/shader_reload.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/assert.h"
#include "core/log.h"

namespace shadel {

void createGpu(Gpu& gpu, const DeviceDesc& desc) {
    createDevice(gpu.device, desc);
    initMemory(gpu.memory, gpu.device);
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.flags =
        VK_COMMAND_POOL_CREATE_TRANSIENT_BIT | VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    ci.queueFamilyIndex = gpu.device.queueFamily;
    VK_CHECK(vkCreateCommandPool(gpu.device.device, &ci, nullptr, &gpu.transientPool));
    setName(gpu.device, gpu.transientPool, VK_OBJECT_TYPE_COMMAND_POOL, "transientPool");
    initBindless(gpu);
    initPipelineLibrary(gpu);
}

void destroyGpu(Gpu& gpu) {
    if (!gpu.device.device) return;
    vkDeviceWaitIdle(gpu.device.device);
    disableShaderHotReload(gpu);
    destroyPipelineLibrary(gpu);
    destroyBindless(gpu);
    for (uint32_t i = 0; i < gpu.readViews.items.size(); ++i)
        if (gpu.readViews.contains(i)) destroy(gpu, TextureReadView{i});
    for (uint32_t i = 0; i < gpu.writeViews.items.size(); ++i)
        if (gpu.writeViews.contains(i)) destroy(gpu, TextureWriteView{i});
    for (uint32_t i = 0; i < gpu.targetViews.items.size(); ++i)
        if (gpu.targetViews.contains(i)) destroy(gpu, RenderTargetView{i});
    for (uint32_t i = 0; i < gpu.depthViews.items.size(); ++i)
        if (gpu.depthViews.contains(i)) destroy(gpu, DepthTargetView{i});
    for (uint32_t i = 0; i < gpu.textures.items.size(); ++i)
        if (gpu.textures.contains(i)) destroy(gpu, TextureHandle{i});
    for (uint32_t i = 0; i < gpu.buffers.items.size(); ++i)
        if (gpu.buffers.contains(i)) destroy(gpu, BufferHandle{i});
    vkDestroyCommandPool(gpu.device.device, gpu.transientPool, nullptr);
    destroyMemory(gpu.memory);
    destroyDevice(gpu.device);
}

void immediateSubmit(Gpu& gpu, const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = gpu.transientPool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    VK_CHECK(vkAllocateCommandBuffers(gpu.device.device, &ai, &cmd));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
    record(cmd);
    VK_CHECK(vkEndCommandBuffer(cmd));
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK_CHECK(vkCreateFence(gpu.device.device, &fci, nullptr, &fence));
    VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cbi.commandBuffer = cmd;
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    si.commandBufferInfoCount = 1;
    si.pCommandBufferInfos = &cbi;
    VK_CHECK(vkQueueSubmit2(gpu.device.queue, 1, &si, fence));
    VK_CHECK(vkWaitForFences(gpu.device.device, 1, &fence, VK_TRUE, UINT64_MAX));
    vkDestroyFence(gpu.device.device, fence, nullptr);
    vkFreeCommandBuffers(gpu.device.device, gpu.transientPool, 1, &cmd);
}

void uploadBuffer(Gpu& gpu, BufferHandle dst, const void* data, VkDeviceSize bytes,
                  VkDeviceSize dstOffset) {
    if (bytes == 0) return;
    SHADEL_ASSERT(dstOffset + bytes <= size(gpu, dst));
    if (void* ptr = mapped(gpu, dst)) {
        std::memcpy(static_cast<uint8_t*>(ptr) + dstOffset, data, bytes);
        return;
    }
    // Through a staging buffer of at most kUploadChunk bytes, one copy per chunk: a scene's
    // largest array never needs as much host-visible memory again, and no single copy region
    // grows past what drivers handle well (lavapipe's copy took a 3.9 GB size as negative).
    constexpr VkDeviceSize kUploadChunk = VkDeviceSize(64) << 20;
    VkDeviceSize chunk = std::min(bytes, kUploadChunk);
    BufferHandle staging = createBuffer(gpu, {"staging.upload", chunk, 0, MemoryKind::Upload});
    if (!staging) throw DeviceError("out of host-visible memory for an upload staging buffer");
    for (VkDeviceSize done = 0; done < bytes; done += chunk) {
        VkDeviceSize n = std::min(chunk, bytes - done);
        std::memcpy(mapped(gpu, staging), static_cast<const uint8_t*>(data) + done, n);
        immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
            VkBufferCopy copy{0, dstOffset + done, n};
            vkCmdCopyBuffer(cmd, vkBuffer(gpu, staging), vkBuffer(gpu, dst), 1, &copy);
            memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                          VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT);
        });
    }
    destroy(gpu, staging);
}

void uploadTexture(Gpu& gpu, TextureHandle dst, const void* rgba8, VkDeviceSize bytes) {
    const TextureDesc& d = desc(gpu, dst);
    BufferHandle staging = createBuffer(gpu, {"staging.texture", bytes, 0, MemoryKind::Upload});
    if (!staging) throw DeviceError("out of host-visible memory for a texture upload");
    std::memcpy(mapped(gpu, staging), rgba8, bytes);
    VkImage image = vkImage(gpu, dst);
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        VkBufferImageCopy copy{};
        copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        copy.imageExtent = {d.width, d.height, 1};
        vkCmdCopyBufferToImage(cmd, vkBuffer(gpu, staging), image,
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
        // Mips by successive linear blits.
        int32_t w = int32_t(d.width), h = int32_t(d.height);
        for (uint32_t mip = 1; mip < d.mipLevels; ++mip) {
            imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                         mip - 1, 1);
            int32_t nw = std::max(1, w / 2), nh = std::max(1, h / 2);
            VkImageBlit blit{};
            blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip - 1, 0, 1};
            blit.srcOffsets[1] = {w, h, 1};
            blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, mip, 0, 1};
            blit.dstOffsets[1] = {nw, nh, 1};
            vkCmdBlitImage(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image,
                           VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
            imageBarrier(
                cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                VK_ACCESS_2_SHADER_READ_BIT, mip - 1, 1);
            w = nw, h = nh;
        }
        imageBarrier(cmd, image, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                     VK_ACCESS_2_SHADER_READ_BIT, d.mipLevels - 1, 1);
    });
    destroy(gpu, staging);
}

std::vector<uint8_t> readbackBuffer(Gpu& gpu, BufferHandle src, VkDeviceSize bytes,
                                    VkDeviceSize offset) {
    std::vector<uint8_t> out(bytes);
    if (bytes == 0) return out;
    BufferHandle staging = createBuffer(gpu, {"staging.readback", bytes, 0, MemoryKind::Readback});
    if (!staging) throw DeviceError("out of host-visible memory for a readback");
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        VkBufferCopy copy{offset, 0, bytes};
        vkCmdCopyBuffer(cmd, vkBuffer(gpu, src), vkBuffer(gpu, staging), 1, &copy);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    });
    std::memcpy(out.data(), mapped(gpu, staging), bytes);
    destroy(gpu, staging);
    return out;
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess, uint32_t baseMip, uint32_t mipCount) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    b.oldLayout = oldLayout;
    b.newLayout = newLayout;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {aspect, baseMip, mipCount, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
    VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

void beginLabel(const Gpu& gpu, VkCommandBuffer cmd, const char* name) {
    if (!gpu.device.cmdBeginLabel) return;
    VkDebugUtilsLabelEXT label{VK_STRUCTURE_TYPE_DEBUG_UTILS_LABEL_EXT};
    label.pLabelName = name;
    gpu.device.cmdBeginLabel(cmd, &label);
}

void endLabel(const Gpu& gpu, VkCommandBuffer cmd) {
    if (gpu.device.cmdEndLabel) gpu.device.cmdEndLabel(cmd);
}

} // namespace shadel
