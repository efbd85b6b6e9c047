#pragma once
// Records one frame as a list of named passes and times each one.
//
// Two timing modes. Timestamps: one command buffer, a timestamp pair around each pass; right
// on GPUs whose timestamps are attributed to the pass that ran. SubmitPerPass: each pass is its
// own submission and the CPU waits for it; slower, but the only trustworthy per-pass figure
// on lavapipe, whose timestamps after a graphics pass are attributed late.
//
// Recording threads (parallel command recording). With one thread each pass is
// recorded when it is declared. With more, `pass` only keeps the pass; endFrame records every
// kept pass into its own command buffer on a pool of workers (each worker its own command
// pool), then submits them in declaration order, so the GPU sees the same commands in the same
// order as the serial frame. Hence the rule for every pass's recording function: it may run
// later and on another thread, so it captures the frame's locals (push constants, the frame
// address, counts) by value, refers by reference only to state that outlives the frame
// (Renderer, a technique's state, the scene), and changes no CPU state another pass reads.
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/cpu_scope.h"
#include "rhi/vk.h"

namespace shadel {

struct Gpu;
class WorkerPool;

enum class TimingMode { Timestamps, SubmitPerPass };

struct PassTiming {
    std::string name;
    double gpuMs = 0.0;
    double startMs = 0.0;     // GPU start relative to the frame's first pass (trace export)
    double recordCpuMs = 0.0; // CPU time of the thread that recorded it (trace, stats)
};

// What one recording worker did in a frame (the trace shows one track per worker).
struct RecordingWorkerTiming {
    double startMs = 0.0;    // first pass begun, from the frame's start
    double durationMs = 0.0; // to the last pass ended
    double cpuMs = 0.0;      // CPU time of the thread while recording
    uint32_t passes = 0;
};

// A worker's command pool and the command buffers it has allocated (reused every frame).
struct RecordingPool {
    VkCommandPool pool = VK_NULL_HANDLE;
    std::vector<VkCommandBuffer> buffers;
    uint32_t used = 0;
};

struct DeferredPass {
    std::function<void(VkCommandBuffer)> record;
    VkCommandBuffer cmd = VK_NULL_HANDLE; // the buffer a worker recorded it into
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
    double gpuWaitMs = 0.0;         // of which the CPU waited on fences or blocked in a submit
    // This frame's vkQueueSubmit2 calls ("submit PASS", or "submit frame" with one batch), from
    // frameStart: the wall clock and the render thread's CPU time inside each (the difference
    // is blocked, counted in gpuWaitMs).
    std::vector<CpuScope> submits;
    // Serial recording: time each pass's recording (PassTiming::recordCpuMs). Off by default:
    // two reads of the thread's CPU clock per pass cost about a microsecond, which would add to
    // the CPU cost measured (threaded recording times its passes anyway).
    bool timeRecording = false;
    std::chrono::steady_clock::time_point frameStart;
    // Binary semaphores the frame's next submission waits on (at every stage), then forgets:
    // work queued before the frame that the frame depends on (sparse binds, render/streaming).
    std::vector<VkSemaphore> waitOnce;
    std::vector<VkCommandBufferSubmitInfo> submitCommandBuffers; // a submit's (reused)
    std::vector<VkSemaphoreSubmitInfo> submitWaits;

    // Recording threads (1 = serial, each pass recorded where it is declared).
    uint32_t recordingThreads = 1;
    std::shared_ptr<WorkerPool> workers;
    std::vector<RecordingPool> recordingPools;        // one per worker
    std::vector<DeferredPass> deferred;               // this frame's passes, when threaded
    std::vector<RecordingWorkerTiming> workerTimings; // filled by endFrame() when threaded
    double recordingMs = 0.0; // wall clock of the parallel recording (threaded)
};

// recordingThreads >= 1; more than one records the frame's passes on that many threads.
void initFrameRecorder(Gpu& gpu, FrameRecorder& recorder, TimingMode mode,
                       uint32_t recordingThreads = 1);
void destroyFrameRecorder(FrameRecorder& recorder);
TimingMode defaultTimingMode(const Gpu& gpu); // SubmitPerPass on CPU devices
uint32_t defaultRecordingThreads();           // the hardware threads, at most 4

void beginFrame(FrameRecorder& recorder);
// Records `record` as the named pass (debug label + timing): now, or with recording threads in
// endFrame (see the rule at the top).
void pass(FrameRecorder& recorder, const char* name,
          const std::function<void(VkCommandBuffer)>& record);
// Submits what is left, waits for the GPU, resolves timings.
void endFrame(FrameRecorder& recorder);

} // namespace shadel
