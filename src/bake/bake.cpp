#include "bake/bake.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <filesystem>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "bake/bake_cache.h"
#include "bake/cache_eviction.h"
#include "bake/chart_packing.h"
#include "bake/charting.h"
#include "bake/id_map.h"
#include "bake/packing.h"
#include "core/error.h"
#include "core/log.h"

namespace shadel {
namespace {

constexpr uint32_t kChunk = 8;

uint32_t roundUp(uint32_t v, uint32_t granularity) {
    return (v + granularity - 1) / granularity * granularity;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Shadel size of each chart's content (without gutters) at a density.
glm::uvec2 contentSize(const Chart& chart, double density) {
    if (chart.kind == ChartKind::DegenerateCells) return glm::uvec2(chart.extent);
    glm::dvec2 e = glm::ceil(chart.extent * density - 1e-9);
    return glm::uvec2(glm::max(e, glm::dvec2(1.0)));
}

double chartScale(const Chart& chart, double density) {
    return chart.kind == ChartKind::DegenerateCells ? 1.0 : density;
}

// Charts are placed in one of kOrientations orientations: quarter turns (k % 4) of their
// min-area-rect alignment rotated by (k / 4) * 22.5 degrees. Meshes of few charts also try 45
// degrees, of fewer still 22.5 and 67.5, which lets round and curved charts nest in more ways
// (with many charts the packer has choice enough).
constexpr size_t kEighthTurnsUpToCharts = 24;
constexpr size_t kSixteenthTurnsUpToCharts = 16;
constexpr uint32_t kFrames = kOrientations / 4;

// A chart rotated by a multiple of 22.5 degrees: where its local coordinates start and how far
// they reach.
struct ChartFrame {
    glm::dvec2 low{0.0}, extent{0.0};
    glm::uvec2 content{0};
};

struct Layout {
    OutlinePack pack;
    std::vector<std::array<ChartFrame, kFrames>> frames;
};

// Rotation by `step` of kFrames steps of a quarter turn.
glm::dvec2 frameTurn(glm::dvec2 p, uint32_t step) {
    if (step == 0) return p;
    double a = 0.5 * 3.14159265358979323846 * double(step) / double(kFrames);
    double c = std::cos(a), s = std::sin(a);
    return glm::dvec2(c * p.x - s * p.y, s * p.x + c * p.y);
}

ChartFrame chartFrame(const ChartedMesh& charted, const Chart& chart, uint32_t step,
                      double density) {
    ChartFrame f;
    if (step == 0) {
        f.extent = chart.extent;
    } else {
        glm::dvec2 lo(1e300), hi(-1e300);
        for (uint32_t v = chart.firstVertex; v < chart.firstVertex + chart.vertexCount; ++v) {
            glm::dvec2 r = frameTurn(charted.local[v], step);
            lo = glm::min(lo, r), hi = glm::max(hi, r);
        }
        f.low = lo, f.extent = hi - lo;
    }
    Chart rotated = chart;
    rotated.extent = f.extent;
    f.content = contentSize(rotated, density);
    return f;
}

// Triangles of each chart (a chart's baked vertices are contiguous, so its first corner says).
std::vector<std::vector<uint32_t>> chartTriangles(const ChartedMesh& charted) {
    std::vector<uint32_t> chartOfVertex(charted.local.size(), 0);
    for (uint32_t c = 0; c < charted.charts.size(); ++c)
        for (uint32_t v = 0; v < charted.charts[c].vertexCount; ++v)
            chartOfVertex[charted.charts[c].firstVertex + v] = c;
    std::vector<std::vector<uint32_t>> triangles(charted.charts.size());
    for (uint32_t t = 0; t < charted.indices.size() / 3; ++t)
        triangles[chartOfVertex[charted.indices[3 * t]]].push_back(t);
    return triangles;
}

// A chart vertex in shadels inside the content box of orientation k: spare space split evenly.
glm::dvec2 orientedPosition(const ChartedMesh& charted, const Chart& chart, uint32_t vertex,
                            const std::array<ChartFrame, kFrames>& frames, uint32_t k,
                            double density) {
    const ChartFrame& f = frames[k / 4];
    double scale = chartScale(chart, density);
    glm::dvec2 centring = (glm::dvec2(f.content) - f.extent * scale) * 0.5;
    glm::dvec2 q = (frameTurn(charted.local[vertex], k / 4) - f.low) * scale + centring;
    return turnQuarter(q, glm::dvec2(f.content), k % 4);
}

// Packs the charts by their outlines (chart_packing.h); padded bounding rectangles
// (packing.h) are kept instead when they happen to pack smaller, so shapes never lose.
Layout layoutCharts(const ChartedMesh& charted, const std::vector<std::vector<uint32_t>>& triangles,
                    double density, uint32_t gutter) {
    Layout layout;
    std::vector<PackRect> rects;
    std::vector<std::array<ChartOutline, kOrientations>> outlines(charted.charts.size());
    std::vector<glm::dvec2> corners;
    bool eighthTurns = charted.charts.size() <= kEighthTurnsUpToCharts;
    bool sixteenthTurns = charted.charts.size() <= kSixteenthTurnsUpToCharts;
    for (size_t c = 0; c < charted.charts.size(); ++c) {
        const Chart& chart = charted.charts[c];
        std::array<ChartFrame, kFrames> frames;
        frames[0] = chartFrame(charted, chart, 0, density);
        bool turnable = eighthTurns && chart.kind != ChartKind::DegenerateCells;
        // Frames left out keep a zero extent, and their outlines width 0 (never tried).
        for (uint32_t r = 1; r < kFrames && turnable; ++r)
            if (r == kFrames / 2 || sixteenthTurns)
                frames[r] = chartFrame(charted, chart, r, density);
        layout.frames.push_back(frames);
        glm::uvec2 content = frames[0].content;
        rects.push_back({content.x + 2 * gutter, content.y + 2 * gutter});
        for (uint32_t k = 0; k < (turnable ? kOrientations : 4); ++k) {
            if (k >= 4 && frames[k / 4].content == glm::uvec2(0)) continue;
            corners.clear();
            for (uint32_t t : triangles[c])
                for (uint32_t i = 0; i < 3; ++i)
                    corners.push_back(orientedPosition(charted, chart, charted.indices[3 * t + i],
                                                       frames, k, density));
            glm::uvec2 box = frames[k / 4].content;
            if (k % 2) box = glm::uvec2(box.y, box.x);
            outlines[c][k] = chartOutline(corners, box, gutter);
        }
    }
    layout.pack = packOutlines(outlines, gutter, kChunk);
    PackResult boxes = packNearSquare(rects, kChunk);
    if (boxes.width != 0 &&
        uint64_t(boxes.width) * boxes.height < uint64_t(layout.pack.width) * layout.pack.height) {
        layout.pack.width = boxes.width, layout.pack.height = boxes.height;
        for (size_t c = 0; c < rects.size(); ++c)
            layout.pack.placements[c] = {boxes.placements[c].x + gutter,
                                         boxes.placements[c].y + gutter,
                                         boxes.placements[c].turned ? 1u : 0u};
    }
    return layout;
}

// Chart-local coordinates -> shadel UVs of the packed rect (width x height shadels).
std::vector<glm::vec2> placeCharts(const ChartedMesh& charted, const Layout& layout, double density,
                                   uint32_t width, uint32_t height) {
    std::vector<glm::vec2> uv(charted.local.size());
    for (size_t c = 0; c < charted.charts.size(); ++c) {
        const Chart& chart = charted.charts[c];
        const OutlinePlacement& place = layout.pack.placements[c];
        glm::dvec2 origin(place.x, place.y);
        for (uint32_t v = chart.firstVertex; v < chart.firstVertex + chart.vertexCount; ++v) {
            glm::dvec2 q =
                orientedPosition(charted, chart, v, layout.frames[c], place.orientation, density);
            glm::dvec2 texel = origin + q;
            uv[v] = glm::vec2(float(texel.x / width), float(texel.y / height));
            uv[v] = glm::clamp(uv[v], glm::vec2(0.0f), glm::vec2(1.0f));
        }
    }
    return uv;
}

// Meshes of at most this many charts that cover less than kGoodUtilisation of their rect are
// charted again with each of these first-growth cones (degrees) and the best layout is kept.
// Variants are only tried on rects of at most kGrowthVariantShadels (packing and ID maps cost
// in proportion to the rect), which keeps the added bake time a small fraction.
constexpr size_t kGrowthVariantCharts = 32;
constexpr double kGrowthVariantShadels = 512.0 * 512.0;
constexpr double kGoodUtilisation = 0.7;
constexpr float kGrowthVariantDegrees[] = {90.0f, 110.0f};

// The MIP-0 layout of a charted mesh: rect, shadel UVs, ID map and the density they use.
struct Mip0 {
    uint32_t width = 0, height = 0;
    double density = 0;
    std::vector<glm::vec2> uv;
    std::vector<uint16_t> level0;
    IdMapStats stats;
    bool padded = false; // the packed charts were smaller than minResolution
    double utilisation() const { return double(stats.coveredShadels) / (double(width) * height); }
};

// Finds a density whose packed rect fits [min, max] resolution and lets every triangle own a
// MIP-0 shadel. Charting is scale-free, so only packing and rasterization repeat. With
// `fixedDensity` a layout that would need another density is given up (width 0) instead.
Mip0 placeMip0(const Mesh& mesh, const ChartedMesh& charted, double density, uint32_t gutter,
               uint32_t minResolution, uint32_t maxResolution, bool fixedDensity = false) {
    IdMapOptions options;
    options.floodPasses = std::max(2u, gutter + 1);
    options.forceOwnership = true;
    int growthsToMinimum = 0;
    std::vector<std::vector<uint32_t>> triangles = chartTriangles(charted);
    for (int attempt = 0;; ++attempt) {
        Layout layout = layoutCharts(charted, triangles, density, gutter);
        uint32_t packedSide = std::max(layout.pack.width, layout.pack.height);
        if (fixedDensity && (packedSide > maxResolution || packedSide * 1.2 < minResolution))
            return {};
        if (packedSide > maxResolution) {
            if (attempt > 40 || density < 1e-9)
                throw InputError(format("mesh '%s': %zu charts do not fit %ux%u shadels",
                                        mesh.name.c_str(), charted.charts.size(), maxResolution,
                                        maxResolution));
            density *= 0.97 * double(maxResolution) / packedSide;
            continue;
        }
        if (growthsToMinimum < 8 && packedSide * 1.2 < minResolution && charted.surfaceArea > 0) {
            // Tiny object: spend the minimum rect on detail instead of empty space. Gutters do
            // not scale with density, so this takes a few steps.
            ++growthsToMinimum;
            density *= std::max(1.1, 0.9 * double(minResolution) / packedSide);
            continue;
        }
        Mip0 m;
        m.width = std::max(layout.pack.width, minResolution);
        m.height = std::max(layout.pack.height, minResolution);
        m.padded = m.width != layout.pack.width || m.height != layout.pack.height;
        m.uv = placeCharts(charted, layout, density, m.width, m.height);
        m.level0 = buildIdMap(m.uv, charted.indices, m.width, m.height, options, &m.stats);
        bool canGrow = std::max(m.width, m.height) < maxResolution && attempt < 40;
        if (m.stats.unownedTriangles > 0 && canGrow) {
            if (fixedDensity) return {};
            // Triangles smaller than a shadel crowd each other out: raise the density.
            density *= 1.4;
            continue;
        }
        m.density = density;
        return m;
    }
}

} // namespace

uint32_t bakedMipCount(uint32_t width, uint32_t height) {
    uint32_t side = std::min(width, height), count = 1;
    while ((side >> count) >= kChunk) ++count;
    return side >= kChunk ? count : 1;
}

BakedMesh bakeMesh(const Mesh& mesh, const BakeSettings& settings) {
    auto start = std::chrono::steady_clock::now();
    if (mesh.triangleCount() > kMaxTrianglesPerMesh)
        throw InputError(format("mesh '%s': %u triangles, the baker takes at most %u per mesh",
                                mesh.name.c_str(), mesh.triangleCount(), kMaxTrianglesPerMesh));
    if (!(settings.shadelsPerMetre > 0) || !std::isfinite(settings.shadelsPerMetre))
        throw InputError(format("bake: shadels per metre must be positive (got %g)",
                                double(settings.shadelsPerMetre)));
    uint32_t minResolution = roundUp(std::max(settings.minResolution, kChunk), kChunk);
    uint32_t maxResolution = std::max(minResolution, settings.maxResolution / kChunk * kChunk);
    uint32_t gutter = settings.gutterShadels;

    ChartedMesh charted = buildCharts(mesh, {settings.chartConeDegrees}); // validates indices
    BakedMesh out;
    out.triangleCount = mesh.triangleCount();
    if (out.triangleCount == 0) {
        out.width = out.height = minResolution;
        out.shadelsPerMetre = settings.shadelsPerMetre;
        for (uint32_t k = 0; k < bakedMipCount(out.width, out.height); ++k)
            out.idMaps.emplace_back(size_t(out.width >> k) * (out.height >> k), kEmptyShadel);
        out.bakeSeconds = secondsSince(start);
        return out;
    }

    Mip0 mip0 =
        placeMip0(mesh, charted, settings.shadelsPerMetre, gutter, minResolution, maxResolution);
    // Charting by normal cones is chaotic on smooth closed meshes: which cone packs best (a torus
    // comes out as crescents whose hollows the packer cannot fill, and a wider cone makes fewer,
    // differently curved ones) is only known after packing. A mesh of few charts that packs poorly
    // is cheap to chart again with wider first-growth cones; the layout covering most of its rect
    // is kept (every variant passes the same stretch and density checks).
    // Only at the requested density and unpadded: where triangles smaller than a shadel or a
    // tiny object made the density grow, or the rect is padded to minResolution, chart shapes are
    // not what wastes the rect.
    if (charted.charts.size() <= kGrowthVariantCharts && mip0.utilisation() < kGoodUtilisation &&
        mip0.density == double(settings.shadelsPerMetre) && !mip0.padded &&
        double(mip0.width) * mip0.height <= kGrowthVariantShadels) {
        for (float wide : kGrowthVariantDegrees) {
            ChartedMesh variant = buildCharts(mesh, {settings.chartConeDegrees, wide});
            Mip0 placed =
                placeMip0(mesh, variant, mip0.density, gutter, minResolution, maxResolution, true);
            if (placed.width > 0 && placed.utilisation() > mip0.utilisation() &&
                placed.stats.unownedTriangles <= mip0.stats.unownedTriangles)
                charted = std::move(variant), mip0 = std::move(placed);
        }
    }
    out.degenerateTriangles = charted.degenerateTriangles;
    out.surfaceArea = charted.surfaceArea;
    out.chartCount = uint32_t(charted.charts.size());
    double stretchArea = 0, stretchSum = 0;
    for (const Chart& chart : charted.charts) {
        if (chart.kind == ChartKind::DegenerateCells) continue;
        stretchArea += chart.surfaceArea, stretchSum += chart.surfaceArea * chart.meanStretch;
        out.maxStretch = std::max(out.maxStretch, float(chart.maxStretch));
    }
    if (stretchArea > 0) out.meanStretch = float(stretchSum / stretchArea);
    out.vertexRemap = std::move(charted.vertexRemap);
    out.indices = std::move(charted.indices);
    out.width = mip0.width, out.height = mip0.height;
    out.shadelUv = std::move(mip0.uv);
    out.idMaps.push_back(std::move(mip0.level0));
    double density = mip0.density;
    const IdMapStats& stats0 = mip0.stats;
    out.shadelsPerMetre = float(density);
    out.forcedTriangles = stats0.forcedTriangles;
    out.unownedTriangles = stats0.unownedTriangles;
    out.utilisation = float(mip0.utilisation());
    if (out.unownedTriangles > 0)
        SHADEL_WARN("mesh '%s': %u triangles own no shadel even at %ux%u", mesh.name.c_str(),
                    out.unownedTriangles, out.width, out.height);

    IdMapOptions options;
    options.floodPasses = std::max(2u, gutter + 1);
    options.forceOwnership = false; // coarse levels cannot hold every triangle, nor need to
    uint32_t mips = bakedMipCount(out.width, out.height);
    for (uint32_t k = 1; k < mips; ++k)
        out.idMaps.push_back(buildIdMap(out.shadelUv, out.indices, out.width >> k, out.height >> k,
                                        options, nullptr));
    out.bakeSeconds = secondsSince(start);
    return out;
}

std::vector<BakedMesh> bakeScene(const Scene& scene, const BakeSettings& settings,
                                 const std::string& cacheDir, const BakeProgress& progress,
                                 const std::vector<float>& meshDensity) {
    size_t meshCount = scene.meshes.size();
    // Density is meant per metre of *world* surface. Meshes are often authored in other units
    // and scaled by their instances (a glTF in millimetres under a 0.001 node), so each mesh is
    // baked at shadelsPerMetre times the largest linear scale of any instance using it.
    std::vector<float> worldScale(meshCount, 0.0f);
    for (const Instance& instance : scene.instances) {
        if (instance.mesh >= meshCount) continue;
        glm::mat3 m(instance.transform);
        float scale = std::max({glm::length(m[0]), glm::length(m[1]), glm::length(m[2])});
        if (std::isfinite(scale) && scale > 0)
            worldScale[instance.mesh] = std::max(worldScale[instance.mesh], scale);
    }
    std::vector<BakeSettings> meshSettings(meshCount, settings);
    for (size_t i = 0; i < meshCount; ++i)
        if (worldScale[i] > 0)
            meshSettings[i].shadelsPerMetre = settings.shadelsPerMetre * worldScale[i];
    for (size_t i = 0; i < std::min(meshCount, meshDensity.size()); ++i)
        if (meshDensity[i] > 0 && std::isfinite(meshDensity[i]))
            meshSettings[i].shadelsPerMetre = meshDensity[i];
    std::vector<BakeKey> keys(meshCount);
    std::vector<size_t> firstWithKey(meshCount);
    std::vector<size_t> jobs; // indices of the first mesh of each distinct content
    {
        std::map<std::pair<uint64_t, uint64_t>, size_t> seen;
        for (size_t i = 0; i < meshCount; ++i) {
            keys[i] = bakeKey(scene.meshes[i], meshSettings[i]);
            auto [it, inserted] = seen.emplace(std::make_pair(keys[i].lo, keys[i].hi), i);
            firstWithKey[i] = it->second;
            if (inserted) jobs.push_back(i);
        }
    }

    std::vector<BakedMesh> results(meshCount);
    // An unwritable cache (read-only, full, a file in the way) fails for every mesh alike: warn
    // once, not once per mesh.
    std::atomic<size_t> failedWrites{0};
    std::vector<std::exception_ptr> errors(jobs.size());
    std::atomic<size_t> next{0};
    std::mutex mutex;
    std::condition_variable finished;
    size_t done = 0;

    auto work = [&] {
        for (size_t j; (j = next.fetch_add(1)) < jobs.size();) {
            size_t i = jobs[j];
            const Mesh& mesh = scene.meshes[i];
            try {
                auto start = std::chrono::steady_clock::now();
                std::string path =
                    cacheDir.empty() ? std::string() : bakeCachePath(cacheDir, keys[i]);
                std::string why;
                BakedMesh baked;
                if (!path.empty() && readBakeCache(path, keys[i], mesh, baked, &why)) {
                    // (the read refreshed its use time, for least-recently-used eviction)
                    baked.fromCache = true;
                    baked.bakeSeconds = secondsSince(start);
                } else {
                    if (!path.empty() && why != "missing")
                        SHADEL_WARN("bake cache %s: %s; rebaking", path.c_str(), why.c_str());
                    baked = bakeMesh(mesh, meshSettings[i]);
                    if (!path.empty() && !writeBakeCache(path, keys[i], baked, &why) &&
                        failedWrites.fetch_add(1) == 0)
                        SHADEL_WARN("bake cache: cannot write %s; baking without the cache "
                                    "(further write failures are not reported)",
                                    why.c_str());
                }
                results[i] = std::move(baked);
            } catch (...) {
                errors[j] = std::current_exception();
            }
            std::lock_guard lock(mutex);
            ++done;
            finished.notify_one();
        }
    };

    if (progress) progress(0, jobs.size());
    size_t workerCount = std::clamp<size_t>(settings.threads, 1, std::max<size_t>(jobs.size(), 1));
    std::vector<std::thread> workers;
    for (size_t w = 0; w < workerCount; ++w) workers.emplace_back(work);
    {
        std::unique_lock lock(mutex);
        size_t reported = 0;
        while (reported < jobs.size()) {
            finished.wait(lock, [&] { return done > reported; });
            size_t now = done;
            lock.unlock();
            for (size_t d = reported + 1; d <= now; ++d)
                if (progress) progress(d, jobs.size());
            reported = now;
            lock.lock();
        }
    }
    for (std::thread& t : workers) t.join();
    if (!cacheDir.empty()) {
        // Trim the cache to its limit (a listing of one folder), keeping every file this scene
        // uses.
        std::set<std::string> keep;
        for (size_t j : jobs)
            keep.insert(std::filesystem::path(bakeCachePath(cacheDir, keys[j])).filename());
        CacheUsage removed = evictCache(cacheDir, settings.cacheLimitBytes, keep);
        if (removed.files > 0)
            SHADEL_INFO("cache %s: removed %llu least recently used files (%.1f MiB) to "
                        "stay within %.1f MiB (--cache-limit)",
                        cacheDir.c_str(), (unsigned long long)removed.files,
                        double(removed.bytes) / (1 << 20),
                        double(settings.cacheLimitBytes) / (1 << 20));
    }
    for (const std::exception_ptr& e : errors)
        if (e) std::rethrow_exception(e);
    for (size_t i = 0; i < meshCount; ++i)
        if (firstWithKey[i] != i) {
            results[i] = results[firstWithKey[i]];
            results[i].bakeSeconds = 0; // the work was done once, for the first copy
        }
    return results;
}

std::string bakeReport(const std::vector<BakedMesh>& meshes, double wallSeconds) {
    uint64_t triangles = 0, charts = 0, shadels = 0, covered = 0, degenerate = 0, forced = 0,
             unowned = 0;
    double stretchArea = 0, stretchSum = 0, maxStretch = 1;
    size_t fromCache = 0;
    double bakeSeconds = 0, area = 0;
    uint32_t maxSide = 0, mips = 0;
    for (const BakedMesh& m : meshes) {
        triangles += m.triangleCount, charts += m.chartCount;
        uint64_t s = uint64_t(m.width) * m.height;
        shadels += s;
        covered += uint64_t(std::llround(double(m.utilisation) * double(s)));
        degenerate += m.degenerateTriangles, forced += m.forcedTriangles,
            unowned += m.unownedTriangles;
        fromCache += m.fromCache;
        bakeSeconds += m.bakeSeconds;
        area += m.surfaceArea;
        stretchArea += m.surfaceArea, stretchSum += m.surfaceArea * m.meanStretch;
        maxStretch = std::max(maxStretch, double(m.maxStretch));
        maxSide = std::max({maxSide, m.width, m.height});
        mips = std::max(mips, m.mipCount());
    }
    std::string r;
    r += format("meshes: %zu (%zu from cache)\n", meshes.size(), fromCache);
    r += format("triangles: %llu (degenerate %llu, forced %llu, unowned %llu)\n",
                (unsigned long long)triangles, (unsigned long long)degenerate,
                (unsigned long long)forced, (unsigned long long)unowned);
    r += format("charts: %llu\n", (unsigned long long)charts);
    r += format("shadels (MIP 0): %llu, largest rect side %u, up to %u MIPs\n",
                (unsigned long long)shadels, maxSide, mips);
    r += format("utilisation: %.1f%% (covered / allocated MIP-0 shadels)\n",
                shadels ? 100.0 * double(covered) / double(shadels) : 0.0);
    r += format("stretch: mean %.3f, max %.3f (shadel spacing on the surface / requested)\n",
                stretchArea > 0 ? stretchSum / stretchArea : 1.0, maxStretch);
    r += format("surface: %.3f m^2\n", area);
    r += format("bake time: %.2f s wall, %.2f s summed over meshes\n", wallSeconds, bakeSeconds);
    return r;
}

// Shadel density for a scene: the requested shadels per metre, lowered when the scene's
// surface at that density would need more than `budget` MIP-0 shadels (triangle-ID maps cost
// 2 bytes each). Unit-less CAD files in millimetres are the usual case.
float sceneShadelDensity(const Scene& scene, float requested, double budget, double& area) {
    std::vector<float> maxScale(scene.meshes.size(), 0.0f);
    for (const Instance& inst : scene.instances) {
        float s = std::max({glm::length(glm::vec3(inst.transform[0])),
                            glm::length(glm::vec3(inst.transform[1])),
                            glm::length(glm::vec3(inst.transform[2]))});
        maxScale[inst.mesh] = std::max(maxScale[inst.mesh], s);
    }
    area = 0.0;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        double a = 0.0;
        for (size_t i = 0; i + 2 < mesh.indices.size(); i += 3) {
            glm::vec3 p0 = mesh.vertices[mesh.indices[i]].position;
            glm::vec3 p1 = mesh.vertices[mesh.indices[i + 1]].position;
            glm::vec3 p2 = mesh.vertices[mesh.indices[i + 2]].position;
            a += 0.5 * glm::length(glm::cross(p1 - p0, p2 - p0));
        }
        area += a * double(maxScale[m]) * double(maxScale[m]);
    }
    double needed = area * double(requested) * double(requested);
    if (needed <= budget || area <= 0.0) return requested;
    return float(std::sqrt(budget / area));
}

} // namespace shadel
