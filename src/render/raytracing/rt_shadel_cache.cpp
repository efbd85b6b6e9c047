#include "render/raytracing/rt_shadel_cache.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "common/dispatch_2d.h"
#include "core/log.h"
#include "render/renderer.h"
#include "render/shadel/decoupled.h"

namespace shadel {

// 2048^2 texels of two rgba16f layers: 64 MiB (and 64 more for the rgba32ui spot visibilities
// when spot shadows are traced). At two MIPs coarser than the lit layer that is
// 16x fewer texels than a 4096^2 shade storage holds shadels, so it is never the bottleneck.
static constexpr uint32_t kAtlasSize = 2048;
static constexpr uint32_t kAtlasAlignment = 8; // rects in whole tiles
// Frames an instance out of view keeps its rect (and history), so a short glance away does not
// restart its convergence.
static constexpr uint64_t kKeepFrames = 30;

struct RtShadelPush {
    uint64_t frame;
};

void createRtShadelCache(Renderer& r, const GpuScene& scene, bool spotShadows, RtShadelCache& c) {
    Gpu& gpu = *r.gpu;
    c.atlasSize = kAtlasSize;
    TextureDesc d;
    d.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.width = d.height = kAtlasSize;
    d.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
              VK_IMAGE_USAGE_TRANSFER_DST_BIT; // cleared once, below
    d.name = "rt.shadelCache.terms";
    c.terms = createTexture(gpu, d);
    d.name = "rt.shadelCache.indirect";
    c.indirect = createTexture(gpu, d);
    if (spotShadows) {
        d.format = VK_FORMAT_R32G32B32A32_UINT; // the spots' visibilities, 8 bits each
        d.name = "rt.shadelCache.spotShadows";
        c.spots = createTexture(gpu, d);
        if (!c.spots) throw DeviceError("out of GPU memory for the RT shadel cache");
    }
    if (!c.terms || !c.indirect) throw DeviceError("out of GPU memory for the RT shadel cache");
    // Every texel starts empty (no rays, no surface): the read pools texels around the ones it
    // needs (rt_apply.glsl), and memory an earlier renderer used must never show through.
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        VkImageSubresourceRange all{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        for (TextureHandle t : {c.terms, c.indirect, c.spots}) {
            if (!t) continue;
            imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                         VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, 0,
                         VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
            VkClearColorValue empty{};
            if (t == c.terms) empty.float32[0] = empty.float32[1] = 1.0f; // sun, AO, -, rays
            if (t == c.spots)
                empty.uint32[0] = empty.uint32[1] = empty.uint32[2] = empty.uint32[3] =
                    0xFFFFFFFFu; // every spot visible
            vkCmdClearColorImage(cmd, vkImage(gpu, t), VK_IMAGE_LAYOUT_GENERAL, &empty, 1, &all);
            imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                         VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                         VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                             VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
    });
    c.termsWrite = createWriteView(gpu, c.terms);
    c.indirectWrite = createWriteView(gpu, c.indirect);
    c.termsRead = createReadView(gpu, c.terms);
    c.indirectRead = createReadView(gpu, c.indirect);
    if (c.spots) {
        c.spotsWrite = createWriteView(gpu, c.spots);
        c.spotsRead = createReadView(gpu, c.spots);
    }
    c.atlas =
        std::make_unique<BlockAllocator<2>>(Extent<2>{kAtlasSize, kAtlasSize}, kAtlasAlignment);
    c.entries.assign(scene.instanceCount, {});
    c.objects.assign(std::max(scene.instanceCount, 1u), {});
    size_t maxTiles = size_t(kAtlasSize / 8) * (kAtlasSize / 8);
    c.objectBuffer =
        createBuffer(gpu, {"rt.shadelCache.objects", c.objects.size() * sizeof(gpu::RtShadelObject),
                           0, MemoryKind::Upload});
    c.tileBuffer = createBuffer(
        gpu, {"rt.shadelCache.tiles", maxTiles * sizeof(gpu::RtShadelTile), 0, MemoryKind::Upload});
    if (!c.objectBuffer || !c.tileBuffer)
        throw DeviceError("out of GPU memory for the RT shadel cache lists");
    c.trace = createComputePipeline(gpu, "rtShadelTrace", "raytracing_rt_shadels.comp.spv");
}

void destroyRtShadelCache(Renderer& r, RtShadelCache& c) {
    Gpu& gpu = *r.gpu;
    if (!c.terms) return;
    destroy(gpu, c.trace);
    destroy(gpu, c.termsWrite);
    destroy(gpu, c.indirectWrite);
    destroy(gpu, c.termsRead);
    destroy(gpu, c.indirectRead);
    if (c.spots) {
        destroy(gpu, c.spotsWrite);
        destroy(gpu, c.spotsRead);
        destroy(gpu, c.spots);
    }
    destroy(gpu, c.terms);
    destroy(gpu, c.indirect);
    destroy(gpu, c.objectBuffer);
    destroy(gpu, c.tileBuffer);
    c = {};
}

static glm::uvec2 levelSize(glm::uvec2 mip0, uint32_t level) {
    return glm::max(mip0 >> level, glm::uvec2(1u));
}

static float distanceToBox(glm::vec3 p, glm::vec3 lo, glm::vec3 hi) {
    return glm::length(glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f)));
}

