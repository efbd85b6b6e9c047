#pragma once
// Live edits of the scene's lights, sun and materials (the viewer's light and material panels).
// The uploaded GpuScene stays as loaded: edited copies live in upload buffers that
// the frame binds in place of the scene's, and each edit also says what it invalidates, so the
// decoupled path's preserved layers reshade exactly what changed (a light's reach, a
// material's objects; the sun reaches everything) instead of carrying stale shading over.
// Edits take effect at the next renderFrame; they compose with --animate-lights (the edited
// lights are the ones animated).
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "common/shared_types.h"
#include "rhi/handles.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SunEdit {
    glm::vec3 direction{0.0f, -1.0f, 0.0f}; // the way the light travels
    glm::vec3 color{0.0f};                  // colour * intensity
};

struct SceneEdits {
    std::vector<gpu::GpuLight> lights;       // the scene's lights as edited; empty: unedited
    std::vector<gpu::GpuMaterial> materials; // the scene's materials as edited; empty: unedited
    std::vector<uint8_t> materialsChanged;   // per material: edited since the last frame
    std::optional<SunEdit> sun;
    bool sunChanged = false;     // since the last frame
    BufferHandle materialBuffer; // host-visible copy of `materials`, bound in place of the scene's
};

// The light's, sun's or material's current value (edited or as loaded).
gpu::GpuLight currentLight(const Renderer& r, const GpuScene& scene, uint32_t index);
// (The material by reference, valid until the next edit: read per instance every frame.)
const gpu::GpuMaterial& currentMaterial(const Renderer& r, const GpuScene& scene, uint32_t index);
SunEdit currentSun(const Renderer& r, const GpuScene& scene);

// Replace one light / material / the sun from the next frame on. An index out of range throws
// InputError (a caller bug or a stale UI list, reported, never written out of bounds).
void editLight(Renderer& r, const GpuScene& scene, uint32_t index, const gpu::GpuLight& light);
void editMaterial(Renderer& r, const GpuScene& scene, uint32_t index,
                  const gpu::GpuMaterial& material);
void editSun(Renderer& r, const SunEdit& sun);

// In renderFrame, before anything reads the constants' lights, materials or sun: binds the
// edited copies and returns the lights this frame starts from (edited or as loaded).
const std::vector<gpu::GpuLight>& applySceneEdits(Renderer& r, const GpuScene& scene,
                                                  gpu::FrameConstants& constants);
// After the frame's decoupled bookkeeping read them: clear the "changed since last frame" marks.
void finishSceneEdits(Renderer& r);
void destroySceneEdits(Renderer& r);

} // namespace shadel
