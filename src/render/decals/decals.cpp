#include "render/decals/decals.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/camera.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"

namespace shadel {

struct DecalState {
    Pipeline tileCull, objectCull;
    BufferHandle decals;        // gpu::GpuDecal[]
    BufferHandle frame;         // gpu::DecalFrame (upload)
    BufferHandle frustumDecals; // uint decal indices (upload), the CPU's frustum cull
    BufferHandle tileRanges;    // uvec2 per (tile, stage)
    BufferHandle objectRanges;  // uvec2 per instance (decoupled)
    BufferHandle entries;       // the pool of decal indices
    BufferHandle counters;      // gpu::DecalCounters (readback)
    BufferHandle visible;       // uint bit set (readback)
    std::vector<gpu::GpuDecal> cpuDecals;
    uint32_t tilesX = 0, tilesY = 0, instanceCount = 0, poolCapacity = 0;
    uint32_t frustumCount = 0;
    // Last frame's counts (read after the GPU finished).
    gpu::DecalCounters last{};
    uint32_t visibleCount = 0;
};

void DecalStateDeleter::operator()(DecalState* state) const {
    delete state;
}

namespace {
struct TilePush {
    uint64_t frame;
    uint32_t depthSlot;
};
struct ObjectPush {
    uint64_t frame;
};
} // namespace

gpu::GpuDecal gpuDecal(const Decal& decal) {
    gpu::GpuDecal g{};
    glm::vec3 z = glm::normalize(decal.axisZ);
    glm::vec3 x = decal.axisX - z * glm::dot(z, decal.axisX);
    x = glm::length(x) > 1e-6f
            ? glm::normalize(x)
            : glm::normalize(
                  glm::cross(z, std::abs(z.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0)));
    glm::vec3 y = glm::cross(z, x);
    glm::vec3 size = glm::max(decal.size, glm::vec3(1e-4f));
    const glm::vec3 axes[3] = {x, y, z};
    glm::mat4 m(0.0f);
    for (int row = 0; row < 3; ++row) { // box coordinate = dot(axis, p - centre) / size
        for (int col = 0; col < 3; ++col) m[col][row] = axes[row][col] / size[row];
        m[3][row] = -glm::dot(axes[row], decal.center) / size[row];
    }
    m[3][3] = 1.0f;
    g.worldToBox = m;
    g.center = decal.center;
    g.axisX = x;
    g.axisY = y;
    g.axisZ = z;
    g.halfSize = size * 0.5f;
    g.kinds = decal.kinds;
    g.pattern = uint32_t(decal.pattern);
    g.color = decal.color;
    g.roughness = decal.roughness;
    g.normalStrength = decal.normalStrength;
    g.occlusion = decal.occlusion;
    return g;
}

DecalStatePtr createDecals(Renderer& r, const GpuScene& scene) {
    if (!r.settings.decals || scene.decals.empty()) return nullptr;
    Gpu& gpu = *r.gpu;
    DecalStatePtr s(new DecalState);
    for (const Decal& d : scene.decals) s->cpuDecals.push_back(gpuDecal(d));
    s->tilesX = (r.internalWidth + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE;
    s->tilesY = (r.internalHeight + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE;
    uint32_t tiles = s->tilesX * s->tilesY;
    // Decoupled: a coarse list per instance, refined per chunk by shadel shading.
    s->instanceCount = r.decoupled ? scene.instanceCount : 0u;
    // One pool for every list: 16 entries per tile or instance on average (at least 64 K, at
    // most 4 M = 16 MiB); a frame that needs more drops the tile lists that do not fit and
    // counts them (an object list that does not fit stands for every frustum decal).
    s->poolCapacity = uint32_t(
        std::clamp<uint64_t>(uint64_t(tiles + s->instanceCount) * 16u, 1u << 16, 1u << 22));
    auto need = [](BufferHandle b) {
        if (!b) throw DeviceError("out of GPU memory for the decal buffers");
        return b;
    };
    size_t count = s->cpuDecals.size();
    s->decals = need(
        createBuffer(gpu, {"decals.boxes", count * sizeof(gpu::GpuDecal), 0, MemoryKind::Upload}));
    std::memcpy(mapped(gpu, s->decals), s->cpuDecals.data(), count * sizeof(gpu::GpuDecal));
    s->frame =
        need(createBuffer(gpu, {"decals.frame", sizeof(gpu::DecalFrame), 0, MemoryKind::Upload}));
    s->frustumDecals =
        need(createBuffer(gpu, {"decals.frustumDecals", count * 4, 0, MemoryKind::Upload}));
    const uint64_t rangeBytes = 8ull * DECAL_STAGES;
    s->tileRanges = need(createBuffer(gpu, {"decals.tileRanges", tiles * rangeBytes}));
    s->objectRanges = need(
        createBuffer(gpu, {"decals.objectRanges", std::max<uint64_t>(s->instanceCount, 1) * 8ull}));
    s->entries = need(createBuffer(gpu, {"decals.entries", uint64_t(s->poolCapacity) * 4}));
    s->counters = need(createBuffer(
        gpu, {"decals.counters", sizeof(gpu::DecalCounters), 0, MemoryKind::Readback}));
    s->visible = need(
        createBuffer(gpu, {"decals.visible", ((count + 31) / 32) * 4, 0, MemoryKind::Readback}));
    s->tileCull = createComputePipeline(gpu, "decalTileCull", "decals_tile_cull.comp.spv");
    if (r.decoupled)
        s->objectCull =
            createComputePipeline(gpu, "decalObjectCull", "decals_object_cull.comp.spv");
    return s;
}

void destroyDecals(Renderer& r, DecalStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    destroy(gpu, state->tileCull);
    if (state->objectCull.pipeline) destroy(gpu, state->objectCull);
    for (BufferHandle b : {state->decals, state->frame, state->frustumDecals, state->tileRanges,
                           state->objectRanges, state->entries, state->counters, state->visible})
        destroy(gpu, b);
    state.reset();
}

uint64_t prepareDecalFrame(Renderer& r, const gpu::FrameConstants& constants) {
    if (!r.decals) return 0;
    Gpu& gpu = *r.gpu;
    DecalState& s = *r.decals;
    // Boxes against the camera frustum (one frustum cull serves every stage).
    std::array<glm::vec4, 6> planes = frustumPlanes(constants.viewProj);
    uint32_t* out = static_cast<uint32_t*>(mapped(gpu, s.frustumDecals));
    s.frustumCount = 0;
    for (uint32_t i = 0; i < s.cpuDecals.size(); ++i) {
        const gpu::GpuDecal& d = s.cpuDecals[i];
        bool in = true;
        for (const glm::vec4& p : planes) {
            glm::vec3 n(p);
            float reach = std::abs(glm::dot(n, d.axisX)) * d.halfSize.x +
                          std::abs(glm::dot(n, d.axisY)) * d.halfSize.y +
                          std::abs(glm::dot(n, d.axisZ)) * d.halfSize.z;
            in = in && glm::dot(n, d.center) + p.w >= -reach;
        }
        if (in) out[s.frustumCount++] = i;
    }
    gpu::DecalFrame f{};
    f.decals = address(gpu, s.decals);
    f.frustumDecals = address(gpu, s.frustumDecals);
    f.tileRanges = address(gpu, s.tileRanges);
    f.objectRanges = address(gpu, s.objectRanges);
    f.entries = address(gpu, s.entries);
    f.counters = address(gpu, s.counters);
    f.visibleDecals = address(gpu, s.visible);
    f.frustumDecalCount = s.frustumCount;
    f.poolCapacity = s.poolCapacity;
    f.tilesX = s.tilesX;
    f.tilesY = s.tilesY;
    f.instanceCount = s.instanceCount;
    std::memcpy(mapped(gpu, s.frame), &f, sizeof(f));
    return address(gpu, s.frame);
}

void recordDecalCulling(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!r.decals) return;
    pass(rec, "decalCulling", [&r, frame](VkCommandBuffer cmd) {
        Gpu& gpu = *r.gpu;
        DecalState& s = *r.decals;
        vkCmdFillBuffer(cmd, vkBuffer(gpu, s.counters), 0, VK_WHOLE_SIZE, 0);
        vkCmdFillBuffer(cmd, vkBuffer(gpu, s.visible), 0, VK_WHOLE_SIZE, 0);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        // Tiles: the prepass depth bounds each tile's frustum (sampled here, then back to the
        // attachment layout later passes test against).
        sceneDepthToSampled(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
        bind(gpu, cmd, s.tileCull);
        pushConstants(gpu, cmd, TilePush{frame, slot(gpu, r.depthRead).value});
        vkCmdDispatch(cmd, s.tilesX, s.tilesY, 1);
        sceneDepthToAttachment(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
        // Decoupled: one invocation per instance, its coarse list. Shadel shading refines it
        // per chunk in the workgroup, from the positions it rebuilds anyway (decals.h).
        if (r.decoupled && s.instanceCount > 0) {
            bind(gpu, cmd, s.objectCull);
            pushConstants(gpu, cmd, ObjectPush{frame});
            vkCmdDispatch(cmd, (s.instanceCount + 63) / 64, 1, 1);
        }
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    });
}

void readDecalStats(Renderer& r) {
    if (!r.decals) return;
    Gpu& gpu = *r.gpu;
    DecalState& s = *r.decals;
    std::memcpy(&s.last, mapped(gpu, s.counters), sizeof(s.last));
    const uint32_t* bits = static_cast<const uint32_t*>(mapped(gpu, s.visible));
    s.visibleCount = 0;
    for (size_t i = 0; i < (s.cpuDecals.size() + 31) / 32; ++i)
        s.visibleCount += uint32_t(std::popcount(bits[i]));
}

void decalStats(const Renderer& r, nlohmann::json& stats) {
    const DecalState* s = r.decals.get();
    stats["decals"] = s ? uint32_t(s->cpuDecals.size()) : 0u;
    stats["decals_in_frustum"] = s ? s->frustumCount : 0u;
    stats["decals_visible"] = s ? s->visibleCount : 0u;
    stats["decal_tile_pairs"] = s ? s->last.tilePairs : 0u;
    stats["decal_shadel_pairs"] = s ? s->last.shadelPairs : 0u;
    stats["decal_object_pairs"] = s ? s->last.objectPairs : 0u;
    stats["decal_list_entries"] = s ? s->last.poolEntries : 0u;
    stats["decal_lists_overflowed"] = s ? s->last.listsOverflowed : 0u;
}

} // namespace shadel
