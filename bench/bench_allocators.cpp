// Allocator benchmarks: the block allocator against the naive baseline it replaces,
// and TLSF against a first-fit free list and malloc/free. Every benchmark reports the time of one
// operation (median of the repetitions); the table at the end divides them within this run.
//
//   shadel_bench_allocators            all benchmarks and the ratio table (about a minute)
//   shadel_bench_allocators --benchmark_filter=tlsf   any Google Benchmark flag works too
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/block_allocator.h"
#include "core/block_allocator_naive.h"
#include "core/tlsf.h"

using namespace shadel;

namespace {

using Clock = std::chrono::steady_clock;

// --- Block allocator ---------------------------------------------------------------------------

// A 2048 x 2048-block sheet with elements of 1..8 blocks per side: 50k live elements fill about
// a sixth of it, so every size level has room to insert.
constexpr Extent<2> kSheet{2048, 2048};
constexpr uint32_t kOpsPerIteration = 64; // removals / insertions timed per iteration
constexpr uint32_t kLiveCounts[] = {1000, 10000, 50000};

Extent<2> randomExtent(std::mt19937& rng) {
    return {uint32_t(1 + rng() % 8), uint32_t(1 + rng() % 8)};
}

// The starting layout for one live count: the same insertion sequence given to each allocator,
// so each starts from the layout it makes itself (the fast allocator halves free boxes, the naive
// one keeps UE4's placement, so the trees differ; nodeCount is printed with the table). Building
// the naive layout for 50k elements at naive speed takes a few seconds, once per run.
struct Layout {
    std::unique_ptr<BlockAllocator2D> fast;
    std::unique_ptr<NaiveBlockAllocator2D> naive;
    std::vector<Placement<2>> fastLive, naiveLive; // same order: element i of the sequence
};

const Layout& layoutFor(uint32_t liveCount) {
    static std::map<uint32_t, Layout> layouts;
    auto [it, inserted] = layouts.try_emplace(liveCount);
    if (inserted) {
        std::mt19937 rng(liveCount);
        Layout& layout = it->second;
        layout.fast = std::make_unique<BlockAllocator2D>(kSheet);
        layout.naive = std::make_unique<NaiveBlockAllocator2D>(kSheet);
        while (layout.fastLive.size() < liveCount) {
            Extent<2> extent = randomExtent(rng);
            auto fast = layout.fast->insert(extent);
            auto naive = layout.naive->insert(extent);
            if (!fast || !naive) std::abort(); // the sheet is sized so that this cannot happen
            layout.fastLive.push_back(*fast);
            layout.naiveLive.push_back(*naive);
        }
    }
    return it->second;
}

template <class Allocator>
const Allocator& startOf(const Layout& layout) {
    if constexpr (std::is_same_v<Allocator, BlockAllocator2D>)
        return *layout.fast;
    else
        return *layout.naive;
}

template <class Allocator>
const std::vector<Placement<2>>& liveOf(const Layout& layout) {
    if constexpr (std::is_same_v<Allocator, BlockAllocator2D>)
        return layout.fastLive;
    else
        return layout.naiveLive;
}

// Each iteration starts from a copy of the same layout (not timed) and times kOpsPerIteration
// operations on it; the reported time is per operation.
template <class Allocator, class Body>
void timePerOp(benchmark::State& state, uint32_t liveCount, Body body) {
    const Layout& layout = layoutFor(liveCount);
    std::mt19937 rng(12345);
    for (auto _ : state) {
        Allocator allocator = startOf<Allocator>(layout);
        // A copied vector has no spare capacity, so the first node the timed operations add
        // would reallocate (copy) the whole node array, which an allocator in use does not do.
        // One untimed insert and remove of a large odd-sized element (no free box has its exact
        // size, so the tree grows) gives it room and leaves the tree as it was.
        if (auto p = allocator.insert(Extent<2>{255, 253})) allocator.remove(p->id);
        // Distinct random victims for this iteration.
        std::vector<uint32_t> victims(kOpsPerIteration);
        for (uint32_t& v : victims) v = rng() % uint32_t(layout.fastLive.size());
        std::sort(victims.begin(), victims.end());
        victims.erase(std::unique(victims.begin(), victims.end()), victims.end());
        std::vector<Extent<2>> extents(kOpsPerIteration);
        for (auto& e : extents) e = randomExtent(rng);

        auto start = Clock::now();
        size_t done = body(allocator, liveOf<Allocator>(layout), victims, extents);
        double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        benchmark::DoNotOptimize(done);
        state.SetIterationTime(seconds / double(std::max<size_t>(done, 1)));
    }
}

// By id (what the engine does: it keeps the Placement) or by origin (the original interface; the
// fast allocator descends the tree, so this costs the depth of the element's leaf).
template <class Allocator, bool byId>
void removal(benchmark::State& state, uint32_t liveCount) {
    timePerOp<Allocator>(state, liveCount,
                         [](Allocator& allocator, const std::vector<Placement<2>>& live,
                            const std::vector<uint32_t>& victims, const std::vector<Extent<2>>&) {
                             for (uint32_t v : victims) {
                                 const Placement<2>& p = live[v];
                                 bool removed =
                                     byId ? allocator.remove(p.id) : allocator.remove(p.origin);
                                 if (!removed) std::abort();
                             }
                             return victims.size();
                         });
}

template <class Allocator>
void insertion(benchmark::State& state, uint32_t liveCount) {
    timePerOp<Allocator>(state, liveCount,
                         [](Allocator& allocator, const std::vector<Placement<2>>&,
                            const std::vector<uint32_t>&, const std::vector<Extent<2>>& extents) {
                             for (const auto& e : extents)
                                 if (!allocator.insert(e)) std::abort();
                             return extents.size();
                         });
}

void insertionBatched(benchmark::State& state, uint32_t liveCount) {
    timePerOp<BlockAllocator2D>(state, liveCount,
                                [](BlockAllocator2D& allocator, const std::vector<Placement<2>>&,
                                   const std::vector<uint32_t>&,
                                   const std::vector<Extent<2>>& extents) {
                                    auto placements = allocator.insertBatch(extents);
                                    for (const auto& p : placements)
                                        if (!p) std::abort();
                                    return extents.size();
                                });
}

// Objects leaving and entering as the camera moves: each operation removes one element and
// inserts another.
template <class Allocator>
void churn(benchmark::State& state, uint32_t liveCount) {
    timePerOp<Allocator>(state, liveCount,
                         [](Allocator& allocator, const std::vector<Placement<2>>& live,
                            const std::vector<uint32_t>& victims,
                            const std::vector<Extent<2>>& extents) {
                             for (size_t i = 0; i < victims.size(); ++i) {
                                 if (!allocator.remove(live[victims[i]].id)) std::abort();
                                 if (!allocator.insert(extents[i])) std::abort();
                             }
                             return victims.size();
                         });
}

// The same churn as a frame would do it: all removals, then one batched insertion.
void churnBatched(benchmark::State& state, uint32_t liveCount) {
    timePerOp<BlockAllocator2D>(
        state, liveCount,
        [](BlockAllocator2D& allocator, const std::vector<Placement<2>>& live,
           const std::vector<uint32_t>& victims, const std::vector<Extent<2>>& extents) {
            for (uint32_t v : victims)
                if (!allocator.remove(live[v].id)) std::abort();
            auto placements = allocator.insertBatch(std::span(extents).first(victims.size()));
            for (const auto& p : placements)
                if (!p) std::abort();
            return victims.size();
        });
}

// --- TLSF --------------------------------------------------------------------------------------

// A GPU-like workload: 4096 live allocations of 64 B .. 256 KiB (log-uniform), 256-byte
// alignment, in a 1 GiB range; each step frees a random live allocation and allocates a new one.
constexpr uint32_t kTlsfLive = 4096;
constexpr uint32_t kTlsfSteps = 1 << 16;
constexpr uint64_t kTlsfCapacity = 1ull << 30;
constexpr uint64_t kTlsfAlignment = 256;

struct TlsfWorkload {
    std::vector<uint64_t> initialSizes;
    std::vector<uint32_t> victims; // index into the live array at each step
    std::vector<uint64_t> sizes;   // size allocated at each step
};

const TlsfWorkload& tlsfWorkload() {
    static TlsfWorkload workload = [] {
        TlsfWorkload w;
        std::mt19937 rng(99);
        auto size = [&] { return uint64_t(64) << (rng() % 13) | (rng() % 64); };
        for (uint32_t i = 0; i < kTlsfLive; ++i) w.initialSizes.push_back(size());
        for (uint32_t i = 0; i < kTlsfSteps; ++i) {
            w.victims.push_back(rng() % kTlsfLive);
            w.sizes.push_back(size());
        }
        return w;
    }();
    return workload;
}

// A simple first-fit free list: free ranges sorted by offset, scanned from the front.
class FirstFitFreeList {
public:
    struct Allocation {
        uint64_t offset, size;
    };
    explicit FirstFitFreeList(uint64_t capacity) : m_free{{0, capacity}} {}

