#pragma once
// Animated playback of a glTF scene over a run's frames (`--time-step SECONDS`): frame i shows
// the file's animations posed at T0 + i * step (T0 = `--time`, default 0). Each frame the file
// is posed again on the CPU (scene/gltf_animation: node TRS, morph weights, skins) and only what
// moved is written to the GPU scene: instance transforms and bounds, and the vertices of meshes
// whose posed vertices changed. Topology never changes, so a decoupled object keeps its charts,
// shadel UVs and triangle-ID maps (baked from the T0 pose); its marking, shading and
// reconstruction read the deformed vertices, and `reposed` tells the reuse logic
// (render/shadel) not to carry its shadels over.
#include <chrono>
#include <cstdint>
#include <future>
#include <string>
#include <vector>

#include "render/gpu_scene.h"
#include "scene/gltf_import.h"
#include "scene/scene.h"

namespace shadel {

struct ScenePlayback {
    std::string spec;         // the glTF file
    SceneFileOptions options; // its import options (time replaced per frame)
    double startTime = 0.0;   // T0 (seconds)
    double step = 0.0;        // seconds per frame
    Scene drawn;              // the pose the GPU scene holds (instances, meshes)
    // Totals over the run (stats).
    uint64_t instancesReposed = 0, meshesReposed = 0, verticesWritten = 0;

    // Frontend/backend overlap: the next frame's pose is imported on a worker thread
    // (prefetchPose) while this frame is recorded, submitted and drawn; poseFrame takes it.
    struct Import {
        Scene scene;
        std::chrono::steady_clock::time_point start, end;
        double cpuMs = 0.0; // the worker thread's CPU time
    };
    std::future<Import> next;
    uint32_t nextFrame = 0;
    Import lastImport; // the prefetched import poseFrame took last (trace)
    bool lastWasPrefetched = false;
    uint32_t prefetched = 0;     // poses taken from the worker
    double prefetchCpuMs = 0.0;  // the worker's CPU time, total
    double prefetchWaitMs = 0.0; // poseFrame waiting for the worker, total
};

// Starts importing the pose of `frame` on a worker thread (the frame after the one about to be
// rendered); poseFrame(frame) takes the result, or imports it itself without a prefetch.
void prefetchPose(ScenePlayback& playback, uint32_t frame);

// `drawn` is the scene uploaded for the first frame (posed at T0, meshes not split into chunks:
// their vertices map one to one onto the file's).
ScenePlayback startPlayback(const std::string& spec, const SceneFileOptions& options,
                            double startTime, double step, Scene drawn);

// Poses the file at T0 + frame * step and writes what changed since the drawn pose into
// `gpuScene` (between frames: the GPU is idle). `reposed` gets one byte per instance: 1 when
// its transform or its mesh's vertices changed. Throws InputError when the posed file no longer
// matches the drawn scene's structure. `reposedFrom` (optional) gets, per instance, the world
// bounds it had before this pose (meaningful where `reposed` is 1): what it no longer covers or
// shadows (decoupled reuse reshades there).
// With `gpuSkinned`, meshes carrying GPU skinning input (Mesh::skin) are not written: the
// skinning pass (render/skinning) deforms them from `drawn.skinPoses`, which the caller hands it.
void poseFrame(Gpu& gpu, ScenePlayback& playback, uint32_t frame, GpuScene& gpuScene,
               std::vector<uint8_t>& reposed, bool gpuSkinned = false,
               std::vector<Aabb>* reposedFrom = nullptr);

} // namespace shadel