// The MIP of the instance's shadel space the cache holds: the finest its nearest point can need
// on screen (a shadel per pixel), plus the offset.
static uint32_t cacheLevel(const Renderer& r, const ShadelMeshInfo& mesh,
                           const gpu::GpuInstance& inst, const CameraView& camera) {
    float scale =
        std::max({glm::length(glm::vec3(inst.model[0])), glm::length(glm::vec3(inst.model[1])),
                  glm::length(glm::vec3(inst.model[2]))});
    float pixelsPerUnit = std::abs(camera.proj[1][1]) * 0.5f * float(r.internalHeight);
    float d = std::max(distanceToBox(camera.position, inst.worldMin, inst.worldMax), 1e-3f);
    float shadelsPerPixel = mesh.shadelsPerUnit * scale * d / pixelsPerUnit; // at MIP 0
    int finest = std::max(0, int(std::floor(std::log2(std::max(shadelsPerPixel, 1e-6f)))));
    int level = finest + int(r.settings.rt.shadelMipOffset);
    return uint32_t(std::clamp(level, 0, int(mesh.mipCount) - 1));
}

void prepareRtShadelCache(Renderer& r, const GpuScene& scene, const CameraView& camera,
                          RtShadelCache& c, gpu::RtFrame& rt) {
    Gpu& gpu = *r.gpu;
    uint64_t now = r.framesRendered + 1;
    c.tiles.clear();
    c.texelsTraced = 0;
    c.instancesCached = 0;
    c.instancesWithoutRoom = 0;
    // Animated playback reposed something (render/animation: moved or skinned): its shadows,
    // occlusion and bounce light reach other instances too, so every history restarts.
    bool sceneMoved = std::find(r.reposedInstances.begin(), r.reposedInstances.end(), 1) !=
                      r.reposedInstances.end();
    for (uint32_t i = 0; i < scene.instanceCount; ++i) {
        RtShadelCache::Entry& e = c.entries[i];
        gpu::RtShadelObject& o = c.objects[i];
        o.flags = 0;
        const gpu::GpuInstance& inst = scene.instanceInfo[i];
        const ShadelMeshInfo* mesh =
            inst.mesh < scene.shadelMeshes.size() ? &scene.shadelMeshes[inst.mesh] : nullptr;
        bool visible = mesh && mesh->mipCount > 0 && drawnDecoupled(r, i);
        if (!visible) {
            if (e.placement && now - e.lastSeen > kKeepFrames) {
                c.atlas->remove(e.placement->id);
                e.placement.reset();
            }
            continue;
        }
        e.lastSeen = now;
        uint32_t level = cacheLevel(r, *mesh, inst, camera);
        // Hysteresis: a rect is kept while its level stays within one of the wanted one.
        bool keep = e.placement && std::abs(int(level) - int(e.level)) <= 1;
        // Moved, or a light changed (GI, or ray-traced spot shadows): the history no longer holds.
        bool lightsMatter = r.settings.rt.gi || rt.spotShadowCount != 0;
        bool reset = !keep || e.model != inst.model || sceneMoved ||
                     (lightsMatter && !r.changedLightVolumes.empty());
        if (!keep) {
            if (e.placement) c.atlas->remove(e.placement->id);
            glm::uvec2 size = levelSize(mesh->mip0Size, level);
            e.placement = c.atlas->insert(Extent<2>{size.x, size.y});
            e.level = level;
        }
        e.model = inst.model;
        if (!e.placement) {
            c.instancesWithoutRoom++;
            continue;
        }
        glm::uvec2 size = levelSize(mesh->mip0Size, e.level);
        o.origin = glm::uvec2(e.placement->origin[0], e.placement->origin[1]);
        o.size = size;
        o.level = e.level;
        o.idMapOffset = mesh->idMapOffset[e.level];
        o.flags = RT_SHADEL_VALID | (reset ? RT_SHADEL_RESET : 0u);
        c.historyResets += reset;
        c.instancesCached++;
        c.texelsTraced += size.x * size.y;
        for (uint32_t y = 0; y < (size.y + 7) / 8; ++y)
            for (uint32_t x = 0; x < (size.x + 7) / 8; ++x) c.tiles.push_back({i, x | y << 16});
    }
    std::memcpy(mapped(gpu, c.objectBuffer), c.objects.data(),
                c.objects.size() * sizeof(gpu::RtShadelObject));
    std::memcpy(mapped(gpu, c.tileBuffer), c.tiles.data(),
                c.tiles.size() * sizeof(gpu::RtShadelTile));
    c.tileCount = uint32_t(c.tiles.size());
    rt.shadelObjects = address(gpu, c.objectBuffer);
    rt.shadelTiles = address(gpu, c.tileBuffer);
    rt.shadelTileCount = c.tileCount;
    rt.historyRays = r.settings.rt.historyRays;
    rt.shadelTermsWrite = slot(gpu, c.termsWrite).value;
    rt.shadelTermsRead = slot(gpu, c.termsRead).value;
    rt.shadelIndirectWrite = slot(gpu, c.indirectWrite).value;
    rt.shadelIndirectRead = slot(gpu, c.indirectRead).value;
    rt.shadelSpotWrite = c.spots ? slot(gpu, c.spotsWrite).value : NO_TEXTURE;
    rt.shadelSpotRead = c.spots ? slot(gpu, c.spotsRead).value : NO_TEXTURE;
}

void recordRtShadelTrace(Renderer& r, VkCommandBuffer cmd, uint64_t frame, RtShadelCache& c) {
    Gpu& gpu = *r.gpu;
    // Last frame's shading read the cache this pass rewrites.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    if (c.tileCount) {
        bind(gpu, cmd, c.trace);
        pushConstants(gpu, cmd, RtShadelPush{frame});
        shader::Dispatch2d groups = shader::dispatch2d(c.tileCount);
        vkCmdDispatch(cmd, groups.x, groups.y, 1);
    }
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                  VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

} // namespace shadel
