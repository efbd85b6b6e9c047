#pragma once
// Spot light shadows: every shadow-casting spot (Light::castsShadow, up to
// LIGHT_MAX_SPOT_SHADOWS, GpuLight::shadowIndex) gets a rectangle of one depth atlas, placed by
// the 2-D block allocator (core/block_allocator.h): soft (PCSS) spots 1024^2, the others 512^2.
// Each map is the spot's perspective view of the opaque shadow casters, culled per spot on the
// GPU (render/culling/culling.h; --shadow-culling whole-scene: the sun's list). Shading
// (shaders/lighting/shadows.glsl, from the shared shadeSurface) filters it with PCF, or with
// PCSS for spots flagged soft; the sun gets PCSS with --sun-shadows pcss.
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SpotShadowState;
struct SpotShadowStateDeleter {
    void operator()(SpotShadowState* state) const;
};
using SpotShadowStatePtr = std::unique_ptr<SpotShadowState, SpotShadowStateDeleter>;

// Null when the scene has no shadow-casting spot.
SpotShadowStatePtr createSpotShadows(Renderer& r, const GpuScene& scene);
void destroySpotShadows(Renderer& r, SpotShadowStatePtr& state);

// This frame's spot views (from `lights`, this frame's) into `f` (spotShadows, the atlas slot)
// and the sun's soft-shadow constants.
void prepareShadows(Renderer& r, const std::vector<gpu::GpuLight>& lights,
                    const gpu::FrameConstants& constants, gpu::LightingFrame& f);
// After prepareShadows: this frame's world -> clip of shadow index `index`; false when the spot
// has no map (the atlas was full) or there is no such index.
bool spotShadowViewProj(const Renderer& r, uint32_t index, glm::mat4& viewProj);
// Shadow indices (LIGHT_MAX_SPOT_SHADOWS at most used), 0 without spot shadows.
uint32_t spotShadowCount(const Renderer& r);
// Whether the maps are drawn this frame: the first frame, or the spots changed since they were
// last drawn, or the camera did while it chooses the casters (whole-scene culling or --lod on).
bool spotShadowMapsThisFrame(const Renderer& r);
// The maps are drawn again next frame whatever changed (render/lighting/sun_shadow_cache.h
// forgetKeptShadowMaps).
void redrawSpotShadowMaps(Renderer& r);
// "spotShadowMaps": the atlas cleared, then each spot's view into its rectangle.
void recordSpotShadowMaps(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
void spotShadowStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
