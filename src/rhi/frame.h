#pragma once
// Records one frame as a list of named passes and times each one.
//
// Two timing modes. Timestamps: one command buffer, a timestamp pair around each pass; right
// on GPUs whose timestamps are attributed to the pass that ran. SubmitPerPass: each pass is its
// own submission and the CPU waits for it; slower, but the only trustworthy per-pass figure
// on lavapipe, whose timestamps after a graphics pass are attributed late.
#include <chrono>
#include <functional>
#include <string>
#include <vector>

#include "rhi/vk.h"

namespace shadel {

struct Gpu;

enum class TimingMode { Timestamps, SubmitPerPass };

struct PassTiming {
    std::string name;
    double gpuMs = 0.0;
    double startMs = 0.0; // GPU start relative to the frame's first pass (trace export)
};

struct FrameRecorder {
    Gpu* gpu = nullptr;
    TimingMode mode = TimingMode::Timestamps;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VkFence fence = VK_NULL_HANDLE;
    VkQueryPool queries = VK_NULL_HANDLE;
    uint32_t maxPasses = 64;
    std::vector<PassTiming> passes; // filled by endFrame()
    double frameMs = 0.0;           // wall clock from beginFrame to the GPU finishing
    double gpuWaitMs = 0.0;         // of which the CPU waited on fences
    std::chrono::steady_clock::time_point frameStart;
    // Binary semaphores the frame's next submission waits on (at every stage), then forgets:
    // work queued before the frame that the frame depends on (sparse binds, render/streaming).
    std::vector<VkSemaphore> waitOnce;
};

void initFrameRecorder(Gpu& gpu, FrameRecorder& recorder, TimingMode mode);
void destroyFrameRecorder(FrameRecorder& recorder);
TimingMode defaultTimingMode(const Gpu& gpu); // SubmitPerPass on CPU devices

void beginFrame(FrameRecorder& recorder);
// Records `record` as the named pass (debug label + timing).
void pass(FrameRecorder& recorder, const char* name,
          const std::function<void(VkCommandBuffer)>& record);
// Submits what is left, waits for the GPU, resolves timings.
void endFrame(FrameRecorder& recorder);

} // namespace shadel
