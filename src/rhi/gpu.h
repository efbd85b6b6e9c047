#pragma once
// The Gpu context: device, memory heaps, resource tables, bindless table, and the small
// amount of frame machinery (command buffers, upload, shader messages). Plain data; the
// functions that act on it live next to the concept they implement.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "rhi/bindless.h"
#include "rhi/device.h"
#include "rhi/memory.h"
#include "rhi/resources.h"

namespace shadel {

template <typename T>
struct SlotTable {
    std::vector<T> items;
    std::vector<bool> alive;
    std::vector<uint32_t> freeList;
    uint32_t add(T item) {
        uint32_t index;
        if (!freeList.empty()) {
            index = freeList.back();
            freeList.pop_back();
            items[index] = std::move(item);
            alive[index] = true;
        } else {
            index = uint32_t(items.size());
            items.push_back(std::move(item));
            alive.push_back(true);
        }
        return index;
    }
    T& operator[](uint32_t i) { return items.at(i); }
    const T& operator[](uint32_t i) const { return items.at(i); }
    bool contains(uint32_t i) const { return i < items.size() && alive[i]; }
    void remove(uint32_t i) {
        alive.at(i) = false;
        items[i] = T{};
        freeList.push_back(i);
    }
    uint32_t count() const { return uint32_t(items.size() - freeList.size()); }
};

struct Gpu {
    Device device;
    Memory memory;
    SlotTable<BufferRecord> buffers;
    SlotTable<TextureRecord> textures;
    SlotTable<ViewRecord> readViews, writeViews, targetViews, depthViews;
    BindlessTable bindless;
    VkCommandPool transientPool = VK_NULL_HANDLE;
    uint64_t frameIndex = 0;
    uint64_t failedAllocations = 0;
    std::shared_ptr<struct ShaderHotReload> hotReload; // rhi/shader_reload.h, when enabled
    // Every pipeline built on this device, shared by the renderers created on it (rhi/pipeline.h).
    std::shared_ptr<struct PipelineLibrary> pipelineLibrary;
};

void createGpu(Gpu& gpu, const DeviceDesc& desc);
void destroyGpu(Gpu& gpu);

// Records commands into a one-shot command buffer, submits and waits (uploads, readbacks).
void immediateSubmit(Gpu& gpu, const std::function<void(VkCommandBuffer)>& record);

// Copies host data into a buffer (through a staging buffer when it is device-local).
void uploadBuffer(Gpu& gpu, BufferHandle dst, const void* data, VkDeviceSize size,
                  VkDeviceSize dstOffset = 0);
// Uploads mip 0 (RGBA8 rows) and generates the rest with blits; leaves SHADER_READ_ONLY.
void uploadTexture(Gpu& gpu, TextureHandle dst, const void* rgba8, VkDeviceSize size);
// Reads a buffer back to host memory.
std::vector<uint8_t> readbackBuffer(Gpu& gpu, BufferHandle src, VkDeviceSize size,
                                    VkDeviceSize offset = 0);

// Barrier helpers (synchronization2). A stage/access pair per side.
void imageBarrier(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                  VkImageLayout oldLayout, VkImageLayout newLayout, VkPipelineStageFlags2 srcStage,
                  VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess, uint32_t baseMip = 0,
                  uint32_t mipCount = VK_REMAINING_MIP_LEVELS);
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess);

void beginLabel(const Gpu& gpu, VkCommandBuffer cmd, const char* name);
void endLabel(const Gpu& gpu, VkCommandBuffer cmd);

} // namespace shadel
