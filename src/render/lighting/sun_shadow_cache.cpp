#include "render/lighting/sun_shadow_cache.h"

#include <algorithm>

#include "render/renderer.h"

namespace shadel {

bool sunShadowKeepable(const Renderer& r) {
    return r.settings.sunShadowCache && !r.settings.lod &&
           r.settings.shadowCulling == ShadowCulling::PerView && !r.gi;
}

static bool anySet(const std::vector<uint8_t>& flags) {
    return std::find(flags.begin(), flags.end(), uint8_t(1)) != flags.end();
}

void noteShadowCasterChanges(Renderer& r, const GpuScene& scene) {
    bool changed = anySet(r.reposedInstances) || anySet(r.edits.materialsChanged);
    // Streaming restreams normal and roughness maps too: only alpha-masked materials' textures
    // reach a shadow map (Renderer::alphaMasked: the scene has some, else the maps draw depth
    // only).
    for (size_t m = 0; r.alphaMasked && !changed && m < r.changedMaterials.size(); ++m)
        changed = r.changedMaterials[m] && m < scene.materialInfo.size() &&
                  (scene.materialInfo[m].flags & MATERIAL_ALPHA_MASK) != 0u;
    r.shadowCastersChanged = changed;
}

void forgetKeptShadowMaps(Renderer& r) {
    r.sunShadowCache.drawn = false;
    redrawSpotShadowMaps(r);
}

void prepareSunShadowMap(Renderer& r, const GpuScene& scene, const gpu::FrameConstants& constants) {
    SunShadowCache& c = r.sunShadowCache;
    if (!r.settings.shadows) { // --shadows off: the map is never read
        c.listThisFrame = SUN_LIST_NONE;
        return;
    }
    bool keepable = sunShadowKeepable(r);
    bool changed = c.drawn && (c.drawnScene != &scene || c.drawnViewProj != constants.sunViewProj ||
                               r.shadowCastersChanged);
    if (keepable && c.drawn && c.drawnAllCasters && !changed) {
        c.listThisFrame = SUN_LIST_NONE;
        return;
    }
    // A map that changes this frame is drawn from the camera-culled list, as without the cache:
    // while playback moves something every frame, every caster in the sun's volume would cost
    // every frame (builtin:many's whole town: ~300 ms against ~180 on lavapipe). The first frame
    // that changes nothing draws them all, and that map is kept.
    c.listThisFrame = keepable && !changed ? SUN_LIST_ALL : SUN_LIST_CAMERA;
    c.drawn = true;
    c.drawnAllCasters = c.listThisFrame == SUN_LIST_ALL;
    c.drawnScene = &scene;
    c.drawnViewProj = constants.sunViewProj;
    c.draws++;
}

bool sunShadowMapThisFrame(const Renderer& r) {
    return r.sunShadowCache.listThisFrame != SUN_LIST_NONE;
}

void sunShadowCacheStats(const Renderer& r, nlohmann::json& stats) {
    stats["sun_shadow_cache"] = sunShadowKeepable(r) ? "on" : "off";
    stats["sun_shadow_map_draws"] = r.sunShadowCache.draws;
}

} // namespace shadel
