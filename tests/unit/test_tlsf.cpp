#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/tlsf.h"

using namespace shadel;

namespace {

// Checks everything the allocator claims against an independent list of live allocations.
void expectConsistent(const Tlsf& tlsf, std::vector<TlsfAllocation> live) {
    ASSERT_TRUE(tlsf.validate());
    std::sort(live.begin(), live.end(),
              [](const auto& a, const auto& b) { return a.offset < b.offset; });
    uint64_t used = 0;
    for (size_t i = 0; i < live.size(); ++i) {
        ASSERT_LE(live[i].offset + live[i].size, tlsf.capacity());
        if (i > 0) {
            ASSERT_LE(live[i - 1].offset + live[i - 1].size, live[i].offset) << "overlap";
        }
        used += live[i].size;
    }
    TlsfStats stats = tlsf.stats();
    EXPECT_EQ(stats.used, used);
    EXPECT_EQ(stats.used + stats.free, stats.capacity);
    EXPECT_EQ(stats.allocationCount, live.size());
    EXPECT_LE(stats.largestFree, stats.free);
    EXPECT_GE(stats.fragmentation, 0.0);
    EXPECT_LE(stats.fragmentation, 1.0);
    if (stats.free > 0) {
        EXPECT_GT(stats.largestFree, 0u);
    }
}

} // namespace

TEST(Tlsf, AllocatesAlignedAndFreesBackToOneBlock) {
    Tlsf tlsf(1 << 20);
    auto a = tlsf.allocate(100);
    auto b = tlsf.allocate(1000, 256);
    auto c = tlsf.allocate(7, 4096);
    ASSERT_TRUE(a && b && c);
    EXPECT_EQ(b->offset % 256, 0u);
    EXPECT_EQ(c->offset % 4096, 0u);
    expectConsistent(tlsf, {*a, *b, *c});
    tlsf.free(*b);
    tlsf.free(*a);
    tlsf.free(*c);
    TlsfStats stats = tlsf.stats();
    EXPECT_EQ(stats.used, 0u);
    EXPECT_EQ(stats.largestFree, 1u << 20);
    EXPECT_EQ(stats.freeBlockCount, 1u);
    EXPECT_EQ(stats.fragmentation, 0.0);
    EXPECT_TRUE(tlsf.validate());
}

TEST(Tlsf, CoalescesBothNeighbours) {
    Tlsf tlsf(300);
    auto a = tlsf.allocate(100), b = tlsf.allocate(100), c = tlsf.allocate(100);
    ASSERT_TRUE(a && b && c);
    EXPECT_FALSE(tlsf.allocate(1));
    tlsf.free(*a);
    tlsf.free(*c);
    EXPECT_EQ(tlsf.stats().freeBlockCount, 2u);
    EXPECT_EQ(tlsf.stats().largestFree, 100u);
    EXPECT_NEAR(tlsf.stats().fragmentation, 0.5, 1e-9);
    tlsf.free(*b); // merges with both sides
    EXPECT_EQ(tlsf.stats().freeBlockCount, 1u);
    EXPECT_EQ(tlsf.stats().largestFree, 300u);
    auto whole = tlsf.allocate(300);
    ASSERT_TRUE(whole);
    EXPECT_EQ(whole->offset, 0u);
}

TEST(Tlsf, FailureIsAValue) {
    Tlsf tlsf(4096);
    EXPECT_FALSE(tlsf.allocate(0));
    EXPECT_FALSE(tlsf.allocate(4097));
    EXPECT_FALSE(tlsf.allocate(16, 3)); // not a power of two
    EXPECT_FALSE(tlsf.allocate(UINT64_MAX, 1ull << 63));
    auto all = tlsf.allocate(4096);
    ASSERT_TRUE(all);
    EXPECT_FALSE(tlsf.allocate(1));
    tlsf.free(*all);
    // Fragmented: free bytes are enough but no block is.
    std::vector<TlsfAllocation> pieces;
    for (int i = 0; i < 16; ++i) pieces.push_back(*tlsf.allocate(256));
    for (int i = 0; i < 16; i += 2) tlsf.free(pieces[i]);
    EXPECT_EQ(tlsf.stats().free, 2048u);
    EXPECT_FALSE(tlsf.allocate(512));
    EXPECT_TRUE(tlsf.allocate(256));
    Tlsf empty(0);
    EXPECT_FALSE(empty.allocate(1));
    EXPECT_TRUE(empty.validate());
}

TEST(Tlsf, AlignedRequestUsesAnAlignedBlockItAlreadyHas) {
    // The only free block that fits is exactly the aligned size; the worst-case padding search
    // alone would miss it.
    Tlsf tlsf(8192);
    auto a = tlsf.allocate(4096);
    auto b = tlsf.allocate(4096);
    ASSERT_TRUE(a && b);
    tlsf.free(*b);
    auto c = tlsf.allocate(4096, 4096);
    ASSERT_TRUE(c);
    EXPECT_EQ(c->offset, 4096u);
}

TEST(Tlsf, HugeCapacities) {
    Tlsf tlsf(1ull << 46);
    auto a = tlsf.allocate(1ull << 45, 1ull << 40);
    auto b = tlsf.allocate((1ull << 45) - 1);
    ASSERT_TRUE(a && b);
    EXPECT_FALSE(tlsf.allocate(2));
    EXPECT_TRUE(tlsf.allocate(1));
    EXPECT_TRUE(tlsf.validate());
}

// Long random sequences with fixed seeds: no overlap, all in bounds, alignment holds, the
// stats add up, and freeing everything restores the empty state.
TEST(Tlsf, RandomSequencesKeepInvariants) {
    for (uint32_t seed : {1u, 2u, 3u, 4u}) {
        std::mt19937 rng(seed);
        const uint64_t capacity = (1ull << 22) + rng() % 4096;
        Tlsf tlsf(capacity);
        std::vector<TlsfAllocation> live;
        uint32_t failures = 0;
        for (int step = 0; step < 20000; ++step) {
            bool doAllocate = live.empty() || rng() % 100 < (step < 10000 ? 60u : 40u);
            if (doAllocate) {
                uint64_t size = 1 + (rng() % (1u << (rng() % 17)));
                uint64_t alignment = 1ull << (rng() % 13);
                auto allocation = tlsf.allocate(size, alignment);
                if (!allocation) {
                    ++failures;
                    continue;
                }
                ASSERT_GE(allocation->size, size);
                ASSERT_LE(allocation->size, (size + alignment - 1) & ~(alignment - 1));
                ASSERT_EQ(allocation->offset % alignment, 0u);
                ASSERT_LE(allocation->offset + size, capacity);
                live.push_back(*allocation);
            } else {
                size_t pick = rng() % live.size();
                tlsf.free(live[pick]);
                live[pick] = live.back();
                live.pop_back();
            }
            if (step % 500 == 0) expectConsistent(tlsf, live);
        }
        expectConsistent(tlsf, live);
        EXPECT_GT(failures, 0u) << "the sequence should also reach full";
        for (const auto& allocation : live) tlsf.free(allocation);
        TlsfStats stats = tlsf.stats();
        EXPECT_EQ(stats.used, 0u);
        EXPECT_EQ(stats.largestFree, capacity);
        EXPECT_EQ(stats.freeBlockCount, 1u);
        EXPECT_TRUE(tlsf.validate());
    }
}
