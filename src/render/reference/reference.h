#pragma once
// The reference path tracer (--mode reference): unbiased multi-bounce light transport of the
// same scene, the oracle the raster modes' lighting is judged against. One compute pass per
// frame (`referencePathTrace`, shaders/reference/path_trace.comp) traces --spp paths per pixel
// with ray queries against the frame's TLAS (render/raytracing) and folds them into the mean
// accumulated since the first frame (RGBA32F, `--capture reference`, the EXR of --out X.exr);
// the mean goes into the scene colour, which the usual tonemap turns into the image. The frame
// keeps the camera culling and the depth prepass (the tonemap's coverage) and skips every
// raster shading pass. Needs VK_KHR_ray_query: without it, --mode reference is an input error.
#include <memory>

#include <nlohmann/json_fwd.hpp>

#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;
struct ReferenceState;

struct ReferenceStateDeleter {
    void operator()(ReferenceState* state) const;
};
using ReferenceStatePtr = std::unique_ptr<ReferenceState, ReferenceStateDeleter>;

// The accumulation image, the pipeline and the capture; after the ray-tracing state.
ReferenceStatePtr createReference(Renderer& r, const GpuScene& scene);
void destroyReference(Renderer& r, ReferenceStatePtr& state);
// CPU side of the frame: a moved camera restarts the mean.
void prepareReferenceFrame(Renderer& r, const CameraView& camera);
// The pass: after the TLAS build and the depth prepass, before the tonemap.
void recordReferencePathTrace(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// Stats: reference {spp_total, spp_per_frame, max_bounces, seed, ...}.
void referenceStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
