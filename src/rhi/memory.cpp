#include "rhi/memory.h"

#include "core/log.h"
#include "rhi/device.h"

namespace shadel {

void initMemory(Memory& memory, const Device& device, uint64_t poolSize) {
    memory.device = &device;
    memory.poolSize = poolSize;
}

void destroyMemory(Memory& memory) {
    for (auto& heap : memory.heaps) {
        heap->pools.reset(); // releases every pool through the destroy callback
        for (VkDeviceMemory m : heap->poolMemory)
            if (m) vkFreeMemory(memory.device->device, m, nullptr);
    }
    memory.heaps.clear();
}

static uint32_t findMemoryType(const Device& device, uint32_t typeBits, MemoryKind kind) {
    VkMemoryPropertyFlags want = 0, avoid = 0;
    switch (kind) {
    case MemoryKind::DeviceLocal:
        want = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
        break;
    case MemoryKind::Upload:
        want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
        break;
    case MemoryKind::Readback:
        want = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT |
               VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
        break;
    }
    if (kind == MemoryKind::DeviceLocal) avoid = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT;
    // Best: all wanted, none avoided; then all wanted; then the host-visible minimum.
    for (int pass = 0; pass < 3; ++pass) {
        for (uint32_t i = 0; i < device.memory.memoryTypeCount; ++i) {
            if (!(typeBits & (1u << i))) continue;
            VkMemoryPropertyFlags f = device.memory.memoryTypes[i].propertyFlags;
            if (pass == 0 && (f & want) == want && !(f & avoid)) return i;
            if (pass == 1 && (f & want) == want) return i;
            if (pass == 2 && kind != MemoryKind::DeviceLocal &&
                (f &
                 (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT)) ==
                    (VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT))
                return i;
            if (pass == 2 && kind == MemoryKind::DeviceLocal) return i;
        }
    }
    return ~0u;
}

static MemoryHeap& heapFor(Memory& memory, MemoryKind kind, uint32_t memoryType) {
    for (auto& h : memory.heaps)
        if (h->kind == kind && h->memoryType == memoryType) return *h;
    auto heap = std::make_unique<MemoryHeap>();
    heap->kind = kind;
    heap->memoryType = memoryType;
    MemoryHeap* raw = heap.get();
    const Device* device = memory.device;
    PoolCallbacks callbacks;
    callbacks.create = [raw, device](uint32_t poolIndex, uint64_t size) -> bool {
        VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
        flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
        VkMemoryAllocateInfo ai{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        ai.pNext = &flags;
        ai.allocationSize = size;
        ai.memoryTypeIndex = raw->memoryType;
        VkDeviceMemory mem = VK_NULL_HANDLE;
        if (vkAllocateMemory(device->device, &ai, nullptr, &mem) != VK_SUCCESS) return false;
        void* mapped = nullptr;
        if (raw->kind != MemoryKind::DeviceLocal &&
            vkMapMemory(device->device, mem, 0, VK_WHOLE_SIZE, 0, &mapped) != VK_SUCCESS) {
            vkFreeMemory(device->device, mem, nullptr);
            return false;
        }
        if (raw->poolMemory.size() <= poolIndex) {
            raw->poolMemory.resize(poolIndex + 1, VK_NULL_HANDLE);
            raw->poolMapped.resize(poolIndex + 1, nullptr);
        }
        raw->poolMemory[poolIndex] = mem;
        raw->poolMapped[poolIndex] = mapped;
        static const char* kindNames[] = {"deviceLocal", "upload", "readback"};
        setName(
            *device, mem, VK_OBJECT_TYPE_DEVICE_MEMORY,
            format("heap.%s.type%u.pool%u", kindNames[int(raw->kind)], raw->memoryType, poolIndex));
        return true;
    };
    callbacks.destroy = [raw, device](uint32_t poolIndex) {
        if (poolIndex < raw->poolMemory.size() && raw->poolMemory[poolIndex]) {
            vkFreeMemory(device->device, raw->poolMemory[poolIndex], nullptr);
            raw->poolMemory[poolIndex] = VK_NULL_HANDLE;
            raw->poolMapped[poolIndex] = nullptr;
        }
    };
    PoolSetDesc desc;
    desc.poolSize = memory.poolSize;
    desc.maxPools = memory.maxPoolsPerHeap;
    heap->pools = std::make_unique<PoolSet>(desc, std::move(callbacks));
    memory.heaps.push_back(std::move(heap));
    return *raw;
}

std::optional<MemoryBlock> allocateMemory(Memory& memory, MemoryKind kind,
                                          const VkMemoryRequirements& requirements) {
    uint32_t type = findMemoryType(*memory.device, requirements.memoryTypeBits, kind);
    if (type == ~0u) return std::nullopt;
    MemoryHeap& heap = heapFor(memory, kind, type);
    // Buffers and optimal-tiling images share pools: keep them on separate granularity pages.
    VkDeviceSize alignment =
        std::max(requirements.alignment, memory.device->properties.limits.bufferImageGranularity);
    auto allocation = heap.pools->allocate(requirements.size, alignment);
    if (!allocation) return std::nullopt;
    MemoryBlock block;
    block.memory = heap.poolMemory[allocation->pool];
    block.offset = allocation->offset;
    block.size = requirements.size;
    uint8_t* base = static_cast<uint8_t*>(heap.poolMapped[allocation->pool]);
    block.mapped = base ? base + allocation->offset : nullptr;
    for (uint32_t i = 0; i < memory.heaps.size(); ++i)
        if (memory.heaps[i].get() == &heap) block.heap = i;
    block.allocation = *allocation;
    return block;
}

void freeMemory(Memory& memory, MemoryBlock& block) {
    if (block.heap == ~0u) return;
    memory.heaps[block.heap]->pools->free(block.allocation);
    block = MemoryBlock{};
}

MemoryHeapStats memoryStats(const Memory& memory) {
    MemoryHeapStats out;
    for (auto& h : memory.heaps) {
        PoolSetStats s = h->pools->stats();
        out.poolBytes += s.poolBytes;
        out.usedBytes += s.usedBytes;
        out.pools += s.poolCount;
        out.allocations += s.allocationCount;
    }
    return out;
}

} // namespace shadel
