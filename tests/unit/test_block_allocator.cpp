#include <gtest/gtest.h>

#include <algorithm>
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

// Every live element of `allocator`, from its tree (preorder), for the grid check.
template <size_t N, class Allocator>
std::vector<Placement<N>> liveOf(const Allocator& allocator) {
    std::vector<Placement<N>> out;
    for (const auto& node : allocator.preorder())
        if (node.used) out.push_back(Placement<N>{node.min, node.size, node.id});
    return out;
}

// Removal is the same in both allocators whatever the layout (free the leaf, collapse the highest
// ancestor left empty). So: rebuild the naive allocator from the fast tree, remove the same
// elements from both, one at a time, and require the same tree after each removal. `victims`
// are removed by origin and by id alternately.
template <size_t N>
void expectSameRemoval(const BlockAllocator<N>& start, std::vector<Placement<N>> victims) {
    BlockAllocator<N> fast = start;
    auto tree = fast.preorder();
    auto mirror = NaiveBlockAllocator<N>::fromPreorder(fast.bounds(), fast.alignment(), tree);
    ASSERT_TRUE(mirror.validate());
    ASSERT_EQ(mirror.preorder(), tree);
    for (size_t i = 0; i < victims.size(); ++i) {
        const Placement<N>& v = victims[i];
        if (i % 2) {
            ASSERT_TRUE(fast.remove(v.origin));
            ASSERT_TRUE(mirror.remove(v.origin));
        } else {
            ASSERT_TRUE(fast.remove(v.id));
            ASSERT_TRUE(mirror.remove(v.id));
        }
        ASSERT_EQ(fast.nodeCount(), mirror.nodeCount()) << "removal " << i;
        ASSERT_EQ(fast.preorder(), mirror.preorder()) << "removal " << i;
    }
    ASSERT_TRUE(fast.validate());
}

