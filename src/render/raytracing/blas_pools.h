#pragma once
// BLAS memory: acceleration-structure storage buffers of a fixed size (128 MiB by
// default), created on demand up to a limit, sub-allocated with TLSF (core/gpu_pools.h), empty
// ones released. Unlike raster geometry an allocation may fail: the caller falls back to the
// least-detailed BLAS of the mesh, which is always built first.
#include <optional>
#include <vector>

#include "core/gpu_pools.h"
#include "rhi/gpu.h"

namespace shadel {

struct BlasRange {
    PoolAllocation allocation;
    VkBuffer buffer = VK_NULL_HANDLE; // the pool's buffer
    VkDeviceSize offset = 0;          // of the BLAS in it (a multiple of 256, as Vulkan asks)
};

class BlasPools {
public:
    BlasPools(Gpu& gpu, uint64_t poolBytes, uint32_t maxPools);
    ~BlasPools();
    BlasPools(const BlasPools&) = delete;
    BlasPools& operator=(const BlasPools&) = delete;

    // nullopt when the pool limit is reached (or the device has no memory for a new pool).
    std::optional<BlasRange> allocate(VkDeviceSize size);
    void free(const BlasRange& range);
    PoolSetStats stats() const { return m_pools->stats(); }

private:
    Gpu& m_gpu;
    std::vector<BufferHandle> m_buffers; // by pool index
    std::unique_ptr<PoolSet> m_pools;
};

} // namespace shadel
