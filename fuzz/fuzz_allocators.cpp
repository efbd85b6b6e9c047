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

// Fast and naive side by side: same placements, same ids, same tree, and no overlap (checked
// with a dense grid, so sheets stay small).
template <size_t N>
void fuzzBlocks(FuzzedDataProvider& in) {
    Extent<N> bounds;
    for (auto& b : bounds) b = in.ConsumeIntegralInRange<uint32_t>(0, N == 2 ? 96 : 24);
    const uint32_t alignment = 1u << in.ConsumeIntegralInRange(0, 3);
    const uint32_t maxSide = in.ConsumeIntegralInRange<uint32_t>(1, N == 2 ? 40 : 12);
    BlockAllocator<N> fast(bounds, alignment);
    NaiveBlockAllocator<N> naive(bounds, alignment);
    std::vector<Placement<N>> live;
    auto extent = [&] {
        Extent<N> e;
        for (auto& x : e) x = in.ConsumeIntegralInRange<uint32_t>(0, maxSide);
        return e;
    };
    auto same = [](const std::optional<Placement<N>>& a, const std::optional<Placement<N>>& b) {
        if (a.has_value() != b.has_value()) return false;
        return !a || (a->origin == b->origin && a->extent == b->extent && a->id == b->id);
    };
    for (int op = 0; op < kMaxOps && in.remaining_bytes() > 0; ++op) {
        switch (in.ConsumeIntegralInRange(0, 4)) {
        case 0:
        case 1: {
            Extent<N> e = extent();
            auto a = fast.insert(e);
            CHECK(same(a, naive.insert(e)));
            if (a) live.push_back(*a);
            break;
        }
        case 2: {
            std::vector<Extent<N>> batch(in.ConsumeIntegralInRange(0, 20));
            for (auto& e : batch) e = extent();
            auto a = fast.insertBatch(batch);
            auto b = naive.insertBatch(batch);
            CHECK(a.size() == batch.size());
            for (size_t i = 0; i < batch.size(); ++i) {
                CHECK(same(a[i], b[i]));
                if (a[i]) live.push_back(*a[i]);
            }
            break;
        }
        case 3: { // remove by origin; sometimes a point that is not an origin
            if (live.empty() || in.ConsumeIntegralInRange(0, 7) == 0) {
                Position<N> p;
                for (auto& x : p) x = in.ConsumeIntegralInRange<uint32_t>(0, 100);
                bool removed = fast.remove(p);
                CHECK(removed == naive.remove(p));
                if (removed) {
                    auto it = std::find_if(live.begin(), live.end(),
                                           [&](const auto& l) { return l.origin == p; });
                    CHECK(it != live.end());
                    live.erase(it);
                }
                break;
            }
            size_t pick = in.ConsumeIntegralInRange<size_t>(0, live.size() - 1);
            CHECK(fast.remove(live[pick].origin) && naive.remove(live[pick].origin));
            live.erase(live.begin() + pick);
            break;
        }
        case 4: { // remove by id, then the stale id must fail
            if (live.empty()) break;
            size_t pick = in.ConsumeIntegralInRange<size_t>(0, live.size() - 1);
            BlockId id = live[pick].id;
            CHECK(fast.remove(id) && naive.remove(id));
            CHECK(!fast.remove(id) && !naive.remove(id));
            live.erase(live.begin() + pick);
            break;
        }
        }
        CHECK(fast.size() == live.size() && naive.size() == live.size());
        CHECK(fast.usedVolume() == naive.usedVolume() && fast.nodeCount() == naive.nodeCount());
        if (op % 32 == 0) {
            CHECK(fast.validate() && naive.validate());
            CHECK(fast.preorder() == naive.preorder());
        }
    }
    CHECK(fast.validate() && naive.validate());
    CHECK(fast.preorder() == naive.preorder());
    // No overlap, all inside the usable bounds, aligned.
    Extent<N> usable;
    size_t cells = 1;
    for (size_t axis = 0; axis < N; ++axis) {
        usable[axis] = bounds[axis] / alignment * alignment;
        cells *= usable[axis];
    }
    std::vector<uint8_t> grid(cells, 0);
    uint64_t volume = 0;
    for (const auto& p : live) {
        uint64_t v = 1;
        for (size_t axis = 0; axis < N; ++axis) {
            CHECK(p.origin[axis] % alignment == 0 && p.extent[axis] % alignment == 0);
            CHECK(p.origin[axis] + p.extent[axis] <= usable[axis]);
            v *= p.extent[axis];
        }
        volume += v;
        Position<N> c = p.origin;
        while (true) {
            size_t linear = 0;
            for (size_t axis = N; axis-- > 0;) linear = linear * usable[axis] + c[axis];
            CHECK(grid[linear] == 0);
            grid[linear] = 1;
            size_t axis = 0;
            for (; axis < N; ++axis) {
                if (++c[axis] < p.origin[axis] + p.extent[axis]) break;
                c[axis] = p.origin[axis];
            }
            if (axis == N) break;
        }
    }
    CHECK(volume == fast.usedVolume());
    for (const auto& p : live) CHECK(fast.remove(p.id));
    CHECK(fast.nodeCount() == 1 && fast.usedVolume() == 0 && fast.validate());
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
