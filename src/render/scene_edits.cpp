#include "render/scene_edits.h"

#include <cstring>

#include "core/error.h"
#include "core/log.h"
#include "render/gpu_scene.h"
#include "render/renderer.h"

namespace shadel {

gpu::GpuLight currentLight(const Renderer& r, const GpuScene& scene, uint32_t index) {
    if (index >= scene.lightInfo.size())
        throw InputError(
            format("light %u: the scene has %zu lights", index, scene.lightInfo.size()));
    return r.edits.lights.empty() ? scene.lightInfo[index] : r.edits.lights[index];
}

const gpu::GpuMaterial& currentMaterial(const Renderer& r, const GpuScene& scene, uint32_t index) {
    if (index >= scene.materialInfo.size())
        throw InputError(
            format("material %u: the scene has %zu materials", index, scene.materialInfo.size()));
    return r.edits.materials.empty() ? scene.materialInfo[index] : r.edits.materials[index];
}

SunEdit currentSun(const Renderer& r, const GpuScene& scene) {
    if (r.edits.sun) return *r.edits.sun;
    return {glm::normalize(scene.sunDirection), scene.sunColor};
}

void editLight(Renderer& r, const GpuScene& scene, uint32_t index, const gpu::GpuLight& light) {
    currentLight(r, scene, index); // range check
    if (r.edits.lights.empty()) r.edits.lights = scene.lightInfo;
    gpu::GpuLight l = light;
    // What the scene decided and an edit must not break: its shadow map and blocker lists.
    l.shadowIndex = scene.lightInfo[index].shadowIndex;
    l.blockerFirst = scene.lightInfo[index].blockerFirst;
    l.blockerCount = scene.lightInfo[index].blockerCount;
    r.edits.lights[index] = l;
}

void editMaterial(Renderer& r, const GpuScene& scene, uint32_t index,
                  const gpu::GpuMaterial& material) {
    currentMaterial(r, scene, index); // range check
    SceneEdits& e = r.edits;
    if (e.materials.empty()) {
        e.materials = scene.materialInfo;
        e.materialsChanged.assign(e.materials.size(), 0);
        e.materialBuffer = createBuffer(*r.gpu, {"scene.materials.edited",
                                                 e.materials.size() * sizeof(gpu::GpuMaterial), 0,
                                                 MemoryKind::Upload});
        if (!e.materialBuffer) throw DeviceError("out of GPU memory for the edited materials");
    }
    gpu::GpuMaterial m = material;
    // The flags the forward draw lists follow (a pipeline per material class, render/forward):
    // an edit that adds a clear coat or a sheen moves the material's instances to the
    // all-features pipeline, one that removes them back.
    setMaterialFeatureFlags(m);
    if (std::memcmp(&e.materials[index], &m, sizeof(m)) == 0) return;
    e.materials[index] = m;
    e.materialsChanged[index] = 1;
}

void editSun(Renderer& r, const SunEdit& sun) {
    SunEdit s = sun;
    s.direction = glm::length(s.direction) > 1e-6f ? glm::normalize(s.direction)
                                                   : glm::vec3(0.0f, -1.0f, 0.0f);
    if (r.edits.sun && r.edits.sun->direction == s.direction && r.edits.sun->color == s.color)
        return;
    r.edits.sun = s;
    r.edits.sunChanged = true;
}

const std::vector<gpu::GpuLight>& applySceneEdits(Renderer& r, const GpuScene& scene,
                                                  gpu::FrameConstants& constants) {
    SceneEdits& e = r.edits;
    if (!e.materials.empty()) {
        // The whole (small) table each frame: one copy, and the buffer is never half-updated.
        std::memcpy(mapped(*r.gpu, e.materialBuffer), e.materials.data(),
                    e.materials.size() * sizeof(gpu::GpuMaterial));
        constants.materials = address(*r.gpu, e.materialBuffer);
    }
    return e.lights.empty() ? scene.lightInfo : e.lights;
}

void finishSceneEdits(Renderer& r) {
    std::fill(r.edits.materialsChanged.begin(), r.edits.materialsChanged.end(), 0);
    r.edits.sunChanged = false;
}

void destroySceneEdits(Renderer& r) {
    if (r.edits.materialBuffer) destroy(*r.gpu, r.edits.materialBuffer);
    r.edits = SceneEdits{};
}

} // namespace shadel
