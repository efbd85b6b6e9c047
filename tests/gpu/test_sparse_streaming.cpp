// Texture streaming with sparse residency (--streaming sparse): the page pool's bookkeeping on the
// CPU (pages owned once, levels whole and contiguous, priorities and the swap ratio), and end to
// end on lavapipe (which has sparseResidencyImage2D): a walk through builtin:textures at test
// scale stays within --texture-budget, binds pages and converges to the image rendered with every
// texture resident, in forward and decoupled; without sparse support the flag is one input error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <sys/wait.h>
#include <unistd.h>

#include "gpu_test_env.h"
#include "render/streaming/sparse_residency.h"
#include "scene/builtin_gallery.h"

using namespace shadel;
using namespace shadel::test;
namespace fs = std::filesystem;

namespace {

// A texture of `size` with 128^2-texel pages (RGBA8's standard block): levels of 128 and more
// are paged, the rest is the tail.
SparseTexture pagedTexture(uint32_t size) {
    SparseTexture t;
    t.size = size;
    for (uint32_t side = size; side >= 128; side /= 2) {
        t.levelPages.push_back(std::max(1u, (side / 128) * (side / 128)));
        t.tailFirst++;
    }
    return t;
}

// Every pool page belongs to exactly one resident level, load in flight or the free list; each
// texture's paged levels are exactly those from its resident level to its tail, each whole.
void expectConsistent(const SparseResidency& r, const std::vector<SparseLevelLoad>& inFlight) {
    std::vector<int> owners(r.poolPages, 0);
    for (uint32_t p : r.freePages) {
        ASSERT_LT(p, r.poolPages);
        owners[p]++;
    }
    for (const SparseTexture& t : r.textures) {
        ASSERT_LE(t.resident, t.tailFirst);
        for (uint32_t l = 0; l < t.tailFirst; ++l) {
            if (l >= t.resident) {
                EXPECT_EQ(t.pages[l].size(), t.levelPages[l]) << "level " << l;
            } else {
                EXPECT_TRUE(t.pages[l].empty()) << "level " << l;
            }
            for (uint32_t p : t.pages[l]) {
                ASSERT_LT(p, r.poolPages);
                owners[p]++;
            }
        }
    }
    uint32_t pending = 0;
    for (const SparseLevelLoad& l : inFlight) {
        const SparseTexture& t = r.textures[l.texture];
        EXPECT_TRUE(t.pending);
        EXPECT_EQ(l.level + l.levels, t.resident);
        size_t pages = 0;
        for (uint32_t k = l.level; k < t.resident; ++k) pages += t.levelPages[k];
        EXPECT_EQ(l.pages.size(), pages);
        for (uint32_t p : l.pages) owners[p]++;
        pending++;
    }
    EXPECT_EQ(pending, r.pending);
    for (uint32_t p = 0; p < r.poolPages; ++p) EXPECT_EQ(owners[p], 1) << "page " << p;
    EXPECT_EQ(usedPages(r) - residentPages(r), [&] {
        uint32_t n = 0;
        for (const auto& l : inFlight) n += uint32_t(l.pages.size());
        return n;
    }());
}

struct CliResult {
    int exitCode = -1;
    std::string stderrText;
};

CliResult runCli(const std::string& env, const std::string& args) {
    std::string errFile =
        (fs::temp_directory_path() / ("shadel_sparse_stderr_" + std::to_string(getpid()) + ".txt"))
            .string();
    std::string cmd =
        env + " timeout 120 " + SHADEL_BINARY + " " + args + " >/dev/null 2>" + errFile;
    int status = std::system(cmd.c_str());
    CliResult r;
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::ifstream in(errFile);
    std::stringstream ss;
    ss << in.rdbuf();
    r.stderrText = ss.str();
    return r;
}

// builtin:textures at test scale (256^2 RGBA8 textures: level 0 is 4 pages, level 1 one page,
// 64^2 and below the always-resident tail). RGBA8, since lavapipe's BC7 page is 256^2 texels: at
// this scale a BC7 texture's 128^2 tail already holds what a 192x108 view samples, and there
// would be nothing to page (BC7 pages: WalkMatchesResidentDecoupledWithBlockCompression).
RenderOptions sparseGallery(RenderMode mode, uint32_t frames, double budgetMiB) {
    RenderOptions o = renderOptions("builtin:textures", mode, 192, 108);
    o.galleryTextureSize = 256;
    o.frames = frames;
    o.cameraPath = CameraPath::Walk;
    o.textureBudgetMiB = budgetMiB;
    o.streaming = StreamingMode::Sparse;
    o.textureCompression = TextureCompression::None;
    return o;
}

} // namespace

