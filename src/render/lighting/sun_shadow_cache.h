#pragma once
// The sun's shadow map, kept while nothing it shows changes. The map is fitted to the scene, not
// to the camera (renderer.cpp sunViewProj), so with a still sun, still casters and casters whose
// LODs do not follow the camera, last frame's map is this frame's: it is drawn once, from every
// caster in the sun's volume (the instance cull then leaves out its usual "can this caster's
// shadow reach the camera's frustum" test, which would tie the map to one camera), and redrawn
// only when the sun's view, a caster (animated playback) or a material (an alpha-masked
// caster's texture streamed or edited) changes. The spot maps are kept the same way
// (render/lighting/spot_shadows.h); the cascades follow the camera and are drawn every frame.
// --shadow-cache off draws the map every frame from the camera-culled list (as before).
#include <nlohmann/json.hpp>

#include "common/shared_types.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SunShadowCache {
    bool drawn = false;           // a map is kept (drawn by an earlier frame)
    bool drawnAllCasters = false; // ... from every caster in the sun's volume
    const GpuScene* drawnScene = nullptr;
    glm::mat4 drawnViewProj{0.0f};
    // The sun's list this frame (SUN_LIST_*): none when the kept map is not redrawn.
    uint32_t listThisFrame = SUN_LIST_CAMERA;
    uint32_t draws = 0; // frames that drew the map
};

// Whether the map may be kept: --shadow-cache on, and no caster's LOD follows the camera
// (--lod on), nor does another pass draw the sun's list and expect it culled for this camera
// (--shadow-culling whole-scene: the spots and cascades; --gi lpv: the reflective shadow maps).
// A map to keep is drawn from every caster in the sun's volume (CullingFrame::sunList); the
// list is the map's alone then, so a frame that keeps the map builds none.
bool sunShadowKeepable(const Renderer& r);
// Whether this frame changed what a kept shadow map (the sun's, the spots') shows of its casters:
// playback moved or deformed one, a material was edited, or a streamed texture changed an
// alpha-masked material (the maps' only material input: other materials are drawn depth-only).
// Sets Renderer::shadowCastersChanged, after Renderer::changedMaterials is known.
void noteShadowCasterChanges(Renderer& r, const GpuScene& scene);
// The kept maps are stale for reasons the renderer cannot see (a shader hot reload): draw them
// again next frame.
void forgetKeptShadowMaps(Renderer& r);
// Decides, before the frame's passes are declared, whether "shadowMap" draws this frame, and
// from which list: every caster to keep the map, or (on a frame that changed it: playback, a
// sun edit) the camera-culled one, as without the cache.
void prepareSunShadowMap(Renderer& r, const GpuScene& scene, const gpu::FrameConstants& constants);
bool sunShadowMapThisFrame(const Renderer& r);
// "sun_shadow_map_draws": frames that drew the map; "sun_shadow_cache": on | off.
void sunShadowCacheStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
