#include "rhi/frame.h"

#include "core/assert.h"
#include "rhi/gpu.h"

namespace shadel {

TimingMode defaultTimingMode(const Gpu& gpu) {
    return gpu.device.isCpu ? TimingMode::SubmitPerPass : TimingMode::Timestamps;
}

void initFrameRecorder(Gpu& gpu, FrameRecorder& r, TimingMode mode) {
    r.gpu = &gpu;
    r.mode = mode;
    VkCommandPoolCreateInfo ci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    ci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    ci.queueFamilyIndex = gpu.device.queueFamily;
    VK_CHECK(vkCreateCommandPool(gpu.device.device, &ci, nullptr, &r.pool));
    setName(gpu.device, r.pool, VK_OBJECT_TYPE_COMMAND_POOL, "frame.commandPool");
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
    r = FrameRecorder{};
}

static void beginCommands(FrameRecorder& r) {
    VK_CHECK(vkResetCommandBuffer(r.cmd, 0));
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(r.cmd, &bi));
}

static void submitAndWait(FrameRecorder& r) {
    VK_CHECK(vkEndCommandBuffer(r.cmd));
    VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cbi.commandBuffer = r.cmd;
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    si.commandBufferInfoCount = 1;
    si.pCommandBufferInfos = &cbi;
    std::vector<VkSemaphoreSubmitInfo> waits;
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
    VK_CHECK(vkQueueSubmit2(r.gpu->device.queue, 1, &si, r.fence));
    auto waitStart = std::chrono::steady_clock::now();
    VkResult res =
        vkWaitForFences(r.gpu->device.device, 1, &r.fence, VK_TRUE, 120ull * 1000000000ull);
    r.gpuWaitMs +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - waitStart)
            .count();
    if (res == VK_TIMEOUT)
        throw DeviceError("GPU frame did not finish within 120 s (device hang?)");
    VK_CHECK(res);
}

void beginFrame(FrameRecorder& r) {
    Gpu& gpu = *r.gpu;
    prepareBindlessFrame(gpu, gpu.frameIndex);
    r.passes.clear();
    r.gpuWaitMs = 0.0;
    r.frameStart = std::chrono::steady_clock::now();
    vkResetQueryPool(gpu.device.device, r.queries, 0, r.maxPasses * 2);
    if (r.mode == TimingMode::Timestamps) beginCommands(r);
}

void pass(FrameRecorder& r, const char* name, const std::function<void(VkCommandBuffer)>& record) {
    Gpu& gpu = *r.gpu;
    uint32_t index = uint32_t(r.passes.size());
    SHADEL_ASSERT(index < r.maxPasses);
    r.passes.push_back({name, 0.0, 0.0});
    if (r.mode == TimingMode::SubmitPerPass) {
        auto start = std::chrono::steady_clock::now();
        r.passes.back().startMs =
            std::chrono::duration<double, std::milli>(start - r.frameStart).count();
        beginCommands(r);
        beginLabel(gpu, r.cmd, name);
        record(r.cmd);
        endLabel(gpu, r.cmd);
        submitAndWait(r);
        r.passes.back().gpuMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                .count();
        return;
    }
    beginLabel(gpu, r.cmd, name);
    vkCmdWriteTimestamp2(r.cmd, VK_PIPELINE_STAGE_2_TOP_OF_PIPE_BIT, r.queries, index * 2);
    record(r.cmd);
    vkCmdWriteTimestamp2(r.cmd, VK_PIPELINE_STAGE_2_BOTTOM_OF_PIPE_BIT, r.queries, index * 2 + 1);
    endLabel(gpu, r.cmd);
}

void endFrame(FrameRecorder& r) {
    Gpu& gpu = *r.gpu;
    if (r.mode == TimingMode::Timestamps) {
        submitAndWait(r);
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
