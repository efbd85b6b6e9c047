#pragma once
// The viewer's light, sun and material editor: a section of the panel listing the
// scene's lights and materials. What the user changes goes to the renderer as scene edits
// (render/scene_edits.h), so both paths show it from the next frame, and the decoupled path
// reshades only what the edit reaches.
#include <cstdint>
#include <map>
#include <optional>

#include "render/scene_edits.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct SceneEditor {
    int light = 0;    // the selected light
    int material = 0; // the selected material
    // Everything edited so far, re-applied to a new renderer (switching modes makes one).
    std::map<uint32_t, gpu::GpuLight> lights;
    std::map<uint32_t, gpu::GpuMaterial> materials;
    std::optional<SunEdit> sun;
};

// Draws the editor's sections into the current ImGui window and applies what changed.
void buildSceneEditor(SceneEditor& editor, Renderer& r, const GpuScene& scene);
// After a new renderer was created: the edits made so far, again.
void reapplySceneEdits(const SceneEditor& editor, Renderer& r, const GpuScene& scene);

} // namespace shadel