TEST(TextureStreamingSparsePolicy, PagesAreOwnedOnceAndLevelsStayWholeUnderRandomWishes) {
    std::mt19937 rng(7);
    std::vector<SparseTexture> textures;
    for (int i = 0; i < 30; ++i) textures.push_back(pagedTexture(64u << (rng() % 5))); // 64..1024
    SparseResidency r = makeSparseResidency(textures, 60);
    EXPECT_EQ(r.poolPages, 60u);
    std::vector<SparseLevelLoad> inFlight;
    TextureCacheLimits limits;
    for (int frame = 0; frame < 400; ++frame) {
        beginSparseFrame(r);
        for (SparseTexture& t : r.textures)
            if (rng() % 8 == 0) t.wanted = float(rng() % 1500);
        std::vector<SparseLevelLoad> still;
        for (const SparseLevelLoad& l : inFlight) {
            uint32_t k = rng() % 10;
            if (k < 6)
                commitSparseLoad(r, l);
            else if (k < 7)
                abandonSparseLoad(r, l);
            else
                still.push_back(l);
        }
        inFlight = still;
        std::vector<SparseLevelLoad> planned;
        std::vector<SparseEviction> evicted;
        planSparseLoads(r, limits, ~0ull, planned, evicted);
        EXPECT_LE(r.pending, limits.pendingTotal);
        for (const SparseEviction& e : evicted) {
            // A level that changed this frame never goes in the same frame (one bind batch
            // must not bind and unbind one range).
            EXPECT_EQ(r.textures[e.texture].resident, e.level + 1);
            for (const SparseLevelLoad& l : planned) EXPECT_NE(l.texture, e.texture);
        }
        for (auto& l : planned) inFlight.push_back(l);
        expectConsistent(r, inFlight);
        ASSERT_LE(usedPages(r), r.poolPages);
    }
    // The pool is never larger than every paged level of every texture.
    uint32_t everything = 0;
    for (const SparseTexture& t : textures)
        for (uint32_t p : t.levelPages) everything += p;
    EXPECT_EQ(makeSparseResidency(textures, 1u << 20).poolPages, everything);
}

TEST(TextureStreamingSparsePolicy, HighPrioritiesGetTheirLevelsAndLowOnesYield) {
    // Four 512^2 textures (levels 512: 16 pages, 256: 4, 128: 1); a pool of 26 pages holds one
    // whole texture (21 pages) plus one texture's 256 and 128 levels (5).
    std::vector<SparseTexture> textures(4, pagedTexture(512));
    ASSERT_EQ(textures[0].tailFirst, 3u);
    SparseResidency r = makeSparseResidency(textures, 26);
    auto run = [&](int frames) {
        for (int f = 0; f < frames; ++f) {
            beginSparseFrame(r);
            std::vector<SparseLevelLoad> planned;
            std::vector<SparseEviction> evicted;
            planSparseLoads(r, {}, ~0ull, planned, evicted);
            for (const SparseLevelLoad& l : planned) commitSparseLoad(r, l); // land at once
            expectConsistent(r, {});
        }
    };
    r.textures[0].wanted = 500.0f; // wants level 0
    r.textures[1].wanted = 200.0f; // wants level 1
    r.textures[2].wanted = 100.0f; // wants level 2
    r.textures[3].wanted = 10.0f;  // the tail is enough
    run(10);
    EXPECT_EQ(r.textures[0].resident, 0u);
    EXPECT_EQ(r.textures[1].resident, 1u);
    EXPECT_EQ(r.textures[2].resident, 3u); // 21 + 5 pages used: no room for its page
    EXPECT_EQ(r.textures[3].resident, 3u);
    EXPECT_EQ(usedPages(r), 26u);
    // A modestly higher wish does not take pages from a texture that needs them (swap ratio)...
    r.textures[2].wanted = 250.0f;
    run(5);
    EXPECT_EQ(r.textures[1].resident, 1u);
    EXPECT_EQ(r.textures[2].resident, 3u);
    // ...a much higher one does: texture 0 no longer needs level 0 and gives it back first;
    // in the end priorities decide: texture 2 whole (21 pages), texture 1 its two levels (5),
    // and texture 0, the lowest of the three, is back to its tail.
    r.textures[0].wanted = 100.0f;
    r.textures[2].wanted = 1000.0f;
    run(10);
    EXPECT_EQ(r.textures[2].resident, 0u);
    EXPECT_EQ(r.textures[1].resident, 1u);
    EXPECT_EQ(r.textures[0].resident, 3u);
    EXPECT_EQ(usedPages(r), 26u);
}

