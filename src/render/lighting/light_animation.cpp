#include "render/lighting/light_animation.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "render/lighting/light_culling.h"

namespace shadel {

std::vector<gpu::GpuLight> animatedLights(const std::vector<gpu::GpuLight>& lights,
                                          uint64_t frame) {
    std::vector<gpu::GpuLight> out = lights;
    for (size_t i = 0; i < out.size(); ++i) {
        gpu::GpuLight& l = out[i];
        if (l.type != LIGHT_POINT && l.type != LIGHT_SPOT) continue;
        // A 0.75 m circle, one turn per 48 frames, each light at its own phase.
        float angle = 6.2831853f * (float(frame % 48) / 48.0f + float(i) * 0.37f);
        float phase0 = 6.2831853f * float(i) * 0.37f;
        glm::vec3 offset = 0.75f * glm::vec3(std::cos(angle) - std::cos(phase0), 0.0f,
                                             std::sin(angle) - std::sin(phase0));
        l.position += offset;
    }
    return out;
}

std::vector<glm::vec4> changedLightVolumes(const std::vector<gpu::GpuLight>& before,
                                           const std::vector<gpu::GpuLight>& after) {
    std::vector<glm::vec4> volumes;
    const float infinite = std::numeric_limits<float>::infinity();
    if (before.size() != after.size()) return {glm::vec4(0.0f, 0.0f, 0.0f, infinite)};
    for (size_t i = 0; i < after.size(); ++i) {
        if (std::memcmp(&before[i], &after[i], sizeof(gpu::GpuLight)) == 0) continue;
        for (const gpu::GpuLight* l : {&before[i], &after[i]}) {
            volumes.push_back(glm::vec4(l->position, lightReach(*l)));
        }
    }
    return volumes;
}

} // namespace shadel
