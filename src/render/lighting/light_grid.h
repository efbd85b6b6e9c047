#pragma once
// The light grid: the frame's lights bucketed in world space, so a shadel chunk's light
// culling (shaders/shadel/shade.comp, cullChunkLights) and a screen tile's
// (shaders/lighting/tile_cull.comp) test the few lights near their box instead of every light
// of the scene (the frustum's, for tiles). Chunk culling cannot use the screen tiles' lists (a
// chunk is not in screen space), and testing every light per chunk was most of the shadel
// shading time on builtin:lights (2020 lights). Layout and query: common/shared_types.h
// GpuLightGrid; the GPU side is shaders/lighting/light_grid.glsl. The query's candidates are
// a superset of the lights that meet the box, and the exact test that follows is unchanged, so
// the lists (and images) are the same as without the grid (--light-grid off).
#include <optional>
#include <vector>

#include "common/shared_types.h"
#include "rhi/handles.h"

namespace shadel {

struct Gpu;

// What the grid holds, built on the CPU (no GPU addresses yet).
struct LightGridData {
    gpu::GpuLightGrid header{};
    std::vector<glm::uvec2> buckets; // levels * LIGHT_GRID_BUCKETS: first entry, count
    std::vector<uint32_t> entries;   // light indices
};

// A light's bounding sphere as the shaders' lightSphere (lighting/light_cull.glsl) has it;
// w < 0: infinite (directional, or no range).
glm::vec4 lightBoundingSphere(const gpu::GpuLight& light);

LightGridData buildLightGrid(const std::vector<gpu::GpuLight>& lights);

// The lights a box tests, in the order the GPU query reads them (duplicates included): nullopt
// when the box is larger than the grid's coarsest cell (the chunk then tests every light).
std::optional<std::vector<uint32_t>> lightGridCandidates(const LightGridData& grid,
                                                         glm::vec3 boxMin, glm::vec3 boxMax);

// The grid in one upload buffer (header, buckets, entries), rebuilt only when the lights change.
struct LightGridBuffer {
    BufferHandle buffer;
    uint64_t capacity = 0;
    std::vector<gpu::GpuLight> builtFrom;
    uint64_t address = 0;
    uint32_t entries = 0;
    uint32_t builds = 0;
};

// This frame's grid (GpuLightGrid address) for `lights`.
uint64_t updateLightGrid(Gpu& gpu, LightGridBuffer& grid, const std::vector<gpu::GpuLight>& lights);
void destroyLightGrid(Gpu& gpu, LightGridBuffer& grid);

} // namespace shadel
