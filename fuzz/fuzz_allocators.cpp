// libFuzzer target: the input is read as a sequence of allocator operations. Every invariant the
// unit tests check is checked here too; a violation aborts, which libFuzzer reports as a crash.
#include <fuzzer/FuzzedDataProvider.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "core/block_allocator.h"
#include "core/block_allocator_naive.h"
#include "core/tlsf.h"

using namespace shadel;

namespace {

constexpr int kMaxOps = 3000;

[[noreturn]] void violated(const char* what) {
    std::fprintf(stderr, "allocator invariant violated: %s\n", what);
    std::abort();
}
#define CHECK(cond)                                                                                \
    do {                                                                                           \
        if (!(cond)) violated(#cond);                                                              \
    } while (0)

void fuzzTlsf(FuzzedDataProvider& in) {
    const uint64_t capacity = in.ConsumeIntegralInRange<uint64_t>(0, 1ull << 40);
    Tlsf tlsf(capacity);
    std::vector<TlsfAllocation> live;
    for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
        if (live.empty() || in.ConsumeBool()) {
            uint64_t size = in.ConsumeBool() ? in.ConsumeIntegralInRange<uint64_t>(0, 4096)
                                             : in.ConsumeIntegral<uint64_t>() >>
                                                   in.ConsumeIntegralInRange(0, 63);
            uint64_t alignment = uint64_t(1) << in.ConsumeIntegralInRange(0, 20);
            if (in.ConsumeIntegralInRange(0, 15) == 0) alignment = in.ConsumeIntegral<uint16_t>();
            auto allocation = tlsf.allocate(size, alignment);
            if (!allocation) continue;
            CHECK(size > 0 && alignment > 0 && (alignment & (alignment - 1)) == 0);
            CHECK(allocation->offset % alignment == 0);
            CHECK(allocation->size >= size);
            CHECK(allocation->offset + allocation->size <= capacity);
            live.push_back(*allocation);
        } else {
            size_t pick = in.ConsumeIntegralInRange<size_t>(0, live.size() - 1);
            tlsf.free(live[pick]);
            live[pick] = live.back();
            live.pop_back();
        }
        if (op % 16 == 0) CHECK(tlsf.validate());
    }
    CHECK(tlsf.validate());
    std::sort(live.begin(), live.end(),
              [](const auto& a, const auto& b) { return a.offset < b.offset; });
    uint64_t used = 0;
    for (size_t i = 0; i < live.size(); ++i) {
        if (i > 0) CHECK(live[i - 1].offset + live[i - 1].size <= live[i].offset);
        used += live[i].size;
    }
    TlsfStats stats = tlsf.stats();
    CHECK(stats.used == used && stats.used + stats.free == capacity);
    CHECK(stats.largestFree <= stats.free);
    for (const auto& allocation : live) tlsf.free(allocation);
    CHECK(tlsf.validate());
    CHECK(tlsf.stats().used == 0 && tlsf.stats().largestFree == capacity);
}

// Checks the layout of one allocator: no overlap (with a dense grid, so sheets stay small), all
// inside the usable bounds, aligned, and the used volume adds up.
template <size_t N, class Allocator>
void checkLayout(const Allocator& allocator, const Extent<N>& usable, uint32_t alignment) {
    CHECK(allocator.validate());
    size_t cells = 1;
    for (uint32_t u : usable) cells *= u;
    std::vector<uint8_t> grid(cells, 0);
    uint64_t volume = 0;
    size_t count = 0;
    for (const auto& node : allocator.preorder()) {
        if (!node.used) continue;
        ++count;
        uint64_t v = 1;
        for (size_t axis = 0; axis < N; ++axis) {
            CHECK(node.min[axis] % alignment == 0 && node.size[axis] % alignment == 0);
            CHECK(node.size[axis] > 0 && node.min[axis] + node.size[axis] <= usable[axis]);
            v *= node.size[axis];
        }
        volume += v;
        Position<N> c = node.min;
        while (true) {
            size_t linear = 0;
            for (size_t axis = N; axis-- > 0;) linear = linear * usable[axis] + c[axis];
            CHECK(grid[linear] == 0);
            grid[linear] = 1;
            size_t axis = 0;
            for (; axis < N; ++axis) {
                if (++c[axis] < node.min[axis] + node.size[axis]) break;
                c[axis] = node.min[axis];
            }
            if (axis == N) break;
        }
    }
    CHECK(volume == allocator.usedVolume() && count == allocator.size());
}

// Fast and naive side by side on the same operations. Their placement policies differ, so each
// keeps its own copy of every element; checked: valid layouts on both (checkLayout), the same
// reserved extent when both place an element, each fails exactly when no free leaf of its own
// tree can hold the element, removal by a point that is no origin fails, stale ids fail, and at the
// end removal collapses the same way in both (the naive allocator rebuilt from the fast tree, the
// same removals, the same tree after each) down to the empty root.
template <size_t N>
void fuzzBlocks(FuzzedDataProvider& in) {
    Extent<N> bounds;
    for (auto& b : bounds) b = in.ConsumeIntegralInRange<uint32_t>(0, N == 2 ? 96 : 24);
    const uint32_t alignment = 1u << in.ConsumeIntegralInRange(0, 3);
    const uint32_t maxSide = in.ConsumeIntegralInRange<uint32_t>(1, N == 2 ? 40 : 12);
    BlockAllocator<N> fast(bounds, alignment);
    NaiveBlockAllocator<N> naive(bounds, alignment);
    Extent<N> usable;
    for (size_t axis = 0; axis < N; ++axis) usable[axis] = bounds[axis] / alignment * alignment;
    struct Element {
        std::optional<Placement<N>> fast, naive;
    };
    std::vector<Element> live; // held by at least one of the two
    auto extent = [&] {
        Extent<N> e;
        for (auto& x : e) x = in.ConsumeIntegralInRange<uint32_t>(0, maxSide);
        return e;
    };
    // The allocator's contract: insertion fails only when no free leaf of its tree can hold the
    // request (rounded up to the alignment). Nothing stronger holds in general: a halving
    // guillotine can be fragmented at low fill (eight 6^3 elements, one per 10^3 octant of a
    // 20^3 sheet, fill 22%, leave no room for a 5^3 one in any layout), so the check is against
    // the tree, not against the used volume.
    auto freeLeafHolds = [&](const auto& allocator, const Extent<N>& e) {
        Extent<N> rounded;
        for (size_t axis = 0; axis < N; ++axis) {
            if (e[axis] == 0) return false;
            rounded[axis] = (e[axis] + alignment - 1) / alignment * alignment;
        }
        for (const auto& node : allocator.preorder())
            if (node.leaf && !node.used && block_detail::fitsIn<N>(rounded, node.size)) return true;
        return false;
    };
    // `fitBefore*`: whether a free leaf held the element when it was tried (single inserts), or
    // nullopt for a batch, where only the tree after the whole batch is known: free leaves only
    // shrink while a batch is placed, so an element that failed holds in none of them either.
    auto keep = [&](const Extent<N>& e, const std::optional<Placement<N>>& a,
                    const std::optional<Placement<N>>& b, std::optional<bool> fitBeforeFast,
                    std::optional<bool> fitBeforeNaive) {
        if (fitBeforeFast)
            CHECK(a.has_value() == *fitBeforeFast);
        else if (!a)
            CHECK(!freeLeafHolds(fast, e));
        if (fitBeforeNaive)
            CHECK(b.has_value() == *fitBeforeNaive);
        else if (!b)
            CHECK(!freeLeafHolds(naive, e));
        if (a && b) CHECK(a->extent == b->extent);
        if (a || b) live.push_back(Element{a, b});
    };
    auto removeFrom = [&](auto& allocator, std::optional<Placement<N>>& p, bool byId) {
        if (!p) return;
        CHECK(byId ? allocator.remove(p->id) : allocator.remove(p->origin));
        CHECK(!allocator.remove(p->id));
        p.reset();
    };
    for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
        switch (in.ConsumeIntegralInRange(0, 4)) {
        case 0:
        case 1: {
            Extent<N> e = extent();
            bool fitFast = freeLeafHolds(fast, e), fitNaive = freeLeafHolds(naive, e);
            auto a = fast.insert(e);
            keep(e, a, naive.insert(e), fitFast, fitNaive);
            break;
        }
        case 2: {
            std::vector<Extent<N>> batch(in.ConsumeIntegralInRange(0, 20));
            for (auto& e : batch) e = extent();
            auto a = fast.insertBatch(batch);
            auto b = naive.insertBatch(batch);
            CHECK(a.size() == batch.size() && b.size() == batch.size());
            // The batch is placed in its own order (largest first); a failed element is judged
            // against the tree the whole batch left.
            for (size_t i = 0; i < batch.size(); ++i) {
                if (a[i]) CHECK(fast.find(a[i]->id)->origin == a[i]->origin);
                keep(batch[i], a[i], b[i], std::nullopt, std::nullopt);
            }
            break;
        }
        case 3: { // a point: removes exactly when it is the origin of an element
            Position<N> p;
            for (auto& x : p) x = in.ConsumeIntegralInRange<uint32_t>(0, 100);
            auto at = [&](auto member) {
                return std::find_if(live.begin(), live.end(), [&](const Element& l) {
                    return (l.*member) && (l.*member)->origin == p;
                });
            };
            auto f = at(&Element::fast);
            CHECK(fast.remove(p) == (f != live.end()));
            if (f != live.end()) f->fast.reset();
            auto n = at(&Element::naive);
            CHECK(naive.remove(p) == (n != live.end()));
            if (n != live.end()) n->naive.reset();
            std::erase_if(live, [](const Element& l) { return !l.fast && !l.naive; });
            break;
        }
        case 4: { // remove an element from both, by id or by origin; the stale id must fail
            if (live.empty()) break;
            size_t pick = in.ConsumeIntegralInRange<size_t>(0, live.size() - 1);
            bool byId = in.ConsumeBool();
            removeFrom(fast, live[pick].fast, byId);
            removeFrom(naive, live[pick].naive, byId);
            live.erase(live.begin() + ptrdiff_t(pick));
            break;
        }
        }
        size_t inFast = 0, inNaive = 0;
        for (const auto& l : live) inFast += l.fast.has_value(), inNaive += l.naive.has_value();
        CHECK(fast.size() == inFast && naive.size() == inNaive);
        if (op % 32 == 0) {
            checkLayout<N>(fast, usable, alignment);
            checkLayout<N>(naive, usable, alignment);
        }
    }
    checkLayout<N>(fast, usable, alignment);
    checkLayout<N>(naive, usable, alignment);
    // Removal collapses the same way in both, whatever the layout.
    auto tree = fast.preorder();
    auto mirror = NaiveBlockAllocator<N>::fromPreorder(bounds, alignment, tree);
    CHECK(mirror.validate() && mirror.preorder() == tree);
    for (const auto& l : live) {
        if (!l.fast) continue;
        CHECK(fast.remove(l.fast->id) && mirror.remove(l.fast->origin));
        CHECK(fast.nodeCount() == mirror.nodeCount() && fast.preorder() == mirror.preorder());
    }
    CHECK(fast.nodeCount() == 1 && fast.usedVolume() == 0 && fast.validate());
    for (const auto& l : live)
        if (l.naive) CHECK(naive.remove(l.naive->id));
    CHECK(naive.nodeCount() == 1 && naive.usedVolume() == 0 && naive.validate());
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    FuzzedDataProvider in(data, size);
    switch (in.ConsumeIntegralInRange(0, 2)) {
    case 0:
        fuzzTlsf(in);
        break;
    case 1:
        fuzzBlocks<2>(in);
        break;
    case 2:
        fuzzBlocks<3>(in);
        break;
    }
    return 0;
}