TEST(TextureStreamingSparsePolicy, LoadsTakeEveryLevelToTheTargetButNoMoreThanTheStagingHolds) {
    SparseResidency r = makeSparseResidency({pagedTexture(512)}, 100);
    r.textures[0].wanted = 512.0f;
    std::vector<SparseLevelLoad> planned;
    std::vector<SparseEviction> evicted;
    beginSparseFrame(r);
    planSparseLoads(r, {}, 5, planned, evicted); // levels 0..2 need 21 pages: 1..2 fit
    ASSERT_EQ(planned.size(), 1u);
    EXPECT_EQ(planned[0].level, 1u);
    EXPECT_EQ(planned[0].levels, 2u);
    EXPECT_EQ(planned[0].pages.size(), 5u);
    commitSparseLoad(r, planned[0]);
    planned.clear();
    beginSparseFrame(r);
    planSparseLoads(r, {}, 15, planned, evicted); // level 0 alone is 16 pages
    EXPECT_TRUE(planned.empty());
    beginSparseFrame(r);
    planSparseLoads(r, {}, ~0ull, planned, evicted);
    ASSERT_EQ(planned.size(), 1u);
    EXPECT_EQ(planned[0].level, 0u);
    EXPECT_EQ(planned[0].levels, 1u);
    commitSparseLoad(r, planned[0]);
    EXPECT_EQ(r.textures[0].resident, 0u);
    EXPECT_EQ(residentPages(r), 21u);
    EXPECT_TRUE(evicted.empty());
}

// The checks at test scale with pages instead of slots: the walk never exceeds the
// budget (tails + a fixed page pool), pages are bound and unbound, and the last frame is
// >= 35 dB against every texture resident.
TEST(TextureStreamingSparse, WalkStaysWithinBudgetAndMatchesResidentForward) {
    // lavapipe has no packed MIP tail: each texture's levels of 64^2 and less take a 64 KiB page
    // each (7 x 64 textures = 28 MiB of tails), leaving a pool of 32 pages (of 320 paged).
    const double budgetMiB = 30.0;
    RenderRun streamed = renderChecked(sparseGallery(RenderMode::Forward, 10, budgetMiB));
    RenderOptions ref = sparseGallery(RenderMode::Forward, 10, 0.0);
    ref.streaming = StreamingMode::Layered; // without a budget both are every texture whole
    RenderRun resident = renderChecked(ref);
    uint64_t peak = streamed.stats["texture_memory_peak_bytes"].get<uint64_t>();
    uint64_t all = resident.stats["texture_memory_peak_bytes"].get<uint64_t>();
    EXPECT_LE(peak, uint64_t(budgetMiB * 1048576.0));
    EXPECT_GT(all, 3 * (peak - streamed.stats["texture_streaming"]["tail_bytes"].get<uint64_t>()));
    const auto& st = streamed.stats["texture_streaming"];
    ASSERT_EQ(st["mode"], "sparse");
    const auto& sp = st["sparse"];
    EXPECT_EQ(sp["page_bytes"].get<uint64_t>(), 65536u);
    EXPECT_GT(sp["page_binds"].get<uint64_t>(), 0u);
    EXPECT_GT(sp["pages_resident"].get<uint32_t>(), 0u);
    EXPECT_LE(sp["pages_used_peak"].get<uint32_t>(), sp["pool_pages"].get<uint32_t>());
    EXPECT_GT(st["exchanges_committed"].get<uint64_t>(), 0u);
    EXPECT_EQ(st["loads_failed"].get<uint64_t>(), 0u);
    for (uint64_t bytes : st["resident_bytes_per_frame"].get<std::vector<uint64_t>>())
        EXPECT_LE(bytes, peak);
    double first = psnr(streamed.frames.front().rgba, resident.frames.front().rgba);
    double last = psnr(streamed.frames.back().rgba, resident.frames.back().rgba);
    RecordProperty("psnr_first", std::to_string(first));
    RecordProperty("psnr_last", std::to_string(last));
    RecordProperty("pages_bound", std::to_string(sp["page_binds"].get<uint64_t>()));
    EXPECT_GE(last, 35.0);
    EXPECT_GT(last, first); // paging improved the image (frame 0 has only the tails)
}