    std::optional<Allocation> allocate(uint64_t size, uint64_t alignment) {
        for (size_t i = 0; i < m_free.size(); ++i) {
            Range& range = m_free[i];
            uint64_t aligned = (range.offset + alignment - 1) & ~(alignment - 1);
            uint64_t padding = aligned - range.offset;
            if (padding > range.size || range.size - padding < size) continue;
            uint64_t end = range.offset + range.size;
            if (padding > 0) {
                range.size = padding;
                if (aligned + size < end)
                    m_free.insert(m_free.begin() + i + 1,
                                  Range{aligned + size, end - aligned - size});
            } else if (size < range.size) {
                range.offset += size;
                range.size -= size;
            } else {
                m_free.erase(m_free.begin() + i);
            }
            return Allocation{aligned, size};
        }
        return std::nullopt;
    }

    void free(const Allocation& allocation) {
        auto next = std::lower_bound(
            m_free.begin(), m_free.end(), allocation.offset,
            [](const Range& range, uint64_t offset) { return range.offset < offset; });
        size_t i = size_t(next - m_free.begin());
        bool mergePrev = i > 0 && m_free[i - 1].offset + m_free[i - 1].size == allocation.offset;
        bool mergeNext =
            i < m_free.size() && allocation.offset + allocation.size == m_free[i].offset;
        if (mergePrev && mergeNext) {
            m_free[i - 1].size += allocation.size + m_free[i].size;
            m_free.erase(m_free.begin() + i);
        } else if (mergePrev) {
            m_free[i - 1].size += allocation.size;
        } else if (mergeNext) {
            m_free[i].offset = allocation.offset;
            m_free[i].size += allocation.size;
        } else {
            m_free.insert(m_free.begin() + i, Range{allocation.offset, allocation.size});
        }
    }

private:
    struct Range {
        uint64_t offset, size;
    };
    std::vector<Range> m_free;
};

// One iteration = free one allocation + allocate one; the step sequence wraps around.
template <class Allocator, class Allocation>
void allocateFreeSteps(benchmark::State& state, Allocator& allocator) {
    const TlsfWorkload& w = tlsfWorkload();
    std::vector<Allocation> live;
    for (uint64_t size : w.initialSizes) live.push_back(*allocator.allocate(size, kTlsfAlignment));
    uint32_t step = 0;
    for (auto _ : state) {
        Allocation& slot = live[w.victims[step]];
        allocator.free(slot);
        auto allocation = allocator.allocate(w.sizes[step], kTlsfAlignment);
        if (!allocation) {
            state.SkipWithError("allocation failed");
            break;
        }
        slot = *allocation;
        step = (step + 1) % kTlsfSteps;
    }
    for (auto& allocation : live) allocator.free(allocation);
}

void tlsfSteps(benchmark::State& state) {
    Tlsf tlsf(kTlsfCapacity);
    allocateFreeSteps<Tlsf, TlsfAllocation>(state, tlsf);
}

void firstFitSteps(benchmark::State& state) {
    FirstFitFreeList list(kTlsfCapacity);
    allocateFreeSteps<FirstFitFreeList, FirstFitFreeList::Allocation>(state, list);
}

void mallocSteps(benchmark::State& state) {
    const TlsfWorkload& w = tlsfWorkload();
    std::vector<void*> live;
    for (uint64_t size : w.initialSizes) live.push_back(std::malloc(size));
    uint32_t step = 0;
    for (auto _ : state) {
        void*& slot = live[w.victims[step]];
        std::free(slot);
        slot = std::malloc(w.sizes[step]);
        benchmark::DoNotOptimize(slot);
        step = (step + 1) % kTlsfSteps;
    }
    for (void* p : live) std::free(p);
}

// --- Registration and the ratio table ----------------------------------------------------------

constexpr int kRepetitions = 5;

// Iterations per repetition: enough for a stable median, bounded for the slow naive cases.
int iterationsFor(bool naive, uint32_t liveCount) {
    if (!naive) return 60;
    return liveCount <= 1000 ? 40 : liveCount <= 10000 ? 8 : 2;
}

// "remove/fast" + 10000 -> "remove/fast/10000" (snprintf: GCC 12 warns falsely on string +).
std::string nameFor(const char* what, uint32_t liveCount) {
    char name[96];
    std::snprintf(name, sizeof name, "%s/%u", what, liveCount);
    return name;
}

void registerBlockBenchmarks() {
    for (uint32_t live : kLiveCounts) {
        auto add = [&](const char* what, bool naive, auto fn) {
            benchmark::RegisterBenchmark(nameFor(what, live).c_str(), fn, live)
                ->UseManualTime()
                ->Iterations(iterationsFor(naive, live))
                ->Repetitions(kRepetitions)
                ->ReportAggregatesOnly(true)
                ->Unit(benchmark::kNanosecond);
        };
        add("remove-id/fast", false, removal<BlockAllocator2D, true>);
        add("remove-id/naive", true, removal<NaiveBlockAllocator2D, true>);
        add("remove-origin/fast", false, removal<BlockAllocator2D, false>);
        add("remove-origin/naive", true, removal<NaiveBlockAllocator2D, false>);
        add("insert/fast-single", false, insertion<BlockAllocator2D>);
        add("insert/fast-batched", false, insertionBatched);
        add("insert/naive", true, insertion<NaiveBlockAllocator2D>);
        add("churn/fast-single", false, churn<BlockAllocator2D>);
        add("churn/fast-batched", false, churnBatched);
        add("churn/naive", true, churn<NaiveBlockAllocator2D>);
    }
}

void registerTlsfBenchmarks() {
    using Fn = void (*)(benchmark::State&);
    const std::pair<const char*, Fn> benchmarks[] = {{"tlsf/alloc+free", tlsfSteps},
                                                     {"first-fit/alloc+free", firstFitSteps},
                                                     {"malloc/alloc+free", mallocSteps}};
    for (auto [name, fn] : benchmarks) {
        benchmark::RegisterBenchmark(name, fn)
            ->MinTime(0.1)
            ->Repetitions(kRepetitions)
            ->ReportAggregatesOnly(true)
            ->Unit(benchmark::kNanosecond);
    }
}

// Prints as usual and keeps the median time of each benchmark, in nanoseconds per operation.
class MedianCollector : public benchmark::ConsoleReporter {
public:
    MedianCollector() : ConsoleReporter(isatty(STDOUT_FILENO) ? OO_Defaults : OO_Tabular) {}
    void ReportRuns(const std::vector<Run>& runs) override {
        for (const Run& run : runs) {
            if (run.error_occurred) continue;
            bool median = run.run_type == Run::RT_Aggregate && run.aggregate_name == "median";
            bool single = run.run_type == Run::RT_Iteration && run.repetitions <= 1;
            if (median || single)
                medians[run.run_name.function_name] =
                    run.GetAdjustedRealTime() *
                    benchmark::GetTimeUnitMultiplier(benchmark::kNanosecond) /
                    benchmark::GetTimeUnitMultiplier(run.time_unit);
        }
        ConsoleReporter::ReportRuns(runs);
    }
    std::map<std::string, double> medians;
};

void printRatioTable(const std::map<std::string, double>& ns) {
    auto get = [&](const std::string& name) {
        auto it = ns.find(name);
        return it == ns.end() ? 0.0 : it->second;
    };
    auto ratio = [](double slow, double fast) { return fast > 0 && slow > 0 ? slow / fast : 0.0; };
    std::printf("\nBlock allocator, 2048x2048 sheet, elements 1..8 per side, median ns per op\n");
    std::printf("%-6s %9s %9s %8s | %9s %9s %8s | %9s %9s %9s %8s %8s %7s | %9s %9s %9s %8s\n",
                "live", "rm id", "naive", "speedup", "rm origin", "naive", "speedup", "ins fast",
                "batched", "naive", "vs 1", "vs batch", "batch/1", "churn", "batched", "naive",
                "speedup");
    for (uint32_t live : kLiveCounts) {
        auto at = [&](const char* what) { return get(nameFor(what, live)); };
        double rf = at("remove-id/fast"), rn = at("remove-id/naive");
        double of = at("remove-origin/fast"), on = at("remove-origin/naive");
        double is = at("insert/fast-single"), ib = at("insert/fast-batched"),
               in = at("insert/naive");
        double cs = at("churn/fast-single"), cb = at("churn/fast-batched"), cn = at("churn/naive");
        std::printf("%-6u %9.0f %9.0f %7.1fx | %9.0f %9.0f %7.1fx | %9.0f %9.0f %9.0f %7.1fx "
                    "%7.1fx %6.2fx | %9.0f %9.0f %9.0f %7.1fx\n",
                    live, rf, rn, ratio(rn, rf), of, on, ratio(on, of), is, ib, in, ratio(in, is),
                    ratio(in, ib), ratio(is, ib), cs, cb, cn, ratio(cn, cs));
    }
    std::printf("\nStarting layouts (same insertion sequence): tree nodes fast / naive\n");
    for (uint32_t live : kLiveCounts) {
        const Layout& layout = layoutFor(live);
        std::printf("%-6u %9zu %9zu\n", live, layout.fast->nodeCount(), layout.naive->nodeCount());
    }
    double t = get("tlsf/alloc+free"), f = get("first-fit/alloc+free"),
           m = get("malloc/alloc+free");
    std::printf("\nAllocate + free, %u live, 64 B..256 KiB, 256-byte alignment, median ns per "
                "pair\n",
                kTlsfLive);
    std::printf("tlsf %.1f ns | first-fit list %.1f ns (%.1fx tlsf) | malloc/free %.1f ns "
                "(%.2fx tlsf)\n",
                t, f, ratio(f, t), m, ratio(m, t));
    double removal10k = ratio(get("remove-id/naive/10000"), get("remove-id/fast/10000"));
    std::printf("\nGoals: removal (by id) at 10k live >= 100x naive: %s (%.1fx); TLSF alloc+free "
                "<= 100 ns: %s (%.1f ns)\n",
                removal10k >= 100 ? "met" : "NOT met", removal10k,
                t > 0 && t <= 100 ? "met" : "NOT met", t);
}

} // namespace

int main(int argc, char** argv) {
    registerTlsfBenchmarks();
    registerBlockBenchmarks();
    benchmark::Initialize(&argc, argv);
    if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
    MedianCollector reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    printRatioTable(reporter.medians);
    benchmark::Shutdown();
    return 0;
}
