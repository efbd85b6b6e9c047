#pragma once
// What carried-over shading may no longer hold (preserved layers, decoupled reuse): the regions
// of the world whose lighting changed since last frame, as capsules. The CPU flags the objects
// a region meets; their chunks check their own shadels against the regions (shade.comp) and
// only those inside are shaded again.
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace shadel {

struct GpuScene;
struct Renderer;

// The points within `radius` of the segment a-b (a sphere when a == b; an infinite radius is
// everywhere). Two vec4s on the GPU: (a, radius), (b, 0).
struct ChangedVolume {
    glm::vec3 a{0.0f};
    float radius = 0.0f;
    glm::vec3 b{0.0f};
    float pad = 0.0f;
};

// This frame's changed regions:
// - lights that changed (moved, edited, animated): what they reach, before and after;
// - instances animated playback moved or deformed (Renderer::reposedInstances), at their old
//   and new places: the space around them (ambient occlusion, contact), the sun shadow they
//   cast (a capsule from them along the sun's direction across the scene) and the reach of every
//   shadow-casting light whose range they are in (the shadow can fall anywhere there);
// - instances whose distance field came into the atlas or left it (--df-residency): the same
//   regions at their place (their DF shadow and occlusion appeared or vanished).
// `sunDirection`: the way the sun's light travels; `sunShadows`: the sun casts shadows.
std::vector<ChangedVolume> changedVolumes(const Renderer& r, const GpuScene& scene,
                                          glm::vec3 sunDirection, bool sunShadows);

enum class ChangeReach { None, Bounded, Everything };
// Which of the regions a box meets (conservative for capsules: the box's bounding sphere).
ChangeReach changeReach(const std::vector<ChangedVolume>& volumes, glm::vec3 boxMin,
                        glm::vec3 boxMax);

} // namespace shadel
