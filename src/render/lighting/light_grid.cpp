#include "render/lighting/light_grid.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/spot_bounds.h"
#include "core/error.h"
#include "render/lighting/light_culling.h"
#include "rhi/resources.h"

namespace shadel {

namespace {

struct CellRange {
    glm::ivec3 lo, hi;
};

// The cells a sphere meets at one level, grown by a margin that covers the GPU's float
// rounding of a box's cells (a chunk near a cell boundary may round into the next cell).
bool sphereCells(const gpu::GpuLightGrid& g, glm::vec4 sphere, double cell, CellRange& out) {
    double margin = cell * 0.01 + double(sphere.w) * 1e-5;
    for (int a = 0; a < 3; ++a) {
        double c = (double(sphere[a]) - double(g.origin[a])) / cell;
        double r = (double(sphere.w) + margin) / cell;
        double lo = std::floor(c - r), hi = std::floor(c + r);
        if (!(std::abs(lo) < LIGHT_GRID_MAX_CELL && std::abs(hi) < LIGHT_GRID_MAX_CELL))
            return false;
        out.lo[a] = int(lo);
        out.hi[a] = int(hi);
    }
    return true;
}

uint32_t bucketOf(glm::ivec3 cell) {
    return LIGHT_GRID_HASH(cell.x, cell.y, cell.z);
}

} // namespace

glm::vec4 lightBoundingSphere(const gpu::GpuLight& l) {
    float reach = lightReach(l);
    if (!(std::isfinite(reach) && reach > 0.0f)) return glm::vec4(l.position, -1.0f);
    if (l.type == LIGHT_SPOT || l.type == LIGHT_SPOT_SQUARE) // as lightSphere (light_cull.glsl)
        return shader::spotSectorSphere(l.position, l.direction, reach,
                                        shader::spotConeCosSin(l.type, l.spotOffset, l.spotScale));
    return glm::vec4(l.position, reach);
}

LightGridData buildLightGrid(const std::vector<gpu::GpuLight>& lights) {
    LightGridData d;
    gpu::GpuLightGrid& g = d.header;
    std::vector<glm::vec4> spheres(lights.size());
    std::vector<float> radii;
    glm::vec3 lo(std::numeric_limits<float>::max());
    for (size_t i = 0; i < lights.size(); ++i) {
        spheres[i] = lightBoundingSphere(lights[i]);
        bool finite = spheres[i].w >= 0.0f && std::isfinite(spheres[i].w) &&
                      std::isfinite(spheres[i].x) && std::isfinite(spheres[i].y) &&
                      std::isfinite(spheres[i].z);
        if (!finite) {
            spheres[i].w = -1.0f;
            continue;
        }
        radii.push_back(spheres[i].w);
        lo = glm::min(lo, glm::vec3(spheres[i]) - spheres[i].w);
    }
    // Level 0's cell is the median light's diameter: such a light meets at most 3 cells per
    // axis there, and a chunk as small as a light needs at most 2x2x2 cells.
    if (!radii.empty()) {
        std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
        g.cellSize = std::clamp(2.0f * radii[radii.size() / 2], 0.05f, 1e5f);
        g.origin = lo;
        g.levels = LIGHT_GRID_LEVELS;
    }
    d.buckets.assign(size_t(g.levels) * LIGHT_GRID_BUCKETS, glm::uvec2(0));

    // Two passes over the same cells: count per bucket, then fill (entries in light order).
    std::vector<uint32_t> globalLights;
    std::vector<std::vector<uint32_t>> big(g.levels);
    std::vector<uint32_t> lightBuckets;
    auto visit = [&](auto&& emit) {
        for (uint32_t i = 0; i < lights.size(); ++i) {
            glm::vec4 s = spheres[i];
            if (s.w < 0.0f || g.levels == 0) continue;
            double cell = g.cellSize;
            for (uint32_t level = 0; level < g.levels; ++level, cell *= 2.0) {
                CellRange range;
                bool ok = sphereCells(g, s, cell, range);
                glm::ivec3 span = range.hi - range.lo + 1;
                if (!ok || span.x > LIGHT_GRID_MAX_SPAN || span.y > LIGHT_GRID_MAX_SPAN ||
                    span.z > LIGHT_GRID_MAX_SPAN) {
                    emit(level, UINT32_MAX, i);
                    continue;
                }
                // Once per bucket: cells of one light that hash together list it once (a
                // point's query reads one bucket and must not count a light twice).
                lightBuckets.clear();
                for (int z = range.lo.z; z <= range.hi.z; ++z)
                    for (int y = range.lo.y; y <= range.hi.y; ++y)
                        for (int x = range.lo.x; x <= range.hi.x; ++x)
                            lightBuckets.push_back(bucketOf({x, y, z}));
                std::sort(lightBuckets.begin(), lightBuckets.end());
                lightBuckets.erase(std::unique(lightBuckets.begin(), lightBuckets.end()),
                                   lightBuckets.end());
                for (uint32_t bucket : lightBuckets) emit(level, bucket, i);
            }
        }
    };
    visit([&](uint32_t level, uint32_t bucket, uint32_t) {
        if (bucket != UINT32_MAX) d.buckets[level * LIGHT_GRID_BUCKETS + bucket].y++;
    });
    uint32_t first = 0;
    for (glm::uvec2& b : d.buckets) {
        b.x = first;
        first += b.y;
        b.y = 0;
    }
    d.entries.resize(first);
    visit([&](uint32_t level, uint32_t bucket, uint32_t light) {
        if (bucket == UINT32_MAX) {
            big[level].push_back(light);
            return;
        }
        glm::uvec2& b = d.buckets[level * LIGHT_GRID_BUCKETS + bucket];
        d.entries[b.x + b.y++] = light;
    });
    for (uint32_t i = 0; i < lights.size(); ++i)
        if (spheres[i].w < 0.0f) globalLights.push_back(i);
    g.globalFirst = uint32_t(d.entries.size());
    g.globalCount = uint32_t(globalLights.size());
    d.entries.insert(d.entries.end(), globalLights.begin(), globalLights.end());
    for (uint32_t level = 0; level < g.levels; ++level) {
        g.big[level] = glm::uvec2(uint32_t(d.entries.size()), uint32_t(big[level].size()));
        d.entries.insert(d.entries.end(), big[level].begin(), big[level].end());
    }
    return d;
}

std::optional<std::vector<uint32_t>> lightGridCandidates(const LightGridData& d, glm::vec3 boxMin,
                                                         glm::vec3 boxMax) {
    // The same steps as shaders/lighting/light_grid.glsl gridChunkLights, in float as there.
    const gpu::GpuLightGrid& g = d.header;
    glm::vec3 size = boxMax - boxMin;
    float extent = std::max(size.x, std::max(size.y, size.z));
    uint32_t level = 0;
    float cell = g.cellSize;
    while (level < g.levels && cell < extent) {
        cell *= 2.0f;
        level++;
    }
    if (level >= g.levels) return std::nullopt;
    glm::vec3 a = glm::floor((boxMin - g.origin) / cell),
              b = glm::floor((boxMax - g.origin) / cell);
    for (int k = 0; k < 3; ++k)
        if (!(std::abs(a[k]) < float(LIGHT_GRID_MAX_CELL) &&
              std::abs(b[k]) < float(LIGHT_GRID_MAX_CELL)))
            return std::nullopt;
    std::vector<uint32_t> out;
    auto take = [&](glm::uvec2 list) {
        out.insert(out.end(), d.entries.begin() + list.x, d.entries.begin() + list.x + list.y);
    };
    take({g.globalFirst, g.globalCount});
    take(g.big[level]);
    glm::ivec3 lo(a), hi(b);
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x)
                take(d.buckets[level * LIGHT_GRID_BUCKETS + bucketOf({x, y, z})]);
    return out;
}

