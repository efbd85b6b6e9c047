#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include "core/gpu_pools.h"

using namespace shadel;

namespace {

constexpr uint64_t kMiB = 1ull << 20;

// Plays the Vulkan heap: records which pools exist and counts the callback calls.
struct FakeBacking {
    std::map<uint32_t, uint64_t> pools; // pool index -> size
    uint32_t creates = 0;
    uint32_t destroys = 0;
    bool failCreate = false;

    PoolCallbacks callbacks() {
        PoolCallbacks callbacks;
        callbacks.create = [this](uint32_t index, uint64_t size) {
            if (failCreate) return false;
            EXPECT_EQ(pools.count(index), 0u) << "pool index reused while alive";
            pools[index] = size;
            ++creates;
            return true;
        };
        callbacks.destroy = [this](uint32_t index) {
            EXPECT_EQ(pools.count(index), 1u) << "destroying a pool that does not exist";
            pools.erase(index);
            ++destroys;
        };
        return callbacks;
    }
};

PoolSetDesc smallDesc(uint32_t maxPools) {
    PoolSetDesc desc;
    desc.poolSize = 1 * kMiB;
    desc.maxPools = maxPools;
    return desc;
}

} // namespace

TEST(PoolSet, DefaultsMatchTheSeed) {
    PoolSetDesc desc;
    EXPECT_EQ(desc.poolSize, 128 * kMiB);
    EXPECT_EQ(desc.maxSpareEmptyPools, 1u);
}

TEST(PoolSet, CreatesPoolsOnDemandUpToTheLimit) {
    FakeBacking backing;
    PoolSet pools(smallDesc(3), backing.callbacks());
    EXPECT_EQ(backing.creates, 0u) << "no pool before the first allocation";
    std::vector<PoolAllocation> live;
    for (int i = 0; i < 3; ++i) {
        auto allocation = pools.allocate(600 * 1024, 256);
        ASSERT_TRUE(allocation) << i;
        EXPECT_EQ(allocation->offset % 256, 0u);
        EXPECT_EQ(backing.pools.at(allocation->pool), 1 * kMiB);
        live.push_back(*allocation);
    }
    EXPECT_EQ(backing.creates, 3u);
    // Three pools hold one 600 KiB allocation each; a fourth pool is over the limit.
    auto denied = pools.allocate(600 * 1024);
    EXPECT_FALSE(denied);
    EXPECT_EQ(pools.stats().failedAllocations, 1u);
    EXPECT_EQ(backing.creates, 3u);
    // But the remaining space in existing pools is still used.
    auto small = pools.allocate(300 * 1024);
    ASSERT_TRUE(small);
    EXPECT_EQ(backing.creates, 3u);
    PoolSetStats stats = pools.stats();
    EXPECT_EQ(stats.poolCount, 3u);
    EXPECT_EQ(stats.poolBytes, 3 * kMiB);
    EXPECT_EQ(stats.usedBytes, 3 * 600 * 1024 + 300 * 1024u);
    EXPECT_EQ(stats.allocationCount, 4u);
}

TEST(PoolSet, ReleasesEmptyPoolsKeepingOneSpare) {
    FakeBacking backing;
    PoolSet pools(smallDesc(8), backing.callbacks());
    std::vector<PoolAllocation> live;
    for (int i = 0; i < 4; ++i) live.push_back(*pools.allocate(1 * kMiB));
    EXPECT_EQ(backing.creates, 4u);
    pools.free(live[0]);
    EXPECT_EQ(backing.destroys, 0u) << "the first empty pool is kept as a spare";
    pools.free(live[1]);
    EXPECT_EQ(backing.destroys, 1u);
    pools.free(live[2]);
    EXPECT_EQ(backing.destroys, 2u);
    EXPECT_EQ(pools.stats().poolCount, 2u);
    EXPECT_EQ(pools.stats().emptyPoolCount, 1u);
    // The spare is reused instead of creating a pool.
    auto again = pools.allocate(1 * kMiB);
    ASSERT_TRUE(again);
    EXPECT_EQ(backing.creates, 4u);
    pools.releaseEmptyPools();
    EXPECT_EQ(pools.stats().poolCount, 2u);
    pools.free(*again);
    pools.free(live[3]);
    pools.releaseEmptyPools();
    EXPECT_EQ(pools.stats().poolCount, 0u);
    EXPECT_EQ(backing.creates, backing.destroys);
    EXPECT_TRUE(backing.pools.empty());
}

