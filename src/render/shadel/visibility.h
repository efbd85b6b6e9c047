#pragma once
// Visibility buffer for the decoupled path (--marking visibility): the depth prepass also
// writes each pixel's instance and triangle; marking and reconstruction become compute passes
// over screen pixels that rebuild the shadel UV and its derivatives from the triangle and the
// pixel ray (shaders/common/visibility.glsl). Raster passes per frame: shadow, the visibility
// prepass and, only for hybrid forward instances, one colour pass after the resolve.
#include <memory>

#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct VisibilityState;

struct VisibilityStateDeleter {
    void operator()(VisibilityState* state) const;
};
using VisibilityStatePtr = std::unique_ptr<VisibilityState, VisibilityStateDeleter>;

// Needs the renderer's targets (the HDR target must allow storage). The triangle IDs come from
// the scene's visibility vertices (GpuScene::visibilityIndices, scene/visibility_vertices.h),
// not gl_PrimitiveID, so no device feature is needed.
VisibilityStatePtr createVisibility(Renderer& r);
void destroyVisibility(Renderer& r, VisibilityStatePtr& state);

// Bindless slots of the visibility buffer (sampled) and of the HDR target (storage), for the
// compute passes that read the one and write the other (also render/lighting's tile shading).
uint32_t visibilityBufferSlot(Renderer& r);
uint32_t visibilityHdrWriteSlot(Renderer& r);

// "visibilityPrepass": reversed-Z depth + instance/triangle IDs of opaque and decoupled lists
// (triangles numbered within their mesh, LOD 0's numbering continued by its other LODs).
void recordVisibilityPrepass(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// "markingCompute": occupancy bits from the visibility buffer (after shadelClear), and per
// pixel the footprints it marked ("reconstructionAddress") for the resolve. Two dispatches: the
// quads on one decoupled triangle, then (indirect) those it listed, pixel by pixel
// (shaders/shadel/mark_quad.glsl says why).
void recordMarkingCompute(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// The resolve's pipelines for this frame's output (Renderer::tonemapFused): created the first
// time a frame needs them, before its passes are recorded.
void prepareResolvePipelines(Renderer& r);
// "hybridForward": the forward (hybrid) opaque instances drawn into the HDR target, before the
// resolve (which keeps their pixels).
void recordHybridForward(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// "resolveCompute": decoupled pixels reconstructed from their addresses (rebuilt from the
// visibility buffer for debug views, --inspect, and the forward fallback) into the HDR target,
// or, with the tonemap fused (Renderer::tonemapFused), every pixel into the readback as the
// display shows it.
void recordResolveCompute(Renderer& r, VkCommandBuffer cmd, uint64_t frame);

} // namespace shadel
