#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/block_allocator.h"
#include "core/block_allocator_naive.h"

using namespace shadel;

namespace {

// Marks every live element in a dense grid: catches overlap and out-of-bounds placements
// independently of the allocator's own bookkeeping.
template <size_t N>
void expectDisjointInBounds(const std::vector<Placement<N>>& live, const Extent<N>& bounds,
                            uint32_t alignment) {
    uint64_t cells = 1;
    for (uint32_t b : bounds) cells *= b;
    std::vector<uint8_t> grid(cells, 0);
    for (const auto& p : live) {
        for (size_t axis = 0; axis < N; ++axis) {
            ASSERT_EQ(p.origin[axis] % alignment, 0u);
            ASSERT_EQ(p.extent[axis] % alignment, 0u);
            ASSERT_LE(uint64_t(p.origin[axis]) + p.extent[axis], bounds[axis]);
        }
        Position<N> cell = p.origin;
        while (true) {
            uint64_t linear = 0;
            for (size_t axis = N; axis-- > 0;) linear = linear * bounds[axis] + cell[axis];
            ASSERT_EQ(grid[linear], 0) << "two elements overlap";
            grid[linear] = 1;
            size_t axis = 0;
            for (; axis < N; ++axis) {
                if (++cell[axis] < p.origin[axis] + p.extent[axis]) break;
                cell[axis] = p.origin[axis];
            }
            if (axis == N) break;
        }
    }
}

template <size_t N>
Extent<N> randomExtent(std::mt19937& rng, uint32_t maxSide) {
    Extent<N> extent;
    for (auto& e : extent) e = 1 + rng() % maxSide;
    return extent;
}

template <size_t N>
uint64_t volumeOf(const Extent<N>& e) {
    uint64_t v = 1;
    for (uint32_t x : e) v *= x;
    return v;
}

// Random inserts, batches and removals (by position and by id) with all invariants checked.
template <size_t N>
void runRandomSequence(uint32_t seed, Extent<N> bounds, uint32_t alignment, uint32_t maxSide,
                       int steps) {
    std::mt19937 rng(seed);
    BlockAllocator<N> allocator(bounds, alignment);
    Extent<N> usable;
    for (size_t axis = 0; axis < N; ++axis) usable[axis] = bounds[axis] / alignment * alignment;
    std::vector<Placement<N>> live;
    uint64_t volume = 0;
    uint32_t failures = 0;
    auto keep = [&](const std::optional<Placement<N>>& placement, const Extent<N>& asked) {
        if (!placement) {
            ++failures;
            return;
        }
        for (size_t axis = 0; axis < N; ++axis) ASSERT_GE(placement->extent[axis], asked[axis]);
        ASSERT_EQ(allocator.find(placement->id)->origin, placement->origin);
        live.push_back(*placement);
        volume += volumeOf<N>(placement->extent);
    };
    for (int step = 0; step < steps; ++step) {
        uint32_t op = rng() % 100;
        uint32_t insertShare = step < steps / 2 ? 60 : 45;
        if (live.empty() || op < insertShare - 10) {
            Extent<N> extent = randomExtent<N>(rng, maxSide);
            keep(allocator.insert(extent), extent);
        } else if (op < insertShare) {
            std::vector<Extent<N>> batch(1 + rng() % 12);
            for (auto& e : batch) e = randomExtent<N>(rng, maxSide);
            auto placements = allocator.insertBatch(batch);
            ASSERT_EQ(placements.size(), batch.size());
            for (size_t i = 0; i < batch.size(); ++i) keep(placements[i], batch[i]);
        } else {
            size_t pick = rng() % live.size();
            Placement<N> victim = live[pick];
            bool byId = rng() % 2;
            ASSERT_TRUE(byId ? allocator.remove(victim.id) : allocator.remove(victim.origin));
            ASSERT_FALSE(allocator.remove(victim.id)) << "stale id must not remove anything";
            ASSERT_FALSE(allocator.find(victim.id));
            volume -= volumeOf<N>(victim.extent);
            live[pick] = live.back();
            live.pop_back();
        }
        ASSERT_EQ(allocator.size(), live.size());
        ASSERT_EQ(allocator.usedVolume(), volume);
        if (step % 97 == 0) {
            ASSERT_TRUE(allocator.validate()) << "step " << step;
            expectDisjointInBounds<N>(live, usable, alignment);
        }
    }
    ASSERT_TRUE(allocator.validate());
    expectDisjointInBounds<N>(live, usable, alignment);
    EXPECT_GT(failures, 0u) << "the sequence should also reach full";
    for (const auto& p : live) ASSERT_TRUE(allocator.remove(p.origin));
    EXPECT_EQ(allocator.size(), 0u);
    EXPECT_EQ(allocator.usedVolume(), 0u);
    EXPECT_EQ(allocator.nodeCount(), 1u) << "freeing everything collapses the tree to the root";
    EXPECT_TRUE(allocator.validate());
    auto whole = allocator.insert(usable);
    ASSERT_TRUE(whole);
    EXPECT_EQ(whole->origin, Position<N>{});
}

// Runs one op sequence on the fast and the naive allocator; both must make the same
// placements, hand out the same ids and hold the same tree.
template <size_t N>
void runDifferential(uint32_t seed, Extent<N> bounds, uint32_t alignment, uint32_t maxSide,
                     int steps) {
    std::mt19937 rng(seed);
    BlockAllocator<N> fast(bounds, alignment);
    NaiveBlockAllocator<N> naive(bounds, alignment);
    std::vector<Placement<N>> live;
    for (int step = 0; step < steps; ++step) {
        uint32_t op = rng() % 100;
        if (live.empty() || op < 45) {
            Extent<N> extent = randomExtent<N>(rng, maxSide);
            auto a = fast.insert(extent);
            auto b = naive.insert(extent);
            ASSERT_EQ(a.has_value(), b.has_value()) << "step " << step;
            if (a) {
                ASSERT_EQ(a->origin, b->origin) << "step " << step;
                ASSERT_EQ(a->extent, b->extent);
                ASSERT_EQ(a->id, b->id);
                live.push_back(*a);
            }
        } else if (op < 55) {
            // The fast batch against the naive one-by-one insertion.
            std::vector<Extent<N>> batch(1 + rng() % 16);
            for (auto& e : batch) e = randomExtent<N>(rng, maxSide);
            auto a = fast.insertBatch(batch);
            auto b = naive.insertBatch(batch);
            for (size_t i = 0; i < batch.size(); ++i) {
                ASSERT_EQ(a[i].has_value(), b[i].has_value()) << "step " << step << " #" << i;
                if (!a[i]) continue;
                ASSERT_EQ(a[i]->origin, b[i]->origin) << "step " << step << " #" << i;
                ASSERT_EQ(a[i]->id, b[i]->id);
                live.push_back(*a[i]);
            }
        } else {
            size_t pick = rng() % live.size();
            if (rng() % 2) {
                ASSERT_TRUE(fast.remove(live[pick].origin));
                ASSERT_TRUE(naive.remove(live[pick].origin));
            } else {
                ASSERT_TRUE(fast.remove(live[pick].id));
                ASSERT_TRUE(naive.remove(live[pick].id));
            }
            live[pick] = live.back();
            live.pop_back();
        }
        ASSERT_EQ(fast.size(), naive.size());
        ASSERT_EQ(fast.usedVolume(), naive.usedVolume());
        ASSERT_EQ(fast.nodeCount(), naive.nodeCount());
        if (step % 50 == 0) {
            ASSERT_TRUE(fast.validate());
            ASSERT_TRUE(naive.validate());
            ASSERT_EQ(fast.preorder(), naive.preorder()) << "step " << step;
        }
    }
    ASSERT_EQ(fast.preorder(), naive.preorder());
    // The naive allocator rebuilt from the fast tree is the same tree and keeps working.
    auto tree = fast.preorder();
    auto rebuilt = NaiveBlockAllocator<N>::fromPreorder(bounds, alignment, tree);
    ASSERT_TRUE(rebuilt.validate());
    ASSERT_EQ(rebuilt.preorder(), tree);
    for (const auto& p : live) ASSERT_TRUE(rebuilt.remove(p.id));
    EXPECT_EQ(rebuilt.nodeCount(), 1u);
}

} // namespace