// Runs one op sequence on the fast and the naive allocator. Their placement policies differ (the
// fast one halves free boxes, the naive one keeps UE4's cuts), so their layouts differ; what is
// asserted:
// - both layouts stay valid: validate() on each, and the dense-grid check (no overlap, inside
//   the usable bounds, origins and extents aligned) on each allocator's own elements;
// - each reserves the rounded-up request: equal extents whenever both place an element, and
//   equal size()/usedVolume() whenever they agree on success;
// - same success where capacity clearly suffices: while each allocator has at most a quarter of
//   the usable volume in use, neither may fail a request whose every side is at most a quarter
//   of the usable sheet (batched or single);
// - removal collapses identically: expectSameRemoval() on the fast tree every 250 steps;
// - freeing everything brings both back to the single root node.
// Failures (beyond that capacity) are counted for both; the fast allocator must not fail much
// more often than the naive one on the same sequence.
template <size_t N>
void runDifferential(uint32_t seed, Extent<N> bounds, uint32_t alignment, uint32_t maxSide,
                     int steps) {
    std::mt19937 rng(seed);
    BlockAllocator<N> fast(bounds, alignment);
    NaiveBlockAllocator<N> naive(bounds, alignment);
    Extent<N> usable;
    uint64_t usableVolume = 1;
    for (size_t axis = 0; axis < N; ++axis) {
        usable[axis] = bounds[axis] / alignment * alignment;
        usableVolume *= usable[axis];
    }
    // Elements are named by the order they were requested in; each allocator has its own copy.
    std::vector<Placement<N>> liveFast, liveNaive;
    std::vector<bool> inFast, inNaive;
    uint32_t failFast = 0, failNaive = 0, requests = 0;
    auto clearlyFits = [&](const Extent<N>& e, uint64_t used) {
        if (used * 4 > usableVolume) return false;
        for (size_t axis = 0; axis < N; ++axis)
            if (uint64_t(e[axis] + alignment - 1) / alignment * alignment * 4 > usable[axis])
                return false;
        return true;
    };
    auto record = [&](const Extent<N>& e, const std::optional<Placement<N>>& a,
                      const std::optional<Placement<N>>& b, uint64_t usedFast, uint64_t usedNaive,
                      int step) {
        ++requests;
        failFast += !a;
        failNaive += !b;
        if (clearlyFits(e, usedFast)) {
            ASSERT_TRUE(a) << "fast failed, step " << step;
        }
        if (clearlyFits(e, usedNaive)) {
            ASSERT_TRUE(b) << "naive failed, step " << step;
        }
        if (a && b) {
            ASSERT_EQ(a->extent, b->extent);
        }
        liveFast.push_back(a.value_or(Placement<N>{}));
        liveNaive.push_back(b.value_or(Placement<N>{}));
        inFast.push_back(a.has_value());
        inNaive.push_back(b.has_value());
    };
    std::vector<size_t> live; // requested elements at least one allocator holds
    for (int step = 0; step < steps; ++step) {
        uint32_t op = rng() % 100;
        if (live.empty() || op < 45) {
            Extent<N> extent = randomExtent<N>(rng, maxSide);
            uint64_t usedFast = fast.usedVolume(), usedNaive = naive.usedVolume();
            auto a = fast.insert(extent);
            auto b = naive.insert(extent);
            record(extent, a, b, usedFast, usedNaive, step);
            if (a || b) live.push_back(liveFast.size() - 1);
        } else if (op < 55) {
            // The fast batch against the naive one-by-one insertion. The fast batch places the
            // largest elements first, so "clearly fits" is judged with the whole batch in use.
            std::vector<Extent<N>> batch(1 + rng() % 16);
            for (auto& e : batch) e = randomExtent<N>(rng, maxSide);
            auto a = fast.insertBatch(batch);
            auto b = naive.insertBatch(batch);
            ASSERT_EQ(a.size(), batch.size());
            uint64_t usedFast = fast.usedVolume(), usedNaive = naive.usedVolume();
            for (size_t i = 0; i < batch.size(); ++i) {
                record(batch[i], a[i], b[i], usedFast, usedNaive, step);
                if (a[i] || b[i]) live.push_back(liveFast.size() - 1);
                if (a[i]) {
                    ASSERT_EQ(fast.find(a[i]->id)->origin, a[i]->origin);
                }
            }
        } else {
            size_t pick = rng() % live.size();
            size_t element = live[pick];
            bool byOrigin = rng() % 2;
            if (inFast[element]) {
                const auto& p = liveFast[element];
                ASSERT_TRUE(byOrigin ? fast.remove(p.origin) : fast.remove(p.id));
                ASSERT_FALSE(fast.remove(p.id));
                inFast[element] = false;
            }
            if (inNaive[element]) {
                const auto& p = liveNaive[element];
                ASSERT_TRUE(byOrigin ? naive.remove(p.origin) : naive.remove(p.id));
                ASSERT_FALSE(naive.remove(p.id));
                inNaive[element] = false;
            }
            live[pick] = live.back();
            live.pop_back();
        }
        size_t countFast = 0, countNaive = 0;
        for (size_t element : live) countFast += inFast[element], countNaive += inNaive[element];
        ASSERT_EQ(fast.size(), countFast);
        ASSERT_EQ(naive.size(), countNaive);
        if (step % 50 == 0) {
            ASSERT_TRUE(fast.validate()) << "step " << step;
            ASSERT_TRUE(naive.validate()) << "step " << step;
            auto a = liveOf<N>(fast), b = liveOf<N>(naive);
            expectDisjointInBounds<N>(a, usable, alignment);
            expectDisjointInBounds<N>(b, usable, alignment);
            uint64_t va = 0, vb = 0;
            for (const auto& p : a) va += volumeOf<N>(p.extent);
            for (const auto& p : b) vb += volumeOf<N>(p.extent);
            ASSERT_EQ(va, fast.usedVolume());
            ASSERT_EQ(vb, naive.usedVolume());
        }
        if (step % 250 == 0 && fast.size() > 0) {
            auto victims = liveOf<N>(fast);
            std::shuffle(victims.begin(), victims.end(), rng);
            victims.resize(std::min<size_t>(victims.size(), 24));
            expectSameRemoval<N>(fast, victims);
        }
    }
    EXPECT_GT(failNaive, 0u) << "the sequence should also reach full";
    // Fragmentation: the halving policy may fail a little more often near full, not much more.
    EXPECT_LE(failFast, failNaive + requests / 50) << failFast << " vs " << failNaive;
    // Freeing everything restores the empty state in both.
    expectSameRemoval<N>(fast, liveOf<N>(fast));
    for (size_t element : live) {
        if (inFast[element]) {
            ASSERT_TRUE(fast.remove(liveFast[element].id));
        }
        if (inNaive[element]) {
            ASSERT_TRUE(naive.remove(liveNaive[element].origin));
        }
    }
    EXPECT_EQ(fast.nodeCount(), 1u);
    EXPECT_EQ(naive.nodeCount(), 1u);
    EXPECT_EQ(fast.usedVolume(), 0u);
    EXPECT_EQ(naive.usedVolume(), 0u);
    EXPECT_TRUE(fast.insert(usable).has_value());
    EXPECT_TRUE(naive.insert(usable).has_value());
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

TEST(BlockAllocator, ValidAgainstNaive2D) {
    runDifferential<2>(31, {128, 128}, 1, 20, 3000);
    runDifferential<2>(32, {200, 90}, 4, 30, 3000);
    runDifferential<2>(33, {64, 64}, 1, 4, 3000);     // many small elements, deep trees
    runDifferential<2>(34, {448, 1024}, 1, 64, 3000); // the shadel sheet's widest region
}

TEST(BlockAllocator, ValidAgainstNaive3D) {
    runDifferential<3>(41, {32, 32, 32}, 1, 12, 2500);
    runDifferential<3>(42, {64, 32, 16}, 4, 20, 2500);
}
