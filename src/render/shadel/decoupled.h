#pragma once
// Generalized decoupled shading: the passes that replace forward shading (the parts and the
// glossary, shadel, chunk, block, virtual sheet, offset map, storage, shading bias, are in
// docs/design.md).
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "common/shared_types.h"
#include "render/renderer.h"
#include "rhi/frame.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;
struct DecoupledState;

DecoupledStatePtr createDecoupled(Renderer& r, const GpuScene& scene);
void destroyDecoupled(Renderer& r, DecoupledStatePtr& state);
// CPU side of the frame: coarse allocation of potentially visible objects in the virtual
// sheet, shading bias; fills the decoupled fields of the frame constants.
void prepareDecoupledFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                           gpu::FrameConstants& constants);
// Frontend/backend overlap: starts the grid visit (coarse_visit.h) of the next frame
// on the frontend worker, for `nextCamera`; that frame's prepareDecoupledFrame takes it. Called
// by renderFrame after this frame's frontend (Renderer::nextFrame). Nothing with --occlusion on
// (the visit is last frame's visible set, a readback) or when `sceneMoves` (animated playback:
// the next frame's bounds are written only before it; counted).
void prefetchCoarseVisit(Renderer& r, const GpuScene& scene, const CameraView& nextCamera,
                         bool sceneMoves);
// Marking and allocation: after them the occupancy masks say which chunks the frame reads.
void recordDecoupledMarking(Renderer& r, FrameRecorder& rec, uint64_t frame);
// Work queues, carry-over, shading, reconstruction.
void recordDecoupledShading(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene& scene);
// Passes after tonemapping (the sheet view).
void recordDecoupledPostPasses(Renderer& r, FrameRecorder& rec, uint64_t frame);
// Whether the instance is shaded in shadel space this frame (after prepareDecoupledFrame).
bool drawnDecoupled(const Renderer& r, uint32_t instance);
// The viewer's hot reload of the material programs (render/materials/material_programs.h
// pollMaterialPrograms): the programs swapped, errors (file:line) of those kept.
uint32_t pollMaterialPrograms(Renderer& r, std::vector<std::string>& errors);
// Reads back the frame's counters (after the GPU finished).
void finishDecoupledFrame(Renderer& r);
// The shading queue, for passes that run once per queued chunk before shading (the spectra's
// chunk classify): the buffer holding its indirect dispatch arguments
// (GpuShadelCounters::invocationDispatch, an invocation per chunk in workgroups of 64) and the
// entries it can hold.
struct ShadelShadingQueue {
    BufferHandle counters;
    VkDeviceSize invocationDispatchOffset = 0;
    uint32_t capacity = 0;
    // The SHADE_OPTIONAL_* parts this renderer's shading pipelines compile in (the spectra's
    // permutations take the same, less the chunk light culling they never run).
    uint32_t shadeOptional = 0;
};
ShadelShadingQueue shadelShadingQueue(const Renderer& r);
// Adds the decoupled fields of the stats contract in docs/design.md (medians over the frames
// rendered so far).
void decoupledStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