TEST(PoolSet, OversizedAllocationGetsADedicatedPool) {
    FakeBacking backing;
    PoolSet pools(smallDesc(2), backing.callbacks());
    auto regular = pools.allocate(1000);
    ASSERT_TRUE(regular);
    auto big = pools.allocate(5 * kMiB + 3, 4096);
    ASSERT_TRUE(big);
    EXPECT_NE(big->pool, regular->pool);
    EXPECT_EQ(big->offset, 0u);
    EXPECT_EQ(backing.pools.at(big->pool), 5 * kMiB + 3);
    EXPECT_EQ(pools.stats().dedicatedPoolCount, 1u);
    // The limit counts dedicated pools too.
    EXPECT_FALSE(pools.allocate(2 * kMiB));
    // Nothing else goes into a dedicated pool, and it goes away as soon as it is free.
    pools.free(*big);
    EXPECT_EQ(backing.pools.count(big->pool), 0u);
    EXPECT_EQ(pools.stats().dedicatedPoolCount, 0u);
}

TEST(PoolSet, DedicatedAllocationAtTheLimitEvictsTheSpare) {
    FakeBacking backing;
    PoolSet pools(smallDesc(2), backing.callbacks());
    auto a = pools.allocate(800 * 1024);
    auto b = pools.allocate(800 * 1024);
    ASSERT_TRUE(a && b);
    pools.free(*b); // pool of b stays as the spare
    EXPECT_EQ(pools.stats().poolCount, 2u);
    auto big = pools.allocate(3 * kMiB);
    ASSERT_TRUE(big);
    EXPECT_EQ(backing.destroys, 1u);
    EXPECT_EQ(pools.stats().poolCount, 2u);
}

TEST(PoolSet, FailedCreateFailsTheAllocationCleanly) {
    FakeBacking backing;
    backing.failCreate = true;
    PoolSet pools(smallDesc(4), backing.callbacks());
    EXPECT_FALSE(pools.allocate(16));
    EXPECT_FALSE(pools.allocate(4 * kMiB));
    EXPECT_EQ(pools.stats().poolCount, 0u);
    EXPECT_EQ(pools.stats().failedAllocations, 2u);
    backing.failCreate = false;
    auto allocation = pools.allocate(16);
    ASSERT_TRUE(allocation);
    EXPECT_EQ(allocation->pool, 0u);
    EXPECT_FALSE(pools.allocate(0));
    EXPECT_FALSE(pools.allocate(16, 24));
}

TEST(PoolSet, DestructorReleasesEveryPool) {
    FakeBacking backing;
    {
        PoolSet pools(smallDesc(4), backing.callbacks());
        ASSERT_TRUE(pools.allocate(900 * 1024));
        ASSERT_TRUE(pools.allocate(900 * 1024));
        ASSERT_TRUE(pools.allocate(9 * kMiB));
    }
    EXPECT_EQ(backing.creates, 3u);
    EXPECT_EQ(backing.destroys, 3u);
    EXPECT_TRUE(backing.pools.empty());
}

TEST(PoolSet, RandomSequencesKeepInvariants) {
    std::mt19937 rng(7);
    FakeBacking backing;
    PoolSetDesc desc = smallDesc(6);
    PoolSet pools(desc, backing.callbacks());
    std::vector<PoolAllocation> live;
    uint32_t failures = 0;
    for (int step = 0; step < 20000; ++step) {
        if (live.empty() || rng() % 100 < 55) {
            uint64_t size = 1 + rng() % (rng() % 50 == 0 ? 3 * kMiB : 200 * 1024);
            uint64_t alignment = 1ull << (rng() % 12);
            auto allocation = pools.allocate(size, alignment);
            if (!allocation) {
                ++failures;
                continue;
            }
            ASSERT_EQ(allocation->offset % alignment, 0u);
            ASSERT_LE(allocation->offset + size, backing.pools.at(allocation->pool));
            live.push_back(*allocation);
        } else {
            size_t pick = rng() % live.size();
            pools.free(live[pick]);
            live[pick] = live.back();
            live.pop_back();
        }
        PoolSetStats stats = pools.stats();
        ASSERT_LE(stats.poolCount, desc.maxPools);
        ASSERT_LE(stats.emptyPoolCount, desc.maxSpareEmptyPools);
        ASSERT_EQ(stats.poolCount, backing.pools.size());
        ASSERT_EQ(stats.allocationCount, live.size());
        if (step % 1000 == 0) {
            // No overlap inside any pool.
            auto sorted = live;
            std::sort(sorted.begin(), sorted.end(), [](const auto& a, const auto& b) {
                return std::tie(a.pool, a.offset) < std::tie(b.pool, b.offset);
            });
            for (size_t i = 1; i < sorted.size(); ++i) {
                if (sorted[i].pool == sorted[i - 1].pool) {
                    ASSERT_LE(sorted[i - 1].offset + sorted[i - 1].size, sorted[i].offset);
                }
            }
            for (const auto& [index, size] : backing.pools) {
                ASSERT_NE(pools.pool(index), nullptr);
                ASSERT_TRUE(pools.pool(index)->validate());
            }
        }
    }
    EXPECT_GT(failures, 0u);
    for (const auto& allocation : live) pools.free(allocation);
    EXPECT_EQ(pools.stats().usedBytes, 0u);
    EXPECT_LE(pools.stats().poolCount, 1u);
}
