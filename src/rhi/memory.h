#pragma once
// Device memory heaps: every buffer and texture is sub-allocated from fixed-size pools of
// VkDeviceMemory managed by TLSF (core/gpu_pools.h). Allocation failure is a value.
#include <memory>
#include <optional>
#include <vector>

#include "core/gpu_pools.h"
#include "rhi/vk.h"

namespace shadel {

struct Device;

enum class MemoryKind : uint32_t {
    DeviceLocal, // GPU only
    Upload,      // host-visible, coherent, written by the CPU
    Readback,    // host-visible, cached, read by the CPU
};

struct MemoryBlock {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
    void* mapped = nullptr; // host pointer for Upload/Readback memory
    uint32_t heap = ~0u;    // which MemoryHeap
    PoolAllocation allocation;
};

struct MemoryHeapStats {
    uint64_t poolBytes = 0; // VkDeviceMemory allocated
    uint64_t usedBytes = 0; // sub-allocated
    uint32_t pools = 0;
    uint32_t allocations = 0;
};

// One heap per (kind, memory type): a PoolSet of VkDeviceMemory blocks.
struct MemoryHeap {
    MemoryKind kind;
    uint32_t memoryType = 0;
    std::unique_ptr<PoolSet> pools;
    std::vector<VkDeviceMemory> poolMemory;
    std::vector<void*> poolMapped;
};

struct Memory {
    const Device* device = nullptr;
    uint64_t poolSize = 128ull << 20;
    uint32_t maxPoolsPerHeap = 64;
    std::vector<std::unique_ptr<MemoryHeap>> heaps;
};

void initMemory(Memory& memory, const Device& device, uint64_t poolSize = 128ull << 20);
void destroyMemory(Memory& memory);
std::optional<MemoryBlock> allocateMemory(Memory& memory, MemoryKind kind,
                                          const VkMemoryRequirements& requirements);
void freeMemory(Memory& memory, MemoryBlock& block);
MemoryHeapStats memoryStats(const Memory& memory);

} // namespace shadel
