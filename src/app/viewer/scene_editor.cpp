#include "app/viewer/scene_editor.h"

#include <algorithm>
#include <cmath>

#include <imgui.h>

#include "render/gpu_scene.h"
#include "render/renderer.h"

namespace shadel {

namespace {

const char* lightKindName(uint32_t type) {
    switch (type) {
    case LIGHT_DIRECTIONAL:
        return "directional";
    case LIGHT_POINT:
        return "point";
    case LIGHT_SPOT:
        return "spot";
    case LIGHT_SPOT_SQUARE:
        return "square spot";
    case LIGHT_TUBE:
        return "tube";
    case LIGHT_AREA:
        return "area";
    default:
        return "light";
    }
}

// A colour * intensity as the two numbers people edit: a colour of max component 1, and the
// intensity (that max). Darks keep their sign in the intensity.
void splitColour(glm::vec3 c, glm::vec3& colour, float& intensity) {
    float sign = (c.x + c.y + c.z) < 0.0f ? -1.0f : 1.0f;
    glm::vec3 a = glm::abs(c);
    float m = std::max(a.x, std::max(a.y, a.z));
    intensity = sign * m;
    colour = m > 0.0f ? a / m : glm::vec3(1.0f);
}

// Returns whether the light changed.
bool lightSection(gpu::GpuLight& l) {
    bool changed = false;
    glm::vec3 colour;
    float intensity;
    splitColour(l.color, colour, intensity);
    changed |= ImGui::ColorEdit3("light colour", &colour.x);
    changed |= ImGui::DragFloat("intensity", &intensity, 0.05f, -1000.0f, 1000.0f, "%.3f");
    if (changed) l.color = colour * intensity;
    if (l.type != LIGHT_DIRECTIONAL) changed |= ImGui::DragFloat3("position", &l.position.x, 0.05f);
    if (l.type == LIGHT_DIRECTIONAL || l.type == LIGHT_SPOT || l.type == LIGHT_SPOT_SQUARE) {
        glm::vec3 d = l.direction;
        if (ImGui::DragFloat3("direction", &d.x, 0.01f, -1.0f, 1.0f) && glm::length(d) > 1e-4f) {
            l.direction = glm::normalize(d);
            changed = true;
        }
    }
    if (l.type != LIGHT_DIRECTIONAL)
        changed |= ImGui::DragFloat("range (0: infinite)", &l.range, 0.05f, 0.0f, 1e4f);
    return changed;
}

bool materialSection(gpu::GpuMaterial& m) {
    bool changed = false;
    changed |= ImGui::ColorEdit4("base colour", &m.baseColorFactor.x);
    changed |= ImGui::SliderFloat("roughness", &m.roughnessFactor, 0.0f, 1.0f);
    changed |= ImGui::SliderFloat("metallic", &m.metallicFactor, 0.0f, 1.0f);
    changed |= ImGui::ColorEdit3("emissive", &m.emissiveFactor.x,
                                 ImGuiColorEditFlags_HDR | ImGuiColorEditFlags_Float);
    return changed;
}

} // namespace

void buildSceneEditor(SceneEditor& e, Renderer& r, const GpuScene& scene) {
    if (r.environment.kind != EnvironmentKind::None && ImGui::CollapsingHeader("environment")) {
        // The next frame reads them (the decoupled path relights everything it carried over).
        ImGui::DragFloat("environment intensity", &r.settings.environmentIntensity, 0.01f, 0.0f,
                         100.0f, "%.2f");
        ImGui::SliderFloat("environment rotation", &r.settings.environmentRotationDegrees, -180.0f,
                           180.0f, "%.0f deg");
    }
    if (ImGui::CollapsingHeader("sun")) {
        SunEdit sun = currentSun(r, scene);
        glm::vec3 colour;
        float intensity;
        splitColour(sun.color, colour, intensity);
        bool changed = ImGui::ColorEdit3("sun colour", &colour.x);
        changed |= ImGui::DragFloat("sun intensity", &intensity, 0.05f, 0.0f, 1000.0f, "%.3f");
        glm::vec3 d = sun.direction;
        if (ImGui::DragFloat3("sun direction", &d.x, 0.01f, -1.0f, 1.0f) &&
            glm::length(d) > 1e-4f) {
            sun.direction = d;
            changed = true;
        }
        if (changed) {
            sun.color = colour * intensity;
            editSun(r, sun);
            e.sun = currentSun(r, scene);
        }
    }
    uint32_t lightCount = uint32_t(scene.lightInfo.size());
    if (lightCount && ImGui::CollapsingHeader("lights")) {
        e.light = std::clamp(e.light, 0, int(lightCount) - 1);
        ImGui::SliderInt("light", &e.light, 0, int(lightCount) - 1);
        gpu::GpuLight l = currentLight(r, scene, uint32_t(e.light));
        ImGui::Text("%s%s%s%s", lightKindName(l.type),
                    l.shadowIndex != LIGHT_NO_SHADOW ? ", shadow map" : "",
                    (l.flags & LIGHT_FLAG_DARK) ? ", dark" : "",
                    (l.flags & LIGHT_FLAG_PROJECTED) ? ", gobo" : "");
        if (lightSection(l)) {
            editLight(r, scene, uint32_t(e.light), l);
            e.lights[uint32_t(e.light)] = currentLight(r, scene, uint32_t(e.light));
        }
    }
    uint32_t materialCount = uint32_t(scene.materialInfo.size());
    if (materialCount && ImGui::CollapsingHeader("materials")) {
        e.material = std::clamp(e.material, 0, int(materialCount) - 1);
        ImGui::SliderInt("material", &e.material, 0, int(materialCount) - 1);
        gpu::GpuMaterial m = currentMaterial(r, scene, uint32_t(e.material));
        if (materialSection(m)) {
            editMaterial(r, scene, uint32_t(e.material), m);
            e.materials[uint32_t(e.material)] = m;
        }
    }
}

void reapplySceneEdits(const SceneEditor& e, Renderer& r, const GpuScene& scene) {
    if (e.sun) editSun(r, *e.sun);
    for (const auto& [index, light] : e.lights) editLight(r, scene, index, light);
    for (const auto& [index, material] : e.materials) editMaterial(r, scene, index, material);
}

} // namespace shadel