uint64_t updateLightGrid(Gpu& gpu, LightGridBuffer& grid,
                         const std::vector<gpu::GpuLight>& lights) {
    bool same = grid.address != 0 && grid.builtFrom.size() == lights.size() &&
                std::memcmp(grid.builtFrom.data(), lights.data(),
                            lights.size() * sizeof(gpu::GpuLight)) == 0;
    if (same) return grid.address;
    LightGridData d = buildLightGrid(lights);
    uint64_t bucketBytes = d.buckets.size() * sizeof(glm::uvec2);
    uint64_t bytes = sizeof(gpu::GpuLightGrid) + bucketBytes + d.entries.size() * 4;
    if (bytes > grid.capacity) {
        // The previous frame has finished (the renderer waits for every frame), so the old
        // buffer can go now. Grown with slack so animated lights do not reallocate each frame.
        if (grid.buffer) destroy(gpu, grid.buffer);
        grid.capacity = bytes + bytes / 2;
        grid.buffer =
            createBuffer(gpu, {"lighting.lightGrid", grid.capacity, 0, MemoryKind::Upload});
        if (!grid.buffer) throw DeviceError("out of GPU memory for the light grid");
    }
    uint64_t base = address(gpu, grid.buffer);
    d.header.buckets = base + sizeof(gpu::GpuLightGrid);
    d.header.entries = d.header.buckets + bucketBytes;
    auto* p = static_cast<uint8_t*>(mapped(gpu, grid.buffer));
    std::memcpy(p, &d.header, sizeof(d.header));
    if (bucketBytes) std::memcpy(p + sizeof(gpu::GpuLightGrid), d.buckets.data(), bucketBytes);
    if (!d.entries.empty())
        std::memcpy(p + sizeof(gpu::GpuLightGrid) + bucketBytes, d.entries.data(),
                    d.entries.size() * 4);
    grid.builtFrom = lights;
    grid.address = base;
    grid.entries = uint32_t(d.entries.size());
    grid.builds++;
    return base;
}

void destroyLightGrid(Gpu& gpu, LightGridBuffer& grid) {
    if (grid.buffer) destroy(gpu, grid.buffer);
    grid = {};
}

} // namespace shadel
