#include "render/raytracing/blas_pools.h"

#include "core/log.h"

namespace shadel {

// VkAccelerationStructureCreateInfoKHR::offset must be a multiple of 256.
static constexpr VkDeviceSize kBlasAlignment = 256;

BlasPools::BlasPools(Gpu& gpu, uint64_t poolBytes, uint32_t maxPools) : m_gpu(gpu) {
    PoolSetDesc desc;
    desc.poolSize = poolBytes;
    desc.maxPools = maxPools;
    desc.maxSpareEmptyPools = 0; // BLASes are built at load: an emptied pool is not refilled soon
    PoolCallbacks callbacks;
    callbacks.create = [this](uint32_t index, uint64_t size) {
        BufferHandle b =
            createBuffer(m_gpu, {format("rt.blasPool%u", index), size,
                                 VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR});
        if (!b) return false;
        if (m_buffers.size() <= index) m_buffers.resize(index + 1);
        m_buffers[index] = b;
        return true;
    };
    callbacks.destroy = [this](uint32_t index) {
        destroy(m_gpu, m_buffers.at(index));
        m_buffers[index] = {};
    };
    m_pools = std::make_unique<PoolSet>(desc, callbacks);
}

BlasPools::~BlasPools() {
    m_pools.reset();
} // destroys the pools' buffers through the callback

std::optional<BlasRange> BlasPools::allocate(VkDeviceSize size) {
    std::optional<PoolAllocation> a = m_pools->allocate(size, kBlasAlignment);
    if (!a) return std::nullopt;
    BlasRange r;
    r.allocation = *a;
    r.buffer = vkBuffer(m_gpu, m_buffers.at(a->pool));
    r.offset = a->offset;
    return r;
}

void BlasPools::free(const BlasRange& range) {
    m_pools->free(range.allocation);
}

} // namespace shadel
