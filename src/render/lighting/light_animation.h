#pragma once
// --animate-lights: point and spot lights move on small horizontal circles, deterministically
// by frame number, so tests and benchmarks can measure what changing lights cost each path.
#include <vector>

#include <glm/glm.hpp>

#include "common/shared_types.h"

namespace shadel {

// The scene's lights as they are at `frame`.
std::vector<gpu::GpuLight> animatedLights(const std::vector<gpu::GpuLight>& lights, uint64_t frame);

// Volumes (xyz centre, w radius; infinite for unbounded lights) that lights which differ
// between `before` and `after` reach, at either position.
std::vector<glm::vec4> changedLightVolumes(const std::vector<gpu::GpuLight>& before,
                                           const std::vector<gpu::GpuLight>& after);

} // namespace shadel
