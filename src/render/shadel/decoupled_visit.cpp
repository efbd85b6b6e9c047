// The decoupled frame's grid visit (coarse_visit.h): computed ahead on the frontend worker
// beside the last frame's backend, or inline.
#include <algorithm>
#include <chrono>

#include "render/shadel/decoupled_state.h"

namespace shadel {

static double msBetween(std::chrono::steady_clock::time_point a,
                        std::chrono::steady_clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
}

void prefetchCoarseVisit(Renderer& r, const GpuScene& scene, const CameraView& nextCamera,
                         bool sceneMoves) {
    if (!r.decoupled) return;
    DecoupledState& d = *r.decoupled;
    // --occlusion on: after its first frame, a frame visits the GPU's visible set of the frame
    // before it, read back when that frame finishes; nothing to run ahead.
    if (r.settings.occlusion) return;
    if (sceneMoves) { // the next frame's bounds are known once its pose is written
        d.visitStats.skippedPlayback++;
        return;
    }
    uint64_t frame = d.frameNumber + 1; // (this frame finishes after this call)
    DecoupledState::PendingVisit& pending = d.pendingVisit;
    pending.frame = frame;
    // The grid and the scene's instances are not written while it runs: the grid is rebuilt
    // only for animated playback (sceneMoves), the scene only between frames by the playback.
    pending.visit = std::async(std::launch::async,
                               [policy = d.visitPolicy, &scene, &grid = d.grid, camera = nextCamera,
                                out = std::move(d.spareVisit)]() mutable {
                                   out.start = std::chrono::steady_clock::now();
                                   double cpuStart = threadCpuMs();
                                   visitCoarse(policy, scene, grid, camera, out);
                                   out.cpuMs = threadCpuMs() - cpuStart;
                                   out.end = std::chrono::steady_clock::now();
                                   return std::move(out);
                               });
}

// This frame's grid visit: the one the frontend worker computed beside the last frame's backend
// when it is for this camera and the scene did not move, else computed here (the same function
// on the same inputs: the same result).
const CoarseVisit& takeCoarseVisit(Renderer& r, const GpuScene& scene, const CameraView& camera) {
    DecoupledState& d = *r.decoupled;
    // Animated playback moved instances (render/animation): the grid follows their bounds.
    bool moved = std::find(r.reposedInstances.begin(), r.reposedInstances.end(), 1) !=
                 r.reposedInstances.end();
    if (moved) d.grid.build(scene.instanceInfo);
    DecoupledState::PendingVisit& pending = d.pendingVisit;
    if (pending.visit.valid() && pending.frame == d.frameNumber) {
        auto waitStart = std::chrono::steady_clock::now();
        CoarseVisit taken = pending.visit.get();
        d.visitStats.waitMs += msBetween(waitStart, std::chrono::steady_clock::now());
        if (!moved && sameVisitCamera(taken.camera, camera)) {
            d.visitStats.prefetched++;
            d.visitStats.workerCpuMs += taken.cpuMs;
            r.frontendTaken.push_back({"coarse visit", msBetween(r.createdAt, taken.start),
                                       msBetween(taken.start, taken.end), taken.cpuMs});
            d.spareVisit = std::move(d.coarseVisit);
            d.coarseVisit = std::move(taken);
            return d.coarseVisit;
        }
        d.visitStats.discarded++;
        d.spareVisit = std::move(taken);
    }
    auto timer = cpuScope(r, "coarse visit (inline)");
    d.visitStats.inlineVisits++;
    visitCoarse(d.visitPolicy, scene, d.grid, camera, d.coarseVisit);
    return d.coarseVisit;
}

} // namespace shadel
