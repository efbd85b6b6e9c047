#include "render/lighting/spot_shadows.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "core/block_allocator.h"
#include "core/error.h"
#include "render/culling/culling.h"
#include "render/forward/forward_passes.h"
#include "render/lighting/shadow_atlas.h"
#include "render/renderer.h"

namespace shadel {

namespace {
constexpr uint32_t kAtlasSize = 4096;
constexpr uint32_t kSoftMapSize = 1024; // PCSS spots: wide kernels want the resolution
constexpr uint32_t kMapSize = 512;
constexpr float kNearPlane = 0.05f;
// The sun's PCSS: penumbra width per metre between occluder and receiver, tan(1.5 degrees) (the
// real sun's 0.27 would stay under a texel of the 2048^2 map over a town).
constexpr float kSunPenumbraScale = 0.0262f;
} // namespace

struct SpotShadowState {
    ShadowAtlas atlas;
    BufferHandle shadows;          // gpu::GpuSpotShadow[] (upload)
    std::vector<uint32_t> lightOf; // light index per shadow index
    std::vector<glm::uvec4> rects; // atlas texels: x, y, size, 1 if placed
    uint32_t placed = 0;
    uint64_t atlasTexelsUsed = 0;
    // The maps are drawn again only when what they see may have changed: the spots (this
    // frame's views differ from the last drawn) or the caster lists, which follow the camera
    // when it chooses them (see cameraChoosesCasters).
    std::vector<gpu::GpuSpotShadow> drawnViews;
    glm::mat4 drawnCamera{0.0f};
    bool redraw = true;
    uint32_t redraws = 0;
};

void SpotShadowStateDeleter::operator()(SpotShadowState* state) const {
    delete state;
}

SpotShadowStatePtr createSpotShadows(Renderer& r, const GpuScene& scene) {
    if (!r.settings.spotShadows) return nullptr;
    std::vector<uint32_t> lightOf;
    for (uint32_t i = 0; i < scene.lightInfo.size(); ++i) {
        uint32_t index = scene.lightInfo[i].shadowIndex;
        if (index == LIGHT_NO_SHADOW) continue;
        if (lightOf.size() <= index) lightOf.resize(index + 1, ~0u);
        lightOf[index] = i;
    }
    if (lightOf.empty()) return nullptr;
    Gpu& gpu = *r.gpu;
    SpotShadowStatePtr s(new SpotShadowState);
    s->lightOf = lightOf;
    // Place every map at once, largest first (the allocator's batched insert).
    std::vector<Extent<2>> extents;
    for (uint32_t light : lightOf) {
        bool soft = (scene.lightInfo[light].flags & LIGHT_FLAG_SOFT_SHADOW) != 0u;
        uint32_t size = soft ? kSoftMapSize : kMapSize;
        extents.push_back({size, size});
    }
    BlockAllocator<2> allocator({kAtlasSize, kAtlasSize});
    auto placements = allocator.insertBatch(extents);
    for (size_t i = 0; i < placements.size(); ++i) {
        const auto& p = placements[i];
        s->rects.push_back(p ? glm::uvec4(p->origin[0], p->origin[1], p->extent[0], 1u)
                             : glm::uvec4(0u));
        s->placed += p ? 1u : 0u;
    }
    s->atlasTexelsUsed = allocator.usedVolume();

    s->shadows = createBuffer(
        gpu, {"spotShadows", lightOf.size() * sizeof(gpu::GpuSpotShadow), 0, MemoryKind::Upload});
    if (!s->shadows) throw DeviceError("out of GPU memory for the spot shadow atlas");
    s->atlas = createShadowAtlas(gpu, "spotShadow", kAtlasSize, kAtlasSize,
                                 "lighting_spot_shadow.vert.spv", r.alphaMasked);
    return s;
}

void destroySpotShadows(Renderer& r, SpotShadowStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    destroyShadowAtlas(gpu, state->atlas);
    destroy(gpu, state->shadows);
    state.reset();
}

// The spot's perspective view: its outer cone (round) or pyramid (square) fills the map.
// Whether the camera's moves change what the spot maps draw: with whole-scene culling they
// draw the sun's list, culled to the casters whose sun shadow reaches the camera's frustum;
// with per-view culling only the LODs (--lod on, chosen from the camera) do.
static bool cameraChoosesCasters(const Renderer& r) {
    return r.settings.shadowCulling == ShadowCulling::WholeScene || r.settings.lod;
}

static gpu::GpuSpotShadow spotView(const gpu::GpuLight& l, glm::uvec4 rect) {
    gpu::GpuSpotShadow s{};
    float tanHalf;
    if (l.type == LIGHT_SPOT_SQUARE) {
        // spotOffset / spotScale = tan(outer) per side; the pyramid's corners need sqrt(2) more
        // only for a round frustum, and this one is square like the cone.
        tanHalf = l.spotOffset / std::max(l.spotScale, 1e-6f);
    } else {
        float cosOuter = std::clamp(-l.spotOffset / std::max(l.spotScale, 1e-6f), 0.05f, 0.9999f);
        tanHalf = std::tan(std::acos(cosOuter));
    }
    tanHalf = std::clamp(tanHalf, 0.01f, std::tan(glm::radians(85.0f)));
    glm::vec3 dir = glm::normalize(l.direction);
    glm::vec3 up = l.type == LIGHT_SPOT_SQUARE ? glm::cross(l.axis, dir)
                   : std::abs(dir.y) > 0.99f   ? glm::vec3(1, 0, 0)
                                               : glm::vec3(0, 1, 0);
    float range = l.range > 0.0f ? l.range : 200.0f;
    glm::mat4 view = glm::lookAt(l.position, l.position + dir, up);
    glm::mat4 proj = glm::perspectiveRH_ZO(2.0f * std::atan(tanHalf), 1.0f, kNearPlane, range);
    s.viewProj = proj * view;
    s.atlasRect = glm::vec4(glm::vec2(rect.x, rect.y), glm::vec2(rect.z)) / float(kAtlasSize);
    s.nearPlane = rect.w ? kNearPlane : -1.0f; // < 0: no map (the atlas was full)
    s.farPlane = range;
    s.lightSize = l.radius;
    s.texelAngle = 2.0f * tanHalf / float(std::max(rect.z, 1u));
    return s;
}

void prepareShadows(Renderer& r, const std::vector<gpu::GpuLight>& lights,
                    const gpu::FrameConstants& constants, gpu::LightingFrame& f) {
    f.sunSoftShadows = r.settings.sunSoftShadows ? 1u : 0u;
    f.sunPenumbraScale = kSunPenumbraScale;
    glm::mat4 inv = glm::inverse(constants.sunViewProj);
    glm::vec4 a = inv * glm::vec4(0, 0, 0, 1), b = inv * glm::vec4(0, 0, 1, 1);
    f.sunDepthRange = glm::length(glm::vec3(b) / b.w - glm::vec3(a) / a.w);
    f.sunCascades = prepareSunCascades(r, constants); // 0 with --sun-cascades 1
    f.spotShadowAtlas = NO_TEXTURE;
    f.spotShadows = 0;
    if (!r.spotShadows) return;
    Gpu& gpu = *r.gpu;
    SpotShadowState& s = *r.spotShadows;
    auto* out = static_cast<gpu::GpuSpotShadow*>(mapped(gpu, s.shadows));
    std::vector<gpu::GpuSpotShadow> views(s.lightOf.size());
    for (size_t i = 0; i < s.lightOf.size(); ++i)
        views[i] = s.lightOf[i] < lights.size() ? spotView(lights[s.lightOf[i]], s.rects[i])
                                                : gpu::GpuSpotShadow{};
    bool cameraMoved = constants.viewProj != s.drawnCamera;
    s.redraw = s.drawnViews.size() != views.size() || (cameraMoved && cameraChoosesCasters(r)) ||
               std::memcmp(views.data(), s.drawnViews.data(),
                           views.size() * sizeof(gpu::GpuSpotShadow)) != 0 ||
               r.shadowCastersChanged; // playback, edits, streamed alpha-masked textures
    if (s.redraw) {
        s.drawnViews = views;
        s.drawnCamera = constants.viewProj;
        s.redraws++;
    }
    std::memcpy(out, views.data(), views.size() * sizeof(gpu::GpuSpotShadow));
    f.spotShadows = address(gpu, s.shadows);
    f.spotShadowAtlas = slot(gpu, s.atlas.read).value;
}

void redrawSpotShadowMaps(Renderer& r) {
    if (r.spotShadows) r.spotShadows->drawnViews.clear();
}

bool spotShadowViewProj(const Renderer& r, uint32_t index, glm::mat4& viewProj) {
    if (!r.spotShadows || index >= r.spotShadows->drawnViews.size()) return false;
    // drawnViews is this frame's: the maps are redrawn whenever the views change.
    const gpu::GpuSpotShadow& view = r.spotShadows->drawnViews[index];
    if (view.nearPlane < 0.0f) return false;
    viewProj = view.viewProj;
    return true;
}

uint32_t spotShadowCount(const Renderer& r) {
    return r.spotShadows ? uint32_t(r.spotShadows->lightOf.size()) : 0u;
}

bool spotShadowMapsThisFrame(const Renderer& r) {
    return r.spotShadows != nullptr && r.spotShadows->redraw;
}

void recordSpotShadowMaps(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    SpotShadowState& s = *r.spotShadows;
    beginShadowAtlas(gpu, cmd, s.atlas, vkBuffer(gpu, r.sceneIndices));
    for (uint32_t i = 0; i < s.rects.size(); ++i) {
        glm::uvec4 rect = s.rects[i];
        if (!rect.w) continue;
        setShadowMapViewport(cmd, rect.x, rect.y, rect.z);
        pushConstants(gpu, cmd, RasterPush{frame, 2u + i});
        drawShadowViewList(r, cmd, CULL_VIEW_SPOT0 + i);
    }
    endShadowAtlas(gpu, cmd, s.atlas);
}

void spotShadowStats(const Renderer& r, nlohmann::json& stats) {
    stats["sun_shadows"] = r.settings.sunSoftShadows ? "pcss" : "pcf";
    if (!r.spotShadows) {
        stats["spot_shadow_maps"] = 0;
        return;
    }
    const SpotShadowState& s = *r.spotShadows;
    stats["spot_shadow_maps"] = s.placed;
    stats["spot_shadow_maps_unplaced"] = uint32_t(s.rects.size()) - s.placed;
    stats["spot_shadow_atlas_draws"] = s.redraws; // frames that drew the maps
    stats["spot_shadow_atlas_fill"] =
        double(s.atlasTexelsUsed) / (double(kAtlasSize) * double(kAtlasSize));
}

} // namespace shadel
