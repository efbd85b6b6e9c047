#pragma once
// The decoupled coarse allocation's first half (the frontend of frame N+1 beside the
// backend of frame N): which instances a camera may need, and per instance what the camera and
// the instance's bounds alone decide (frustum test with the margin, the hybrid's small-object
// test, the finest MIP's footprint before the shading bias). It reads no readback and no
// allocator state, so it can run for the next frame on the frontend worker while this frame
// records, submits and waits; the second half (rects, windows from the wants read back, bias,
// GPU entries, uploads) stays in prepareDecoupledFrame after this frame's finish.
#include <array>
#include <chrono>
#include <cstdint>
#include <vector>

#include "render/camera.h"

namespace shadel {

struct GpuScene;
class InstanceGrid;

// What the visit reads besides the camera, the scene and the grid (fixed for a run).
struct CoarseVisitPolicy {
    float viewportHeight = 1.0f;     // internal (SSAA) pixels
    float frustumMargin = 0.1f;      // fraction of an instance's size (DecoupledState)
    float forwardBelowPixels = 0.0f; // --forward-below (0: off)
    bool blendedForward = false;     // sorted OIT: blended instances stay forward
    bool sheetAllMips = false;       // --sheet-all-mips: every level from MIP 0
};

// One instance as the camera sees it.
struct CoarseInstanceView {
    // It can be decoupled (has shadel MIPs, not a forward transparent) and its margin-padded
    // bounds touch the frustum. (With --occlusion on, the GPU's visible set must agree too.)
    bool inFrustum = false;
    // Projected diameter below --forward-below: drawn forward (only meaningful when inFrustum).
    bool small = false;
    // log2 of the footprint lower bound (footprintLod) finestMipFromLod turns into a MIP, before
    // the frame's shading bias (which the capacity controller sets from the last frame's readback):
    // -inf when MIP 0 is needed whatever the bias. Computed only when inFrustum and not small.
    float lodBeforeBias = 0.0f;
};

// The finest MIP an instance can need: its footprint's LOD plus the shading bias, floored,
// clamped to the mesh's levels (the bias is added here so the result is that of one expression).
uint32_t finestMipFromLod(float lodBeforeBias, float bias, uint32_t mipCount);

// One instance's view; `planes`: frustumPlanes of the frame constants' viewProj.
CoarseInstanceView viewInstance(const CoarseVisitPolicy& policy, const GpuScene& scene,
                                const CameraView& camera, const std::array<glm::vec4, 6>& planes,
                                uint32_t instance);

// A camera's visit: the grid's answer for the frustum's bounding box, in query order, and each
// listed instance's view. Filled by visitCoarse, on the frontend worker or inline.
struct CoarseVisit {
    CameraView camera; // the camera it is for (its taker checks it is the frame's)
    std::vector<uint32_t> instances;
    std::vector<CoarseInstanceView> views; // per entry of `instances`
    // On the frontend worker: when it ran and the worker thread's CPU time (trace, stats).
    std::chrono::steady_clock::time_point start, end;
    double cpuMs = 0.0;
};

// Where the frames' visits came from (stats "frontend").
struct FrontendVisitStats {
    uint32_t prefetched = 0;      // taken from the frontend worker
    uint32_t inlineVisits = 0;    // computed on the render thread (serial, the first frame, ...)
    uint32_t readbackVisits = 0;  // --occlusion on: last frame's visible set, no grid visit
    uint32_t skippedPlayback = 0; // not prefetched: the next frame's bounds are not posed yet
    uint32_t discarded = 0;       // prefetched for another camera than the frame's
    double workerCpuMs = 0.0;     // the worker's CPU time in the visits taken, total
    double waitMs = 0.0;          // the render thread waiting for the worker, total
};

// Fills `out` (its vectors reused) for `camera`. Reads only the camera, the policy, the
// instances' bounds, meshes and materials, and the grid.
void visitCoarse(const CoarseVisitPolicy& policy, const GpuScene& scene, const InstanceGrid& grid,
                 const CameraView& camera, CoarseVisit& out);

// Whether a visit computed for `a` holds for `b` (every camera field it reads is equal).
bool sameVisitCamera(const CameraView& a, const CameraView& b);

} // namespace shadel
