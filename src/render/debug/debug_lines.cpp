#include "render/debug/debug_lines.h"

#include <algorithm>
#include <cstring>
#include <sstream>

#include "common/shared_types.h"
#include "core/error.h"
#include "core/log.h"
#include "render/forward/forward_passes.h"
#include "render/gpu_scene.h"
#include "render/renderer.h"
#include "rhi/gpu.h"
#include "rhi/pipeline.h"
#include "rhi/rendering.h"
#include "rhi/resources.h"

namespace shadel {

struct DebugLinesState {
    uint32_t mask = 0;
    uint32_t capacity = 0;
    BufferHandle lines;    // GpuDebugLines header + GpuDebugLine[capacity]
    BufferHandle readback; // the header after the frame
    Pipeline emit, args, draw;
};

void DebugLinesStateDeleter::operator()(DebugLinesState* state) const {
    delete state;
}

uint32_t parseDebugLines(const std::string& list) {
    if (list == "none") return 0;
    uint32_t mask = 0;
    std::stringstream ss(list);
    std::string kind;
    while (std::getline(ss, kind, ',')) {
        if (kind == "lights")
            mask |= DEBUG_LINES_LIGHTS;
        else if (kind == "blockers")
            mask |= DEBUG_LINES_BLOCKERS;
        else if (kind == "chunks")
            mask |= DEBUG_LINES_CHUNKS;
        else
            throw InputError(format("--debug-lines %s: unknown kind '%s' (expected none or a comma "
                                    "list of lights, blockers, chunks)",
                                    list.c_str(), kind.c_str()));
    }
    if (mask == 0)
        throw InputError(format("--debug-lines %s: expected none or a comma list of lights, "
                                "blockers, chunks",
                                list.c_str()));
    return mask;
}

DebugLinesStatePtr createDebugLines(Renderer& r) {
    if (r.settings.debugLines == 0) return nullptr;
    Gpu& gpu = *r.gpu;
    DebugLinesStatePtr state(new DebugLinesState);
    DebugLinesState& d = *state;
    d.mask = r.settings.debugLines;
    // The default 256k segments (8 MiB) hold every chunk box of a 1280x720 decoupled frame
    // (about 20k chunks, 12 segments each) with room to spare.
    d.capacity = std::max(r.settings.debugLineCapacity, 1u);
    VkDeviceSize bytes =
        sizeof(gpu::GpuDebugLines) + VkDeviceSize(d.capacity) * sizeof(gpu::GpuDebugLine);
    d.lines =
        createBuffer(gpu, {"debugLines", bytes,
                           VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT});
    d.readback = createBuffer(gpu, {"debugLines.readback", sizeof(gpu::GpuDebugLines),
                                    VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
    if (!d.lines || !d.readback) throw DeviceError("out of GPU memory for the debug line buffer");
    d.emit = createComputePipeline(gpu, "debugLinesEmit", "debug_debug_lines_emit.comp.spv");
    d.args = createComputePipeline(gpu, "debugLinesArgs", "debug_debug_lines_args.comp.spv");
    GraphicsPipelineDesc desc;
    desc.name = "debugLines";
    desc.vertexShader = "debug_debug_lines.vert.spv";
    desc.fragmentShader = "debug_debug_lines.frag.spv";
    desc.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    desc.depthFormat = VK_FORMAT_D32_SFLOAT;
    desc.depthWrite = false; // tested against the scene, never hiding it
    desc.cullMode = VK_CULL_MODE_NONE;
    desc.topology = VK_PRIMITIVE_TOPOLOGY_LINE_LIST;
    d.draw = createGraphicsPipeline(gpu, desc);
    return state;
}

void destroyDebugLines(Renderer& r, DebugLinesStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    for (Pipeline* p : {&state->emit, &state->args, &state->draw}) destroy(gpu, *p);
    destroy(gpu, state->lines);
    destroy(gpu, state->readback);
    state.reset();
}

uint64_t debugLinesAddress(const Renderer& r) {
    return r.debugLines ? address(*r.gpu, r.debugLines->lines) : 0;
}

void recordDebugLinesClear(Renderer& r, VkCommandBuffer cmd) {
    DebugLinesState& d = *r.debugLines;
    // Last frame's draw read the buffer (indirect arguments, vertices).
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT | VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT |
                      VK_PIPELINE_STAGE_2_COPY_BIT,
                  VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                      VK_ACCESS_2_TRANSFER_READ_BIT,
                  VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    gpu::GpuDebugLines header{};
    header.instanceCount = 1;
    header.capacity = d.capacity;
    header.mask = d.mask;
    vkCmdUpdateBuffer(cmd, vkBuffer(*r.gpu, d.lines), 0, sizeof(header), &header);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void recordDebugLinePasses(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene& scene,
                           uint32_t lightCount) {
    Gpu& gpu = *r.gpu;
    DebugLinesState& d = *r.debugLines;
    struct Push {
        uint64_t frame;
    } push{frame};
    // --debug-lines-at: the pixel in the internal (supersampled) frame, whose depth the emit
    // pass reads back to the surface point the lights must reach.
    struct EmitPush {
        uint64_t frame;
        int32_t atX, atY;
        uint32_t depthSlot;
    } emitPush{frame, -1, -1, slot(gpu, r.depthRead).value};
    if (r.settings.debugLinesAtX >= 0) {
        emitPush.atX = r.settings.debugLinesAtX * int32_t(r.settings.ssaa);
        emitPush.atY = r.settings.debugLinesAtY * int32_t(r.settings.ssaa);
    }
    pass(rec, "debugLinesEmit", [&, push, emitPush, lightCount](VkCommandBuffer cmd) {
        // Segments appended by earlier passes (shadelShading's chunk boxes) come first.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        if (d.mask & (DEBUG_LINES_LIGHTS | DEBUG_LINES_BLOCKERS)) {
            bool readDepth = emitPush.atX >= 0;
            if (readDepth) // after every pass that wrote depth; back to the attachment below
                sceneDepthToSampled(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
            bind(gpu, cmd, d.emit);
            pushConstants(gpu, cmd, emitPush);
            // One invocation per light, then one per blocker (the shader reads both counts).
            uint32_t invocations = lightCount + scene.blockerCount;
            if (invocations) vkCmdDispatch(cmd, (invocations + 63) / 64, 1, 1);
            memoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
            if (readDepth) sceneDepthToAttachment(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
        }
        bind(gpu, cmd, d.args);
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, 1, 1, 1);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT |
                          VK_PIPELINE_STAGE_2_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT,
                      VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                          VK_ACCESS_2_TRANSFER_READ_BIT);
        VkBufferCopy header{0, 0, sizeof(gpu::GpuDebugLines)};
        vkCmdCopyBuffer(cmd, vkBuffer(gpu, d.lines), vkBuffer(gpu, d.readback), 1, &header);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    });
    pass(rec, "debugLines", [&, push](VkCommandBuffer cmd) {
        // After every pass that wrote colour or depth.
        memoryBarrier(cmd,
                      VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                          VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT |
                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                          VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT,
                      VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT |
                          VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
        beginRendering(cmd, r.internalWidth, r.internalHeight, {{vkView(gpu, r.hdrTarget)}},
                       {vkView(gpu, r.depthTarget)});
        bind(gpu, cmd, d.draw);
        pushConstants(gpu, cmd, push);
        vkCmdDrawIndirect(cmd, vkBuffer(gpu, d.lines), 0, 1, 0);
        vkCmdEndRendering(cmd);
    });
}

void debugLinesStats(const Renderer& r, nlohmann::json& stats) {
    if (!r.debugLines) return;
    gpu::GpuDebugLines header;
    std::memcpy(&header, mapped(*r.gpu, r.debugLines->readback), sizeof(header));
    uint32_t drawn = std::min(header.count, header.capacity);
    if (header.count > drawn)
        logLine(LogLevel::Warn, "--debug-lines: %u of %u segments dropped (the buffer holds %u)",
                header.count - drawn, header.count, header.capacity);
    stats["debug_lines"] = {
        {"segments", drawn}, {"dropped", header.count - drawn}, {"capacity", header.capacity}};
}

} // namespace shadel
