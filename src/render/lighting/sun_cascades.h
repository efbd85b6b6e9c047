#pragma once
// Cascaded sun shadows (PCF and PCSS over cascades). One orthographic map
// fitted to the whole scene spends its texels evenly over a town, so near the camera a texel is
// metres wide and small casters' shadows vanish. With --sun-cascades N (2..4) the camera's view
// depth is cut into N slices (the "practical" split: a blend of logarithmic and uniform), each
// with its own map: an orthographic view of the slice's bounding sphere (its size does not
// change as the camera turns) whose centre is snapped to the map's texels in a fixed light
// basis, so the maps do not swim while the camera moves. The maps are rectangles of one depth
// atlas. Shading (shaders/lighting/shadows.glsl, sunCascadeShadow, from the shared shadeSurface,
// so forward and shadel paths alike) picks the first cascade whose slice holds the point and
// filters it with PCF or PCSS; beyond the last slice the whole-scene map still answers.
// --sun-cascades 1 keeps that one map alone (no cascade state at all).
//
// Casters: each cascade draws its own list, culled on the GPU against its box with the camera's
// and the sun's lists (render/culling/culling.h); with --shadow-culling whole-scene, the sun
// view's list (culled against the whole-scene volume, which contains every cascade's).
#include <memory>

#include <nlohmann/json.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SunCascadeState;
struct SunCascadeStateDeleter {
    void operator()(SunCascadeState* state) const;
};
using SunCascadeStatePtr = std::unique_ptr<SunCascadeState, SunCascadeStateDeleter>;

// Null with --sun-cascades 1 or when the sun casts no shadow.
SunCascadeStatePtr createSunCascades(Renderer& r, const GpuScene& scene);
void destroySunCascades(Renderer& r, SunCascadeStatePtr& state);

// This frame's cascades for the camera of `constants`: LightingFrame::sunCascades (0 without).
uint64_t prepareSunCascades(Renderer& r, const gpu::FrameConstants& constants);
// The cascades' count (0 without) and, after prepareSunCascades, this frame's world -> clip.
uint32_t sunCascadeCount(const Renderer& r);
glm::mat4 sunCascadeViewProj(const Renderer& r, uint32_t cascade);
// "sunCascades": the atlas cleared, then each cascade's view of the casters into its rectangle.
void recordSunCascades(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// sun_cascades, sun_cascade_splits_m, sun_cascade_texel_m, sun_shadow_texel_m.
void sunCascadeStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
