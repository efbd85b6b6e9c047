#pragma once
// Light propagation volume GI (seed 001, after Kaplanyan and Dachsbacher 2010): reflective
// shadow maps from the sun and shadow-casting spots, injected as 2-band SH into three
// camera-centred cascades of 32^3 cells (snapped to their cell size so they do not swim),
// propagated N steps with geometry occlusion, and read by the shared lighting code
// (shaders/gi/lpv_sample.glsl via shaders/common/lighting.glsl).
#include <memory>

#include <nlohmann/json_fwd.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;
struct GiState;

struct GiStateDeleter {
    void operator()(GiState* state) const;
};
using GiStatePtr = std::unique_ptr<GiState, GiStateDeleter>;

GiStatePtr createGi(Renderer& r, const GpuScene& scene);
void destroyGi(Renderer& r, GiStatePtr& state);

// CPU side of the frame: places the cascades around the camera and points constants.gi at them.
// Call after the frame constants are filled (it reads the sun's view).
void prepareGiFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                    gpu::FrameConstants& constants);
// The passes, in frame order (after instance culling, before shading).
void recordGiReflectiveShadowMaps(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
void recordGiInjection(Renderer& r, VkCommandBuffer cmd);
void recordGiPropagation(Renderer& r, VkCommandBuffer cmd);

// Stats "gi": cascades (origin, cell size, extent), cells, RSMs, iterations.
void giStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