TEST(TextureStreamingSparse, WalkMatchesResidentDecoupled) {
    const double budgetMiB = 30.0;
    RenderRun streamed = renderChecked(sparseGallery(RenderMode::Decoupled, 8, budgetMiB));
    RenderOptions ref = sparseGallery(RenderMode::Decoupled, 8, 0.0);
    ref.streaming = StreamingMode::Layered;
    RenderRun resident = renderChecked(ref);
    EXPECT_LE(streamed.stats["texture_memory_peak_bytes"].get<uint64_t>(),
              uint64_t(budgetMiB * 1048576.0));
    EXPECT_GT(streamed.stats["texture_streaming"]["sparse"]["page_binds"].get<uint64_t>(), 0u);
    double last = psnr(streamed.frames.back().rgba, resident.frames.back().rgba);
    RecordProperty("psnr_last", std::to_string(last));
    EXPECT_GE(last, 35.0);
}

// The sparse images hold BC7 blocks: 256^2-texel pages of 64 KiB on lavapipe (its granularity is
// in blocks), each texture's 128^2 and smaller levels a page each (8 x 64 = 32 MiB of tails), a
// pool of 24 pages; the last frame against every texture resident (BC7 too), within the budget,
// with pages bound and the validation layer watching.
TEST(TextureStreamingSparse, WalkMatchesResidentDecoupledWithBlockCompression) {
    const double budgetMiB = 33.5;
    RenderOptions o = sparseGallery(RenderMode::Decoupled, 8, budgetMiB);
    o.textureCompression = TextureCompression::Bc;
    RenderRun streamed = renderChecked(o);
    o.textureBudgetMiB = 0.0;
    o.streaming = StreamingMode::Layered;
    RenderRun resident = renderChecked(o);
    const auto& st = streamed.stats["texture_streaming"];
    ASSERT_EQ(st["compression"], "bc7");
    EXPECT_EQ(st["sparse"]["page_texels"][0].get<uint32_t>(), 256u);
    EXPECT_EQ(st["tail_bytes"].get<uint64_t>(), 32ull << 20);
    EXPECT_LE(streamed.stats["texture_memory_peak_bytes"].get<uint64_t>(),
              uint64_t(budgetMiB * 1048576.0));
    EXPECT_GT(st["sparse"]["page_binds"].get<uint64_t>(), 0u);
    EXPECT_LE(streamed.stats["texture_bytes_per_texel"].get<double>(), 1.01);
    double last = psnr(streamed.frames.back().rgba, resident.frames.back().rgba);
    RecordProperty("psnr_last", std::to_string(last));
    EXPECT_GE(last, 35.0);
}

// A pool too small for what the walk wants (512^2 textures, 20 pages): textures that hold more
// than they want give their finest level back, whose pages are unbound and bound elsewhere in
// later frames, with the validation layer watching.
TEST(TextureStreamingSparse, ATightPoolEvictsAndUnbindsLevels) {
    RenderOptions o = sparseGallery(RenderMode::Forward, 10, 29.25);
    o.galleryTextureSize = 512;
    o.width = 320, o.height = 180;
    RenderRun run = renderChecked(o);
    const auto& st = run.stats["texture_streaming"];
    const auto& sp = st["sparse"];
    EXPECT_EQ(sp["pool_pages"].get<uint32_t>(), 20u);
    EXPECT_GT(sp["level_evictions"].get<uint64_t>(), 0u);
    EXPECT_GT(sp["page_unbinds"].get<uint64_t>(), 0u);
    EXPECT_GT(sp["page_binds"].get<uint64_t>(), sp["pages_resident"].get<uint64_t>());
    EXPECT_LE(sp["pages_used_peak"].get<uint32_t>(), 20u);
    EXPECT_EQ(st["loads_failed"].get<uint64_t>(), 0u);
    EXPECT_LE(run.stats["texture_memory_peak_bytes"].get<uint64_t>(), uint64_t(29.25 * 1048576.0));
}

TEST(TextureStreamingSparse, UnsupportedDeviceOrTooSmallBudgetExitWith2) {
    const std::string gallery = "render --size 16x16 --scene builtin:textures "
                                "--gallery-texture-size 256 --streaming sparse ";
    // As on a device without sparse residency: one line naming the flag and why.
    CliResult r = runCli("SHADEL_DISABLE_SPARSE=1", gallery + "--texture-budget 30");
    EXPECT_EQ(r.exitCode, 2) << r.stderrText;
    EXPECT_NE(r.stderrText.find("shadel: --streaming sparse: "), std::string::npos) << r.stderrText;
    EXPECT_NE(r.stderrText.find("sparse residency"), std::string::npos) << r.stderrText;
    // The tails do not fit in 2 MiB.
    r = runCli("", gallery + "--texture-budget 2");
    EXPECT_EQ(r.exitCode, 2) << r.stderrText;
    EXPECT_NE(r.stderrText.find("--texture-budget 2.00"), std::string::npos) << r.stderrText;
}
