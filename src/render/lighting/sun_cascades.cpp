#include "render/lighting/sun_cascades.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/matrix_transform.hpp>

#include "core/error.h"
#include "render/culling/culling.h"
#include "render/forward/forward_passes.h"
#include "render/lighting/shadow_atlas.h"
#include "render/renderer.h"

namespace shadel {

namespace {
// Cascades start this close to the camera (nearer points belong to the first).
constexpr float kFirstSplitNear = 0.5f;
// The practical split scheme: this much logarithmic, the rest uniform.
constexpr float kLogWeight = 0.75f;
// Metres added in front of and behind the scene along the light, so casters are never clipped.
constexpr float kDepthPadding = 1.0f;
} // namespace

struct SunCascadeState {
    uint32_t count = 0;
    uint32_t mapSize = 0; // texels per side of one cascade
    uint32_t columns = 1; // of the atlas
    Aabb sceneBounds;
    ShadowAtlas atlas;
    BufferHandle cascades; // gpu::GpuSunCascades (upload)
    gpu::GpuSunCascades last{};
    float wholeSceneTexel = 0.0f;
};

void SunCascadeStateDeleter::operator()(SunCascadeState* state) const {
    delete state;
}

SunCascadeStatePtr createSunCascades(Renderer& r, const GpuScene& scene) {
    if (r.settings.sunCascades <= 1 || !scene.sunCastsShadow) return nullptr;
    Gpu& gpu = *r.gpu;
    SunCascadeStatePtr s(new SunCascadeState);
    s->count = std::min(r.settings.sunCascades, SUN_MAX_CASCADES);
    // Half the whole-scene map's resolution per cascade: four cascades fill an atlas of the
    // whole-scene map's size, and each still covers far less ground per texel.
    s->mapSize = std::max(r.settings.shadowMapSize / 2, 256u);
    s->columns = std::min(s->count, 2u);
    s->sceneBounds = scene.bounds.valid() ? scene.bounds : Aabb{glm::vec3(-1), glm::vec3(1)};
    s->cascades =
        createBuffer(gpu, {"sunCascades", sizeof(gpu::GpuSunCascades), 0, MemoryKind::Upload});
    if (!s->cascades) throw DeviceError("out of GPU memory for the sun's cascades");
    s->atlas = createShadowAtlas(gpu, "sunCascade", s->mapSize * s->columns,
                                 s->mapSize * ((s->count + s->columns - 1) / s->columns),
                                 "lighting_sun_cascade.vert.spv", r.alphaMasked);
    return s;
}

void destroySunCascades(Renderer& r, SunCascadeStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    destroyShadowAtlas(gpu, state->atlas);
    destroy(gpu, state->cascades);
    state.reset();
}

uint64_t prepareSunCascades(Renderer& r, const gpu::FrameConstants& constants) {
    if (!r.sunCascades) return 0;
    Gpu& gpu = *r.gpu;
    SunCascadeState& s = *r.sunCascades;
    s.wholeSceneTexel = constants.shadowTexelSize;
    gpu::GpuSunCascades c{};
    c.count = s.count;
    c.atlasSlot = slot(gpu, s.atlas.read).value;

    // The camera's basis and its frustum's half-extents per metre of view depth.
    glm::mat4 invView = glm::inverse(constants.view);
    glm::vec3 eye = constants.cameraPosition;
    glm::vec3 right = glm::normalize(glm::vec3(invView[0]));
    glm::vec3 up = glm::normalize(glm::vec3(invView[1]));
    glm::vec3 forward = -glm::normalize(glm::vec3(invView[2]));
    float tanX = 1.0f / std::max(std::abs(constants.proj[0][0]), 1e-6f);
    float tanY = 1.0f / std::max(std::abs(constants.proj[1][1]), 1e-6f);
    c.cameraForward = forward;

    // The slices end where the scene does: its farthest corner's view depth.
    const Aabb& b = s.sceneBounds;
    glm::vec3 sceneCorners[8];
    float far = 0.0f;
    for (int i = 0; i < 8; ++i) {
        sceneCorners[i] = glm::vec3(i & 1 ? b.max.x : b.min.x, i & 2 ? b.max.y : b.min.y,
                                    i & 4 ? b.max.z : b.min.z);
        far = std::max(far, glm::dot(sceneCorners[i] - eye, forward));
    }
    far = std::max(far, kFirstSplitNear * 4.0f);

    // A fixed light basis (rotation only): texel snapping in it is stable under camera motion.
    glm::vec3 dir = glm::normalize(constants.sunDirection);
    glm::vec3 lightUp = std::abs(dir.y) > 0.99f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    glm::mat4 lightView = glm::lookAt(glm::vec3(0.0f), dir, lightUp);
    float sceneZMin = 1e30f, sceneZMax = -1e30f;
    for (const glm::vec3& p : sceneCorners) {
        float z = (lightView * glm::vec4(p, 1.0f)).z;
        sceneZMin = std::min(sceneZMin, z), sceneZMax = std::max(sceneZMax, z);
    }

    float sliceNear = 0.0f;
    for (uint32_t i = 0; i < s.count; ++i) {
        float t = float(i + 1) / float(s.count);
        float logSplit = kFirstSplitNear * std::pow(far / kFirstSplitNear, t);
        float uniformSplit = kFirstSplitNear + (far - kFirstSplitNear) * t;
        float sliceFar = kLogWeight * logSplit + (1.0f - kLogWeight) * uniformSplit;
        // The slice's bounding sphere: centroid of its corners, radius to the farthest.
        glm::vec3 corners[8];
        glm::vec3 center(0.0f);
        for (int k = 0; k < 8; ++k) {
            float d = k & 4 ? sliceFar : sliceNear;
            corners[k] = eye + forward * d + right * (k & 1 ? d * tanX : -d * tanX) +
                         up * (k & 2 ? d * tanY : -d * tanY);
            center += corners[k] * 0.125f;
        }
        float radius = 0.0f;
        for (const glm::vec3& p : corners) radius = std::max(radius, glm::length(p - center));
        radius = std::ceil(radius * 16.0f) / 16.0f; // constant for a camera of fixed field of view
        float texel = 2.0f * radius / float(s.mapSize);
        glm::vec3 lc = glm::vec3(lightView * glm::vec4(center, 1.0f));
        lc.x = std::floor(lc.x / texel) * texel;
        lc.y = std::floor(lc.y / texel) * texel;
        // Depth: the whole scene along the light (and the slice, for cameras outside it), so a
        // caster between the sun and the slice is never clipped.
        float zMin = sceneZMin, zMax = sceneZMax;
        for (const glm::vec3& p : corners) {
            float z = (lightView * glm::vec4(p, 1.0f)).z;
            zMin = std::min(zMin, z), zMax = std::max(zMax, z);
        }
        float nearPlane = -zMax - kDepthPadding, farPlane = -zMin + kDepthPadding;
        glm::mat4 proj = glm::orthoRH_ZO(lc.x - radius, lc.x + radius, lc.y - radius, lc.y + radius,
                                         nearPlane, farPlane);
        c.viewProj[i] = proj * lightView;
        float column = float(i % s.columns), row = float(i / s.columns);
        float rows = float((s.count + s.columns - 1) / s.columns);
        c.atlasRect[i] =
            glm::vec4(column / float(s.columns), row / rows, 1.0f / float(s.columns), 1.0f / rows);
        c.splitFar[i] = sliceFar;
        c.texelWorld[i] = texel;
        c.depthRange = std::max(c.depthRange, farPlane - nearPlane);
        sliceNear = sliceFar;
    }
    s.last = c;
    std::memcpy(mapped(gpu, s.cascades), &c, sizeof(c));
    return address(gpu, s.cascades);
}

uint32_t sunCascadeCount(const Renderer& r) {
    return r.sunCascades ? r.sunCascades->count : 0u;
}

glm::mat4 sunCascadeViewProj(const Renderer& r, uint32_t cascade) {
    return r.sunCascades->last.viewProj[cascade];
}

void recordSunCascades(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    SunCascadeState& s = *r.sunCascades;
    beginShadowAtlas(gpu, cmd, s.atlas, vkBuffer(gpu, r.sceneIndices));
    for (uint32_t i = 0; i < s.count; ++i) {
        setShadowMapViewport(cmd, (i % s.columns) * s.mapSize, (i / s.columns) * s.mapSize,
                             s.mapSize);
        pushConstants(gpu, cmd, RasterPush{frame, i});
        drawShadowViewList(r, cmd, CULL_VIEW_CASCADE0 + i);
    }
    endShadowAtlas(gpu, cmd, s.atlas);
}

void sunCascadeStats(const Renderer& r, nlohmann::json& stats) {
    stats["sun_cascades"] = r.sunCascades ? r.sunCascades->count : 1u;
    if (!r.sunCascades) return;
    const SunCascadeState& s = *r.sunCascades;
    nlohmann::json splits = nlohmann::json::array(), texels = nlohmann::json::array();
    for (uint32_t i = 0; i < s.count; ++i) {
        splits.push_back(s.last.splitFar[i]);
        texels.push_back(s.last.texelWorld[i]);
    }
    stats["sun_cascade_splits_m"] = splits;          // view depth where each cascade ends
    stats["sun_cascade_texel_m"] = texels;           // a texel's width per cascade
    stats["sun_shadow_texel_m"] = s.wholeSceneTexel; // the whole-scene map's
}

} // namespace shadel
