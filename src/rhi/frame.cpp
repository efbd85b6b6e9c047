#include "rhi/frame.h"

#include <algorithm>
#include <thread>

#include "core/assert.h"
#include "core/cpu_scope.h"
#include "core/log.h"
#include "core/worker_pool.h"
#include "rhi/gpu.h"

namespace shadel {

using Clock = std::chrono::steady_clock;

static double msBetween(Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double, std::milli>(to - from).count();
}

static VkCommandPool createCommandPool(Gpu& gpu, const std::string& name) {
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    ci.queueFamilyIndex = gpu.device.queueFamily;
    VkCommandPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateCommandPool(gpu.device.device, &ci, nullptr, &pool));
    setName(gpu.device, pool, VK_OBJECT_TYPE_COMMAND_POOL, name.c_str());
    return pool;
}

TimingMode defaultTimingMode(const Gpu& gpu) {
    return gpu.device.isCpu ? TimingMode::SubmitPerPass : TimingMode::Timestamps;
}

// Beyond four, recording a frame of a few dozen passes gains little against waking threads.
uint32_t defaultRecordingThreads() {
    return std::clamp(std::thread::hardware_concurrency(), 1u, 4u);
}

void initFrameRecorder(Gpu& gpu, FrameRecorder& r, TimingMode mode, uint32_t recordingThreads) {
    SHADEL_ASSERT(recordingThreads >= 1);
    r.gpu = &gpu;
    r.mode = mode;
    r.pool = createCommandPool(gpu, "frame.commandPool");
    r.recordingThreads = recordingThreads;
    if (recordingThreads > 1) {
        r.workers = std::make_shared<WorkerPool>(recordingThreads);
        r.recordingPools.resize(recordingThreads);
        for (uint32_t w = 0; w < recordingThreads; ++w)
            r.recordingPools[w].pool =
                createCommandPool(gpu, "frame.recordingWorker" + std::to_string(w) + ".pool");
    }
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = r.pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    VK_CHECK(vkAllocateCommandBuffers(gpu.device.device, &ai, &r.cmd));
    setName(gpu.device, r.cmd, VK_OBJECT_TYPE_COMMAND_BUFFER, "frame.commands");
    VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VK_CHECK(vkCreateFence(gpu.device.device, &fci, nullptr, &r.fence));
    setName(gpu.device, r.fence, VK_OBJECT_TYPE_FENCE, "frame.fence");
    VkQueryPoolCreateInfo qci{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qci.queryType = VK_QUERY_TYPE_TIMESTAMP;
    qci.queryCount = r.maxPasses * 2;
    VK_CHECK(vkCreateQueryPool(gpu.device.device, &qci, nullptr, &r.queries));
    setName(gpu.device, r.queries, VK_OBJECT_TYPE_QUERY_POOL, "frame.timestamps");
}

void destroyFrameRecorder(FrameRecorder& r) {
    if (!r.gpu) return;
    VkDevice dev = r.gpu->device.device;
    vkDeviceWaitIdle(dev);
    vkDestroyQueryPool(dev, r.queries, nullptr);
    vkDestroyFence(dev, r.fence, nullptr);
    vkDestroyCommandPool(dev, r.pool, nullptr);
    for (RecordingPool& p : r.recordingPools) vkDestroyCommandPool(dev, p.pool, nullptr);
    r.workers.reset(); // joins the workers
    r = FrameRecorder{};
}

static void beginCommands(FrameRecorder& r) {
    VK_CHECK(vkResetCommandBuffer(r.cmd, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(r.cmd, &bi));
}

// Submits the (ended) command buffers in order as one batch and waits for the GPU. `name` names
// the submission's CPU scope ("submit NAME").
static void submitAndWait(FrameRecorder& r, const VkCommandBuffer* cmds, uint32_t count,
                          const std::string& name) {
    // The recorder's vectors, reused: a submit allocates nothing (one per pass on CPU devices).
    std::vector<VkCommandBufferSubmitInfo>& cbis = r.submitCommandBuffers;
    cbis.assign(count, {VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO});
    for (uint32_t i = 0; i < count; ++i) cbis[i].commandBuffer = cmds[i];
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    si.commandBufferInfoCount = count;
    si.pCommandBufferInfos = cbis.data();
    std::vector<VkSemaphoreSubmitInfo>& waits = r.submitWaits;
    waits.clear();
    for (VkSemaphore sem : r.waitOnce) {
        VkSemaphoreSubmitInfo w{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
        w.semaphore = sem;
        w.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
        waits.push_back(w);
    }
    r.waitOnce.clear();
    si.waitSemaphoreInfoCount = uint32_t(waits.size());
    si.pWaitSemaphoreInfos = waits.data();
    VK_CHECK(vkResetFences(r.gpu->device.device, 1, &r.fence));
    auto submitStart = std::chrono::steady_clock::now();
    double submitCpuStart = threadCpuMs();
    VK_CHECK(vkQueueSubmit2(r.gpu->device.queue, 1, &si, r.fence));
    auto waitStart = std::chrono::steady_clock::now();
    double submitCpuMs = threadCpuMs() - submitCpuStart;
    double submitWallMs = msBetween(submitStart, waitStart);
    r.submits.push_back(
        {"submit " + name, msBetween(r.frameStart, submitStart), submitWallMs, submitCpuMs});
    // A CPU device's submit can block on its queue thread (lavapipe: up to 16 ms at 1M instances
    // with ~0.01 ms of this thread's CPU): the blocked part is waiting for the GPU too.
    r.gpuWaitMs += std::max(0.0, submitWallMs - submitCpuMs);
    // A hang detector, not a budget. A CPU device (lavapipe) compiles each pipeline's shader
    // on its first dispatch inside the queue, so a first frame with many permutations (the
    // shadel path's spectra: every mode of shade.comp) waits minutes on a loaded machine.
    const bool cpuDevice = r.gpu->device.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    const uint64_t timeoutSeconds = cpuDevice ? 600 : 120;
    VkResult res =
        vkWaitForFences(r.gpu->device.device, 1, &r.fence, VK_TRUE, timeoutSeconds * 1000000000ull);
    r.gpuWaitMs +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitStart)
            .count();
    if (res == VK_TIMEOUT)
        throw DeviceError(format("GPU frame did not finish within %llu s (device hang?)",
                                 (unsigned long long)timeoutSeconds));
    VK_CHECK(res);
}

static void submitAndWait(FrameRecorder& r, const std::string& name) {
    VK_CHECK(vkEndCommandBuffer(r.cmd));
    submitAndWait(r, &r.cmd, 1, name);
}

void beginFrame(FrameRecorder& r) {
    Gpu& gpu = *r.gpu;
    prepareBindlessFrame(gpu, gpu.frameIndex);
    r.passes.clear();
    r.deferred.clear();
    r.workerTimings.clear();
    r.submits.clear();
    r.recordingMs = 0.0;
    r.gpuWaitMs = 0.0;
    r.frameStart = std::chrono::steady_clock::now();
    vkResetQueryPool(gpu.device.device, r.queries, 0, r.maxPasses * 2);
    if (r.mode == TimingMode::Timestamps && r.recordingThreads == 1) beginCommands(r);
}

void pass(FrameRecorder& r, const char* name, const std::function<void(VkCommandBuffer)>& record) {
    Gpu& gpu = *r.gpu;
    uint32_t index = uint32_t(r.passes.size());
    SHADEL_ASSERT(index < r.maxPasses);
    r.passes.push_back({name, 0.0, 0.0, 0.0});
    if (r.recordingThreads > 1) { // recorded in endFrame, on the workers
        r.deferred.push_back({record, VK_NULL_HANDLE});
        return;
    }
    if (r.mode == TimingMode::SubmitPerPass) {
        auto start = std::chrono::steady_clock::now();
        r.passes.back().startMs =
            std::chrono::duration<double, std::milli>(start - r.frameStart).count();
        double cpuStart = r.timeRecording ? threadCpuMs() : 0.0;
        beginCommands(r);
        beginLabel(gpu, r.cmd, name);
        record(r.cmd);
        endLabel(gpu, r.cmd);
        if (r.timeRecording) r.passes.back().recordCpuMs = threadCpuMs() - cpuStart;
        submitAndWait(r, r.passes.back().name);
        r.passes.back().gpuMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        return;
    }
    double cpuStart = r.timeRecording ? threadCpuMs() : 0.0;
    beginLabel(gpu, r.cmd, name);
    vkCmdWriteTimestamp2(r.cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, r.queries, index * 2);
    record(r.cmd);
    vkCmdWriteTimestamp2(r.cmd, VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT, r.queries, index * 2 + 1);
    endLabel(gpu, r.cmd);
    if (r.timeRecording) r.passes.back().recordCpuMs = threadCpuMs() - cpuStart;
}

// Records every kept pass into its own command buffer, on the workers (threaded frames).
static void recordDeferredPasses(FrameRecorder& r) {
    Gpu& gpu = *r.gpu;
    uint32_t n = uint32_t(r.deferred.size());
    for (RecordingPool& p : r.recordingPools) {
        VK_CHECK(vkResetCommandPool(gpu.device.device, p.pool, 0));
        p.used = 0;
    }
    r.workerTimings.assign(r.recordingThreads, {});
    std::vector<Clock::time_point> firstStart(r.recordingThreads), lastEnd(r.recordingThreads);
    Clock::time_point start = Clock::now();
    r.workers->parallelFor(n, [&](uint32_t i, uint32_t worker) {
        Clock::time_point passStart = Clock::now();
        double cpuStart = threadCpuMs();
        RecordingPool& p = r.recordingPools[worker];
        if (p.used == p.buffers.size()) {
            VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
            ai.commandPool = p.pool;
            ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
            ai.commandBufferCount = 1;
            VkCommandBuffer cmd = VK_NULL_HANDLE;
            VK_CHECK(vkAllocateCommandBuffers(gpu.device.device, &ai, &cmd));
            std::string name = "frame.recordingWorker" + std::to_string(worker) + ".commands" +
                               std::to_string(p.buffers.size());
            setName(gpu.device, cmd, VK_OBJECT_TYPE_COMMAND_BUFFER, name.c_str());
            p.buffers.push_back(cmd);
        }
        VkCommandBuffer cmd = p.buffers[p.used++];
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK_CHECK(vkBeginCommandBuffer(cmd, &bi));
        const char* name = r.passes[i].name.c_str();
        beginLabel(gpu, cmd, name);
        bool stamps = r.mode == TimingMode::Timestamps;
        if (stamps)
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, r.queries, i * 2);
        r.deferred[i].record(cmd);
        if (stamps)
            vkCmdWriteTimestamp2(cmd, VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT, r.queries, i * 2 + 1);
        endLabel(gpu, cmd);
        VK_CHECK(vkEndCommandBuffer(cmd));
        r.deferred[i].cmd = cmd;
        r.passes[i].recordCpuMs = threadCpuMs() - cpuStart; // only this worker writes pass i
        RecordingWorkerTiming& t = r.workerTimings[worker];
        if (t.passes++ == 0) firstStart[worker] = passStart;
        lastEnd[worker] = Clock::now();
        t.cpuMs += threadCpuMs() - cpuStart;
    });
    r.recordingMs = msBetween(start, Clock::now());
    for (uint32_t w = 0; w < r.recordingThreads; ++w) {
        RecordingWorkerTiming& t = r.workerTimings[w];
        if (!t.passes) continue;
        t.startMs = msBetween(r.frameStart, firstStart[w]);
        t.durationMs = msBetween(firstStart[w], lastEnd[w]);
    }
}

// Submits the recorded passes in order: one batch (timestamps) or one by one (submit per pass).
static void submitDeferredPasses(FrameRecorder& r) {
    uint32_t n = uint32_t(r.deferred.size());
    if (r.mode == TimingMode::Timestamps) {
        std::vector<VkCommandBuffer> cmds(n);
        for (uint32_t i = 0; i < n; ++i) cmds[i] = r.deferred[i].cmd;
        if (n) submitAndWait(r, cmds.data(), n, "frame");
        return;
    }
    for (uint32_t i = 0; i < n; ++i) {
        Clock::time_point start = Clock::now();
        r.passes[i].startMs = msBetween(r.frameStart, start);
        submitAndWait(r, &r.deferred[i].cmd, 1, r.passes[i].name);
        r.passes[i].gpuMs = msBetween(start, Clock::now());
    }
}

void endFrame(FrameRecorder& r) {
    Gpu& gpu = *r.gpu;
    if (r.recordingThreads > 1) {
        recordDeferredPasses(r);
        submitDeferredPasses(r);
        r.deferred.clear(); // the captured state is released with the frame
    } else if (r.mode == TimingMode::Timestamps) {
        submitAndWait(r, "frame");
    }
    if (r.mode == TimingMode::Timestamps) {
        uint32_t n = uint32_t(r.passes.size());
        if (n) {
            std::vector<uint64_t> ticks(n * 2);
            VK_CHECK(vkGetQueryPoolResults(
                gpu.device.device, r.queries, 0, n * 2, ticks.size() * sizeof(uint64_t),
                ticks.data(), sizeof(uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
            double msPerTick = double(gpu.device.timestampPeriodNs) * 1e-6;
            for (uint32_t i = 0; i < n; ++i) {
                r.passes[i].gpuMs = double(ticks[i * 2 + 1] - ticks[i * 2]) * msPerTick;
                r.passes[i].startMs = double(ticks[i * 2] - ticks[0]) * msPerTick;
            }
        }
    }
    r.frameMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - r.frameStart)
            .count();
    gpu.frameIndex++;
}

} // namespace shadel
