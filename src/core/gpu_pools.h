#pragma once
// A growable set of fixed-size memory pools, each sub-allocated with TLSF (128 MiB
// pools created on demand, an upper limit on their number, unused pools released, and allocation
// that fails cleanly at the limit so the caller can fall back, e.g. to the always-resident
// least-detailed LOD). The set only manages offsets; the owner creates and destroys the backing
// memory (a VkDeviceMemory per pool) in the callbacks.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/tlsf.h"

namespace shadel {

struct PoolSetDesc {
    uint64_t poolSize = 128ull << 20;
    uint32_t maxPools = 16;          // regular and dedicated pools together
    uint32_t maxSpareEmptyPools = 1; // empty regular pools kept to avoid create/destroy thrash
};

struct PoolCallbacks {
    // Creates the backing memory of pool `poolIndex` with `size` bytes; false means the memory is
    // not available and the allocation that needed it fails.
    std::function<bool(uint32_t poolIndex, uint64_t size)> create;
    // Releases the backing memory of `poolIndex`; the index may be reused by a later create.
    std::function<void(uint32_t poolIndex)> destroy;
};

struct PoolAllocation {
    uint32_t pool = ~0u;
    uint64_t offset = 0;
    uint64_t size = 0;
    TlsfAllocation tlsf;
};

struct PoolSetStats {
    uint64_t poolBytes = 0; // backing memory currently created
    uint64_t usedBytes = 0; // sub-allocated
    uint32_t poolCount = 0;
    uint32_t dedicatedPoolCount = 0;
    uint32_t emptyPoolCount = 0;
    uint32_t allocationCount = 0;
    uint32_t failedAllocations = 0; // allocate() calls that returned nullopt
};

class PoolSet {
public:
    PoolSet(PoolSetDesc desc, PoolCallbacks callbacks);
    // Destroys every pool still alive through the destroy callback.
    ~PoolSet();
    PoolSet(const PoolSet&) = delete;
    PoolSet& operator=(const PoolSet&) = delete;

    // Sub-allocates from an existing pool, else creates one. Sizes above the pool size get a
    // dedicated pool of exactly that size. Returns nullopt when the pool limit is reached, the
    // create callback fails, the size is 0 or the alignment is not a power of two.
    std::optional<PoolAllocation> allocate(uint64_t size, uint64_t alignment = 1);
    void free(const PoolAllocation& allocation);
    // Destroys all empty pools, including the spare one.
    void releaseEmptyPools();

    PoolSetStats stats() const;
    const PoolSetDesc& desc() const { return m_desc; }
    // The TLSF of a live pool, for inspection; nullptr if `poolIndex` is not alive.
    const Tlsf* pool(uint32_t poolIndex) const;

private:
    struct Pool {
        Tlsf tlsf;
        bool dedicated;
    };
    std::optional<uint32_t> createPool(uint64_t size, bool dedicated);
    void destroyPool(uint32_t poolIndex);
    uint32_t livePoolCount() const;
    uint32_t emptyRegularPoolCount() const;

    PoolSetDesc m_desc;
    PoolCallbacks m_callbacks;
    std::vector<std::unique_ptr<Pool>> m_pools; // indexed by pool index; null = free slot
    uint32_t m_failedAllocations = 0;
};

} // namespace shadel
