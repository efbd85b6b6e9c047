#include "render/lighting/light_culling.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>

#include "render/camera.h"
#include "render/forward/forward_passes.h"
#include "render/lighting/feature_spectra.h"
#include "render/lighting/light_grid.h"
#include "render/renderer.h"
#include "render/shadel/visibility.h"

namespace shadel {

struct LightCullingState {
    Pipeline tileCull;
    BufferHandle frame;         // gpu::LightingFrame (upload)
    BufferHandle tileRanges;    // uvec2 per tile
    BufferHandle tileLights;    // the pool of list entries
    BufferHandle counters;      // gpu::LightingCounters (readback)
    BufferHandle visibleLights; // uint bit set (readback)
    BufferHandle frustumLights; // uint light indices (upload), the CPU's frustum cull
    uint32_t tilesX = 0, tilesY = 0, poolCapacity = 0;
    // Last frame's counts (read after the GPU finished).
    gpu::LightingCounters last{};
    uint32_t lightsVisible = 0;
    bool tiledThisFrame = false;         // see kMinLightsForTiles
    bool subgroupListsThisFrame = false; // see LightingFrame::subgroupLists
    bool screenTilesThisFrame = false;   // the tile pass runs (not in decoupled frames with a grid)
    LightGridBuffer grid;                // the shadel chunks' light grid (decoupled, tiled)
};

// Below this many lights in the view (and with no blockers to classify), the tile pass costs
// more than it saves: on builtin:default (8 lights, 1280x720, lavapipe) it took 92 ms to save
// forward shading 73 ms. The lights are then looped over directly, the same sum.
constexpr uint32_t kMinLightsForTiles = 16;

// With at most LIGHT_SUBGROUP_MAX_LIGHTS lights in the scene, shading culls them per subgroup
// instead (light_cull.glsl useSubgroupLightList): no tile pass, no chunk culling and its
// barriers. builtin:default (8 lights) 1280x720, lavapipe, interleaved medians: forward shading
// 174 -> 142 ms, shadel shading 205 -> 153 ms, the same images. Not with spectra (their bins
// come from the tile or chunk lists), nor in forward frames with blockers: there the tile pass
// keeps each light's blockers per tile, the subgroup path tests every blocker of a kept light
// per pixel.
// From the settings only (spectra exist exactly when they are not off), so the decoupled state
// can ask before the culling and spectra states exist.
static bool subgroupListsFit(const Renderer& r, uint32_t lightCount, bool blockersOn) {
    return r.settings.lightCulling == LightCulling::Tiled && lightCount > 0 &&
           lightCount <= LIGHT_SUBGROUP_MAX_LIGHTS && r.settings.spectra == Spectra::Off &&
           (r.settings.mode == RenderMode::Decoupled || !blockersOn);
}

bool shadelsCullLightsPerChunk(const Renderer& r, const GpuScene& scene) {
    // (Blockers do not decide it in a decoupled frame.)
    return r.settings.lightCulling == LightCulling::Tiled &&
           !subgroupListsFit(r, uint32_t(scene.lightInfo.size()), false);
}

bool forwardSplitsTileLights(const Renderer& r, const GpuScene& scene) {
    bool blockersOn = r.settings.lightBlockers && scene.blockerCount > 0; // as prepareLightCulling
    if (r.settings.lightCulling != LightCulling::Tiled ||
        subgroupListsFit(r, uint32_t(scene.lightInfo.size()), blockersOn))
        return false;
    // Decoupled frames with the grid have no screen tiles: forward (hybrid) pixels take the
    // grid's candidates (screenTilesThisFrame).
    if (r.decoupled && r.settings.lightGrid) return false;
    for (const gpu::GpuLight& light : scene.lightInfo) // as lightSamplesTextures (spectra.glsl)
        if (light.type == LIGHT_AREA || (light.flags & LIGHT_FLAG_PROJECTED) != 0 ||
            (light.shadowIndex != LIGHT_NO_SHADOW && r.settings.spotShadows))
            return true;
    return false;
}

void LightCullingStateDeleter::operator()(LightCullingState* state) const {
    delete state;
}

namespace {
struct CullPush {
    uint64_t frame;
    uint32_t depthSlot;
    uint32_t visibilitySlot; // feature spectra: the pixels' materials (SPECTRUM_MATERIAL)
};
} // namespace

LightCullingStatePtr createLightCulling(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    LightCullingStatePtr s(new LightCullingState);
    s->tilesX = (r.internalWidth + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE;
    s->tilesY = (r.internalHeight + LIGHT_TILE_SIZE - 1) / LIGHT_TILE_SIZE;
    uint32_t tiles = s->tilesX * s->tilesY;
    // Lists share one pool sized for 256 lights per tile on average (at least 1 M entries, at
    // most 8 M = 64 MiB); a frame that needs more counts the tiles that overflowed.
    s->poolCapacity = uint32_t(std::clamp<uint64_t>(uint64_t(tiles) * 256u, 1u << 20, 1u << 23));
    auto need = [](BufferHandle b) {
        if (!b) throw DeviceError("out of GPU memory for the light culling buffers");
        return b;
    };
    s->frame = need(
        createBuffer(gpu, {"lighting.frame", sizeof(gpu::LightingFrame), 0, MemoryKind::Upload}));
    s->tileRanges = need(createBuffer(gpu, {"lighting.tileRanges", uint64_t(tiles) * 8}));
    s->tileLights = need(createBuffer(gpu, {"lighting.tileLights", uint64_t(s->poolCapacity) * 8}));
    s->counters = need(createBuffer(
        gpu, {"lighting.counters", sizeof(gpu::LightingCounters), 0, MemoryKind::Readback}));
    s->visibleLights = need(createBuffer(
        gpu, {"lighting.visibleLights", std::max<uint64_t>((scene.lightCount + 31) / 32, 1) * 4, 0,
              MemoryKind::Readback}));
    s->frustumLights = need(
        createBuffer(gpu, {"lighting.frustumLights", std::max<uint64_t>(scene.lightCount, 1) * 4, 0,
                           MemoryKind::Upload}));
    s->tileCull = createComputePipeline(gpu, "lightTileCull", "lighting_tile_cull.comp.spv");
    return s;
}

void destroyLightCulling(Renderer& r, LightCullingStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    destroy(gpu, state->tileCull);
    for (BufferHandle b : {state->frame, state->tileRanges, state->tileLights, state->counters,
                           state->visibleLights, state->frustumLights})
        destroy(gpu, b);
    destroyLightGrid(gpu, state->grid);
    state.reset();
}

float lightReach(const gpu::GpuLight& l) {
    if (l.type == LIGHT_DIRECTIONAL || l.range <= 0.0f)
        return std::numeric_limits<float>::infinity();
    float extra = l.type == LIGHT_TUBE ? l.halfLength : 0.0f;
    if (l.type == LIGHT_AREA) extra = std::hypot(l.halfLength, l.radius);
    return l.range + extra;
}

uint64_t prepareLightCulling(Renderer& r, const GpuScene& scene,
                             const std::vector<gpu::GpuLight>& lights,
                             const gpu::FrameConstants& constants) {
    const glm::mat4& viewProj = constants.viewProj;
    Gpu& gpu = *r.gpu;
    LightCullingState& s = *r.lightCulling;
    gpu::LightingFrame f{};
    // Spheres against the camera frustum; a light without a finite range always passes.
    std::array<glm::vec4, 6> planes = frustumPlanes(viewProj);
    uint32_t* visible = static_cast<uint32_t*>(mapped(gpu, s.frustumLights));
    uint32_t count = 0;
    for (uint32_t i = 0; i < lights.size(); ++i) {
        const gpu::GpuLight& l = lights[i];
        bool in = true;
        if (glm::vec4 sphere = lightBoundingSphere(l); sphere.w >= 0.0f) {
            for (const glm::vec4& p : planes)
                in = in && glm::dot(glm::vec3(p), glm::vec3(sphere)) + p.w >= -sphere.w;
        }
        if (in) visible[count++] = i;
    }
    f.frustumLights = address(gpu, s.frustumLights);
    f.frustumLightCount = count;
    f.tileLights = address(gpu, s.tileLights);
    f.tileRanges = address(gpu, s.tileRanges);
    f.blockers = address(gpu, scene.blockers);
    f.portals = address(gpu, scene.portals);
    f.lightBlockers = address(gpu, scene.lightBlockerLists);
    f.counters = address(gpu, s.counters);
    f.visibleLights = address(gpu, s.visibleLights);
    f.tilesX = s.tilesX;
    f.tilesY = s.tilesY;
    f.blockersOn = r.settings.lightBlockers && scene.blockerCount > 0 ? 1u : 0u;
    s.subgroupListsThisFrame = subgroupListsFit(r, uint32_t(lights.size()), f.blockersOn != 0u);
    f.subgroupLists = s.subgroupListsThisFrame ? 1u : 0u;
    s.tiledThisFrame = r.settings.lightCulling == LightCulling::Tiled &&
                       !s.subgroupListsThisFrame &&
                       (count >= kMinLightsForTiles || f.blockersOn != 0u);
    f.tiled = s.tiledThisFrame ? 1u : 0u;
    f.poolCapacity = s.poolCapacity;
    f.blockerCount = scene.blockerCount;
    // Tile shading needs every tile's features and bin, whatever the light count.
    if (r.spectra && r.settings.lightCulling == LightCulling::Tiled) {
        s.tiledThisFrame = true;
        f.tiled = 1u;
    }
    (usesChunkSpectra(r) ? f.chunkSpectra : f.spectra) =
        prepareFeatureSpectra(r, s.tilesX, s.tilesY);
    // Screen tiles and shadel chunks take their candidate lights from the light grid.
    f.lightGrid = f.tiled != 0u && r.settings.lightGrid ? updateLightGrid(gpu, s.grid, lights) : 0;
    // Screen tiles' lists serve forward shading. A decoupled frame's shadel chunks cull against
    // the grid themselves, and its few forward pixels (hybrid objects) take the grid's
    // candidates at their point, so it skips the tile pass (205 of 1198 ms on builtin:lights
    // at 1280x720, lavapipe).
    s.screenTilesThisFrame = s.tiledThisFrame && !(r.decoupled && f.lightGrid != 0);
    f.screenTiles = s.screenTilesThisFrame ? 1u : 0u;
    prepareShadows(r, lights, constants, f);
    std::memcpy(mapped(gpu, s.frame), &f, sizeof(f));
    return address(gpu, s.frame);
}

void recordLightCulling(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    LightCullingState& s = *r.lightCulling;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.counters), 0, VK_WHOLE_SIZE, 0);
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.visibleLights), 0, VK_WHOLE_SIZE, 0);
    recordSpectraReset(r, cmd);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    if (r.settings.lightCulling != LightCulling::Tiled || !s.screenTilesThisFrame) return;
    // The prepass depth is sampled here, then goes back to the attachment layout the passes
    // after this one test against.
    sceneDepthToSampled(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    bind(gpu, cmd, s.tileCull);
    uint32_t visibilitySlot = usesTileShading(r) ? visibilityBufferSlot(r) : NO_TEXTURE;
    pushConstants(gpu, cmd, CullPush{frame, slot(gpu, r.depthRead).value, visibilitySlot});
    vkCmdDispatch(cmd, s.tilesX, s.tilesY, 1);
    sceneDepthToAttachment(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

bool lightCullingThisFrame(const Renderer& r) {
    return r.lightCulling &&
           (r.lightCulling->tiledThisFrame || r.lightCulling->subgroupListsThisFrame);
}

void readLightCullingStats(Renderer& r) {
    LightCullingState& s = *r.lightCulling;
    Gpu& gpu = *r.gpu;
    if (!s.tiledThisFrame && !s.subgroupListsThisFrame) { // nothing counted (nor cleared)
        s.last = {};
        s.lightsVisible = 0;
        return;
    }
    std::memcpy(&s.last, mapped(gpu, s.counters), sizeof(s.last));
    const uint32_t* bits = static_cast<const uint32_t*>(mapped(gpu, s.visibleLights));
    size_t words = size(gpu, s.visibleLights) / 4;
    s.lightsVisible = 0;
    for (size_t i = 0; i < words; ++i) s.lightsVisible += uint32_t(std::popcount(bits[i]));
}

void lightCullingStats(const Renderer& r, const GpuScene& scene, nlohmann::json& stats) {
    const LightCullingState& s = *r.lightCulling;
    bool subgroups = s.subgroupListsThisFrame;
    bool tiled = s.tiledThisFrame || subgroups;
    stats["light_culling"] = subgroups ? "subgroups (few lights)"
                             : tiled   ? "tiled"
                             : r.settings.lightCulling == LightCulling::Tiled
                                 ? "none (fewer lights in view than tiles pay for)"
                                 : "none";
    stats["blockers"] = r.settings.lightBlockers ? "on" : "off";
    stats["light_blockers"] = scene.blockerCount;
    // Without culling every light is considered everywhere.
    stats["lights_visible"] = tiled ? s.lightsVisible : scene.lightCount;
    stats["light_tile_pairs"] = s.tiledThisFrame ? s.last.lightTilePairs : 0u;
    // Spectra per light: of those pairs, the lights that read no texture (each tile lists them
    // first), and whether the raster forward pass shades them in a loop without that code.
    stats["light_tile_plain_pairs"] = s.tiledThisFrame ? s.last.lightTilePlainPairs : 0u;
    stats["light_tile_split"] = r.forwardSplitsTileLights;
    stats["light_tiles"] = s.tilesX * s.tilesY;
    stats["light_screen_tiles"] = s.screenTilesThisFrame; // false: decoupled, chunks + grid
    stats["per_pixel_blocker_tiles"] = s.last.perPixelBlockerTiles;
    stats["light_tiles_overflowed"] = s.last.tilesOverflowed;
    // The shadel path's lists: whole chunks', or with few lights its subgroups' (the counts
    // below then count (light, subgroup) pairs; subgroups of 8 shadels on lavapipe).
    stats["light_chunk_unit"] = s.last.lightSubgroupLists != 0 ? "subgroup" : "chunk";
    stats["light_subgroup_lists"] = s.last.lightSubgroupLists;
    stats["light_chunk_pairs"] = s.last.lightChunkPairs;
    // Lights the chunks tested to find those pairs (every light per chunk without the grid).
    stats["light_chunk_candidates"] = s.last.lightGridCandidates;
    stats["light_grid_entries"] = s.grid.entries;
    stats["light_grid_builds"] = s.grid.builds; // rebuilt only in frames whose lights changed
    stats["per_pixel_blocker_chunks"] = s.last.perPixelBlockerChunks;
    stats["light_chunks_overflowed"] = s.last.chunksOverflowed;
    stats["lights_culled_by_blockers"] = s.last.lightsCulledByBlockers;
}

} // namespace shadel
