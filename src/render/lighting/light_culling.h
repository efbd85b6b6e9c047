#pragma once
// Tiled light culling: after the depth prepass, one compute workgroup per 16x16-pixel
// tile builds that tile's light list from its depth bounds, with light blockers and portals
// classified per tile (shaders/lighting/tile_cull.comp). Forward shading reads the list of
// its pixel's tile; the shadel path culls per chunk inside its shading workgroup
// (shaders/shadel/shade.comp) against the same lights and blockers. Both call the shared
// shadeSurface (shaders/common/lighting.glsl).
#include <cstdint>
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct LightCullingState;
struct LightCullingStateDeleter {
    void operator()(LightCullingState* state) const;
};
using LightCullingStatePtr = std::unique_ptr<LightCullingState, LightCullingStateDeleter>;

LightCullingStatePtr createLightCulling(Renderer& r, const GpuScene& scene);
void destroyLightCulling(Renderer& r, LightCullingStatePtr& state);

// This frame's LightingFrame (host-visible), with the lights that meet the camera frustum
// (`lights`: this frame's, `viewProj`: the camera's); returns its address for
// FrameConstants::lighting.
// Also this frame's shadow constants (render/lighting/spot_shadows.h).
uint64_t prepareLightCulling(Renderer& r, const GpuScene& scene,
                             const std::vector<gpu::GpuLight>& lights,
                             const gpu::FrameConstants& constants);
// The radius about GpuLight::position within which the light reaches anything: its range,
// plus a tube's half length or an area light's half diagonal; infinite without a range (and for
// directional lights). The CPU's side of lightSphere (shaders/lighting/light_cull.glsl).
float lightReach(const gpu::GpuLight& light);
// Whether the raster forward pass should shade a screen tile's lights that read no texture in a
// loop of their own (spectra per light, SPECTRUM_LIGHT_SPLIT_CONSTANT_ID): its pixels read tile
// lists (not per-subgroup lists: too many lights, or blockers in a forward frame), and some
// light reads a texture. Chosen once, for the pipeline (Renderer::forwardSplitsTileLights): the
// second loop costs the scenes that never fill it (builtin:default forward shading 130 -> 139 ms),
// and a scene edit that changes either only costs speed, never the image.
bool forwardSplitsTileLights(const Renderer& r, const GpuScene& scene);
// Whether decoupled shading may cull a chunk's lights in shared memory (tiled culling with more
// lights than per-subgroup lists take): otherwise its pipelines leave that culling and its
// barriers out (SHADE_OPTIONAL_CHUNK_LIGHTS). From the settings and the scene, so the decoupled
// state can ask before the culling state exists; a frame's choice always agrees.
bool shadelsCullLightsPerChunk(const Renderer& r, const GpuScene& scene);
// Whether this frame culls lights (and so records the culling pass): tile lists
// (--light-culling tiled and enough lights in view, or blockers to classify) or, with few
// lights, per-subgroup lists in shading; otherwise shading loops over the lights directly.
bool lightCullingThisFrame(const Renderer& r);
// The culling pass: clears the counters shading's culling adds to, then (screen tiles only)
// the tile pass; with --light-culling none it records nothing.
void recordLightCulling(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// After the frame: counters into the stats (lights, lights_visible, light_tile_pairs, ...).
void readLightCullingStats(Renderer& r);
void lightCullingStats(const Renderer& r, const GpuScene& scene, nlohmann::json& stats);

} // namespace shadel
