#pragma once
// Ray tracing: BLASes per mesh LOD in TLSF pools, a TLAS rebuilt every
// frame from the instances within the ray-tracing distance, and ray-traced sun and
// shadow-casting spot shadows, ambient occlusion and one-bounce diffuse GI
// (shaders/raytracing/rt_effects.glsl). The forward path
// traces per pixel in `rtPixelTerms` (before forward shading, which reads the result through
// shaders/raytracing/rt_apply.glsl). Needs VK_KHR_ray_query + VK_KHR_acceleration_structure:
// without them, asking for any --rt-* effect is an input error.
#include <memory>

#include <nlohmann/json_fwd.hpp>

#include "common/shared_types.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;
struct RayTracingState;

struct RayTracingStateDeleter {
    void operator()(RayTracingState* state) const;
};
using RayTracingStatePtr = std::unique_ptr<RayTracingState, RayTracingStateDeleter>;

// Builds every BLAS (compacted, in pools) and the TLAS storage. Throws InputError when the
// device cannot trace rays.
RayTracingStatePtr createRayTracing(Renderer& r, const GpuScene& scene);
void destroyRayTracing(Renderer& r, RayTracingStatePtr& state);

// CPU side of the frame: the instances within the ray-tracing distance, each with the BLAS of
// its LOD (by projected error), into the TLAS instance buffer; points constants.rt at the frame.
void prepareRayTracingFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                            gpu::FrameConstants& constants);
// The passes, in frame order: the TLAS build (before anything traces), and the forward path's
// per-pixel terms (after the depth prepass, before forward shading).
void recordTlasBuild(Renderer& r, VkCommandBuffer cmd);
void recordRayTracedPixels(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// The shadel path's pass (render/raytracing/rt_shadel_cache.h): before the decoupled passes.
void recordRayTracedShadels(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// After the frame: the GPU's ray count.
void finishRayTracingFrame(Renderer& r);
// Stats: blas_count, blas_bytes, blas_pools, blas_fallbacks, tlas_instances, rays_traced, ...
void rayTracingStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
