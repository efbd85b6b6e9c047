#include "core/gpu_pools.h"

#include "core/assert.h"

namespace shadel {

PoolSet::PoolSet(PoolSetDesc desc, PoolCallbacks callbacks)
    : m_desc(desc), m_callbacks(std::move(callbacks)) {
    SHADEL_ASSERT(m_desc.poolSize > 0);
}

PoolSet::~PoolSet() {
    for (uint32_t i = 0; i < m_pools.size(); ++i)
        if (m_pools[i]) destroyPool(i);
}

uint32_t PoolSet::livePoolCount() const {
    uint32_t count = 0;
    for (const auto& pool : m_pools) count += pool != nullptr;
    return count;
}

uint32_t PoolSet::emptyRegularPoolCount() const {
    uint32_t count = 0;
    for (const auto& pool : m_pools) count += pool && !pool->dedicated && pool->tlsf.empty();
    return count;
}

std::optional<uint32_t> PoolSet::createPool(uint64_t size, bool dedicated) {
    if (livePoolCount() >= m_desc.maxPools) return std::nullopt;
    uint32_t index = 0;
    while (index < m_pools.size() && m_pools[index]) ++index;
    if (m_callbacks.create && !m_callbacks.create(index, size)) return std::nullopt;
    if (index == m_pools.size()) m_pools.emplace_back();
    m_pools[index] = std::make_unique<Pool>(Pool{Tlsf(size), dedicated});
    return index;
}

void PoolSet::destroyPool(uint32_t poolIndex) {
    if (m_callbacks.destroy) m_callbacks.destroy(poolIndex);
    m_pools[poolIndex].reset();
    while (!m_pools.empty() && !m_pools.back()) m_pools.pop_back();
}

std::optional<PoolAllocation> PoolSet::allocate(uint64_t size, uint64_t alignment) {
    auto fail = [&] {
        ++m_failedAllocations;
        return std::nullopt;
    };
    if (size == 0 || alignment == 0 || (alignment & (alignment - 1)) != 0) return fail();
    auto from = [&](uint32_t poolIndex) -> std::optional<PoolAllocation> {
        auto allocation = m_pools[poolIndex]->tlsf.allocate(size, alignment);
        if (!allocation) return std::nullopt;
        return PoolAllocation{poolIndex, allocation->offset, size, *allocation};
    };

    if (size > m_desc.poolSize) {
        // Too big to share: a pool of its own, released as soon as it is freed. At the limit,
        // an idle spare pool is worth less than this allocation.
        if (livePoolCount() >= m_desc.maxPools) {
            for (uint32_t i = 0; i < m_pools.size(); ++i) {
                if (m_pools[i] && !m_pools[i]->dedicated && m_pools[i]->tlsf.empty()) {
                    destroyPool(i);
                    break;
                }
            }
        }
        auto index = createPool(size, true);
        if (!index) return fail();
        auto allocation = from(*index);
        SHADEL_ASSERT(allocation.has_value()); // offset 0 of an exactly sized pool
        return allocation;
    }

    // Fill pools that are in use before touching an empty one, so that the spare stays empty
    // and can be released.
    for (int pass = 0; pass < 2; ++pass) {
        for (uint32_t i = 0; i < m_pools.size(); ++i) {
            const Pool* pool = m_pools[i].get();
            if (!pool || pool->dedicated || pool->tlsf.empty() != (pass == 1)) continue;
            if (auto allocation = from(i)) return allocation;
        }
    }
    auto index = createPool(m_desc.poolSize, false);
    if (!index) return fail();
    auto allocation = from(*index);
    SHADEL_ASSERT(allocation.has_value()); // a fresh pool holds anything up to poolSize
    return allocation;
}

void PoolSet::free(const PoolAllocation& allocation) {
    SHADEL_ASSERT(allocation.pool < m_pools.size() && m_pools[allocation.pool]);
    Pool& pool = *m_pools[allocation.pool];
    pool.tlsf.free(allocation.tlsf);
    if (!pool.tlsf.empty()) return;
    if (pool.dedicated || emptyRegularPoolCount() > m_desc.maxSpareEmptyPools)
        destroyPool(allocation.pool);
}

void PoolSet::releaseEmptyPools() {
    for (uint32_t i = 0; i < m_pools.size(); ++i)
        if (m_pools[i] && m_pools[i]->tlsf.empty()) destroyPool(i);
}

PoolSetStats PoolSet::stats() const {
    PoolSetStats stats;
    for (const auto& pool : m_pools) {
        if (!pool) continue;
        ++stats.poolCount;
        stats.poolBytes += pool->tlsf.capacity();
        TlsfStats tlsf = pool->tlsf.stats();
        stats.usedBytes += tlsf.used;
        stats.allocationCount += tlsf.allocationCount;
        stats.dedicatedPoolCount += pool->dedicated;
        stats.emptyPoolCount += tlsf.allocationCount == 0;
    }
    stats.failedAllocations = m_failedAllocations;
    return stats;
}

const Tlsf* PoolSet::pool(uint32_t poolIndex) const {
    if (poolIndex >= m_pools.size() || !m_pools[poolIndex]) return nullptr;
    return &m_pools[poolIndex]->tlsf;
}

} // namespace shadel