TEST(BlockAllocator, FillsExactlyAndCollapsesBack) {
    BlockAllocator2D allocator({16, 16});
    std::vector<Placement<2>> placed;
    for (int i = 0; i < 16; ++i) {
        auto p = allocator.insert({4, 4});
        ASSERT_TRUE(p) << i;
        placed.push_back(*p);
    }
    EXPECT_FALSE(allocator.insert({1, 1}));
    EXPECT_EQ(allocator.usedVolume(), 256u);
    EXPECT_TRUE(allocator.validate());
    expectDisjointInBounds<2>(placed, {16, 16}, 1);
    for (const auto& p : placed) ASSERT_TRUE(allocator.remove(p.origin));
    EXPECT_EQ(allocator.nodeCount(), 1u);
    EXPECT_TRUE(allocator.insert({16, 16}));
}

TEST(BlockAllocator, FirstPlacementIsAtTheOrigin) {
    BlockAllocator3D allocator({64, 64, 64});
    auto p = allocator.insert({10, 20, 30});
    ASSERT_TRUE(p);
    EXPECT_EQ(p->origin, (Position<3>{0, 0, 0}));
    EXPECT_EQ(p->extent, (Extent<3>{10, 20, 30}));
    EXPECT_EQ(allocator.bounds(), (Extent<3>{64, 64, 64}));
}

