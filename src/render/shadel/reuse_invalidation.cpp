#include "render/shadel/reuse_invalidation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "render/distance_fields/distance_fields.h"
#include "render/lighting/light_culling.h"
#include "render/renderer.h"

namespace shadel {

static_assert(sizeof(ChangedVolume) == 32, "two vec4s in the shaders");

namespace {

struct Sphere {
    glm::vec3 centre;
    float radius;
};

Sphere boundingSphere(glm::vec3 boxMin, glm::vec3 boxMax) {
    return {0.5f * (boxMin + boxMax), 0.5f * glm::length(boxMax - boxMin)};
}

float segmentDistance(glm::vec3 p, glm::vec3 a, glm::vec3 b) {
    glm::vec3 ab = b - a;
    float t = glm::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12f), 0.0f, 1.0f);
    return glm::length(p - (a + t * ab));
}

ChangedVolume sphereVolume(glm::vec3 centre, float radius) {
    return {centre, radius, centre, 0.0f};
}

// The regions a caster's change (from or to `s`) relights.
void casterVolumes(Sphere s, const GpuScene& scene, const std::vector<gpu::GpuLight>& lights,
                   glm::vec3 sunDirection, bool sunShadows, std::vector<ChangedVolume>& out) {
    // Around it: what it occludes nearby (ambient occlusion, contact, bounced light) reaches
    // about its own size.
    out.push_back(sphereVolume(s.centre, 2.0f * s.radius));
    if (sunShadows) { // its shadow: from its sunward side down the sun's direction, past the scene
        glm::vec3 d = glm::normalize(sunDirection);
        float across = glm::length(scene.bounds.max - scene.bounds.min) + 2.0f * s.radius;
        out.push_back({s.centre - d * s.radius, s.radius, s.centre + d * across, 0.0f});
    }
    for (size_t i = 0; i < lights.size() && i < scene.lightCastsShadow.size(); ++i) {
        if (!scene.lightCastsShadow[i]) continue;
        float reach = lightReach(lights[i]);
        if (glm::length(lights[i].position - s.centre) > reach + s.radius) continue;
        out.push_back(sphereVolume(lights[i].position, reach)); // infinite: everywhere
    }
}

} // namespace

std::vector<ChangedVolume> changedVolumes(const Renderer& r, const GpuScene& scene,
                                          glm::vec3 sunDirection, bool sunShadows) {
    std::vector<ChangedVolume> volumes;
    for (const glm::vec4& l : r.changedLightVolumes)
        volumes.push_back(sphereVolume(glm::vec3(l), l.w));
    const std::vector<gpu::GpuLight>& lights =
        r.lightsLastFrame.empty() ? scene.lightInfo : r.lightsLastFrame;
    for (size_t i = 0; i < r.reposedInstances.size(); ++i) {
        if (!r.reposedInstances[i] || i >= scene.instanceInfo.size()) continue;
        const gpu::GpuInstance& now = scene.instanceInfo[i];
        casterVolumes(boundingSphere(now.worldMin, now.worldMax), scene, lights, sunDirection,
                      sunShadows, volumes);
        if (i < r.reposedFrom.size() && r.reposedFrom[i].valid())
            casterVolumes(boundingSphere(r.reposedFrom[i].min, r.reposedFrom[i].max), scene, lights,
                          sunDirection, sunShadows, volumes);
        else // where it was is unknown: everything may have changed
            volumes.push_back(
                sphereVolume(glm::vec3(0.0f), std::numeric_limits<float>::infinity()));
    }
    if (r.distanceFields)
        for (uint32_t i : distanceFieldRelitInstances(*r.distanceFields)) {
            if (i >= scene.instanceInfo.size()) continue;
            const gpu::GpuInstance& inst = scene.instanceInfo[i];
            casterVolumes(boundingSphere(inst.worldMin, inst.worldMax), scene, lights, sunDirection,
                          sunShadows, volumes);
        }
    return volumes;
}

ChangeReach changeReach(const std::vector<ChangedVolume>& volumes, glm::vec3 boxMin,
                        glm::vec3 boxMax) {
    ChangeReach reach = ChangeReach::None;
    Sphere box = boundingSphere(boxMin, boxMax);
    for (const ChangedVolume& v : volumes) {
        if (!std::isfinite(v.radius)) return ChangeReach::Everything;
        bool meets = v.a == v.b // a sphere: the box's nearest point
                         ? glm::length(glm::clamp(v.a, boxMin, boxMax) - v.a) <= v.radius
                         : segmentDistance(box.centre, v.a, v.b) <= v.radius + box.radius;
        if (meets) reach = ChangeReach::Bounded;
    }
    return reach;
}

} // namespace shadel