TEST(BlockAllocator, AlignmentRoundsExtentsAndOrigins) {
    BlockAllocator2D allocator({130, 130}, 64); // usable area 128 x 128
    auto a = allocator.insert({1, 1});
    auto b = allocator.insert({3, 65});
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->extent, (Extent<2>{64, 64}));
    EXPECT_EQ(b->extent, (Extent<2>{64, 128}));
    EXPECT_EQ(b->origin, (Position<2>{64, 0}));
    EXPECT_FALSE(allocator.insert({129, 1}));
    EXPECT_EQ(allocator.usedVolume(), 64u * 64 + 64 * 128);
}

TEST(BlockAllocator, FailureIsAValue) {
    BlockAllocator2D allocator({32, 32});
    EXPECT_FALSE(allocator.insert({0, 4}));
    EXPECT_FALSE(allocator.insert({33, 1}));
    EXPECT_FALSE(allocator.remove(Position<2>{3, 3}));
    EXPECT_FALSE(allocator.remove(Position<2>{100, 0}));
    EXPECT_FALSE(allocator.remove(BlockId{}));
    EXPECT_FALSE(allocator.remove(BlockId{12345, 0}));
    auto p = allocator.insert({8, 8});
    ASSERT_TRUE(p);
    EXPECT_FALSE(allocator.remove(Position<2>{1, 0})) << "inside an element is not its origin";
    auto batch = allocator.insertBatch(std::vector<Extent<2>>{{0, 1}, {40, 40}, {8, 8}});
    EXPECT_FALSE(batch[0]);
    EXPECT_FALSE(batch[1]);
    EXPECT_TRUE(batch[2]);
    BlockAllocator2D tiny({3, 3}, 4); // smaller than one aligned block
    EXPECT_FALSE(tiny.insert({1, 1}));
    EXPECT_TRUE(tiny.validate());
}

TEST(BlockAllocator, ClearInvalidatesIds) {
    BlockAllocator2D allocator({64, 64});
    auto p = allocator.insert({8, 8});
    ASSERT_TRUE(p);
    allocator.clear();
    EXPECT_EQ(allocator.size(), 0u);
    EXPECT_FALSE(allocator.remove(p->id));
    auto q = allocator.insert({8, 8});
    ASSERT_TRUE(q);
    EXPECT_EQ(q->id.slot, p->id.slot);
    EXPECT_NE(q->id, p->id);
    EXPECT_TRUE(allocator.validate());
}

TEST(BlockAllocator, RandomSequences2D) {
    runRandomSequence<2>(11, {128, 128}, 1, 24, 6000);
    runRandomSequence<2>(12, {100, 150}, 1, 9, 6000);
    runRandomSequence<2>(13, {256, 256}, 4, 40, 4000);
    runRandomSequence<2>(14, {1024, 512}, 64, 200, 3000);
}

TEST(BlockAllocator, RandomSequences3D) {
    runRandomSequence<3>(21, {32, 32, 32}, 1, 10, 5000);
    runRandomSequence<3>(22, {40, 24, 64}, 4, 16, 4000);
}

TEST(BlockAllocator, SameLayoutAsNaive2D) {
    runDifferential<2>(31, {128, 128}, 1, 20, 3000);
    runDifferential<2>(32, {200, 90}, 4, 30, 3000);
    runDifferential<2>(33, {64, 64}, 1, 4, 3000); // many small elements, deep trees
}

TEST(BlockAllocator, SameLayoutAsNaive3D) {
    runDifferential<3>(41, {32, 32, 32}, 1, 12, 2500);
    runDifferential<3>(42, {64, 32, 16}, 4, 20, 2500);
}
