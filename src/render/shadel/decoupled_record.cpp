// The decoupled frame's GPU passes: marking and allocation, work queues, carry-over, shading,
// reconstruction or resolve, and the sheet view.
#include <algorithm>

#include "render/background/background.h"
#include "render/decals/decals.h"
#include "render/forward/forward_passes.h"
#include "render/oit/oit.h"
#include "render/shadel/decoupled_state.h"
#include "render/shadel/visibility.h"

namespace shadel {

namespace {
struct FramePush {
    uint64_t frame;
};
void computeToCompute(VkCommandBuffer cmd) {
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT |
                      VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}

// A compute pipeline of this path with the frame's constants: over `groups` workgroups, or over
// the indirect arguments the GPU wrote into GpuShadelCounters at `argsOffset`.
void dispatchFrame(Gpu& gpu, VkCommandBuffer cmd, const Pipeline& p, uint64_t frame,
                   uint32_t groups) {
    bind(gpu, cmd, p);
    pushConstants(gpu, cmd, FramePush{frame});
    vkCmdDispatch(cmd, groups, 1, 1);
}
void dispatchCounted(Gpu& gpu, VkCommandBuffer cmd, const DecoupledState& d, const Pipeline& p,
                     uint64_t frame, VkDeviceSize argsOffset) {
    bind(gpu, cmd, p);
    pushConstants(gpu, cmd, FramePush{frame});
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, d.counters), argsOffset);
}
// The passes that route chunks to the material program lists (fill, near change) push their
// addresses after the frame's (render/materials/material_programs.h).
void dispatchRouting(Gpu& gpu, VkCommandBuffer cmd, const DecoupledState& d, const Pipeline& p,
                     uint64_t frame, VkDeviceSize argsOffset) {
    bind(gpu, cmd, p);
    pushConstants(gpu, cmd, programListsPush(gpu, d.programs.get(), frame));
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, d.counters), argsOffset);
}
} // namespace

ShadelShadingQueue shadelShadingQueue(const Renderer& r) {
    const DecoupledState& d = *r.decoupled;
    return {d.counters, offsetof(gpu::GpuShadelCounters, invocationDispatch), d.capacityChunks,
            d.shadeOptional};
}

void recordDecoupledMarking(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    uint32_t rectGroups = (d.rectBlockCount + 63) / 64;

    pass(rec, "shadelClear", [&, frame, rectGroups](VkCommandBuffer cmd) {
        vkCmdFillBuffer(cmd, vkBuffer(gpu, d.counters), 0, VK_WHOLE_SIZE, 0);
        if (!d.rects.empty())
            vkCmdFillBuffer(cmd, vkBuffer(gpu, d.levelWants), 0, d.rects.size() * 16, 0);
        if (rectGroups) dispatchFrame(gpu, cmd, d.clear, frame, rectGroups);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_CLEAR_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT |
                          VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });

    pass(rec, r.visibility ? "markingCompute" : "marking", [&, frame](VkCommandBuffer cmd) {
        // --marking visibility: a compute pass over the visibility buffer's pixels; the
        // transparent layers behind its nearest surface are marked by raster below.
        if (r.visibility) {
            recordMarkingCompute(r, cmd, frame);
            if (decoupledTransparentDraws(r) == 0) return;
            memoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        beginSceneDepthPass(r, cmd, false); // against the prepass depth
        if (!r.visibility) {
            bind(gpu, cmd, d.mark);
            pushConstants(gpu, cmd, RasterPush{frame, 0});
            drawCameraList(r, cmd, DRAW_LIST_DECOUPLED);
        }
        // Transparent surfaces: tested against the opaque depth only, never against each
        // other (nothing here writes depth), so every layer marks what it will read.
        bind(gpu, cmd, d.markTransparent);
        pushConstants(gpu, cmd, RasterPush{frame, 0});
        drawCameraList(r, cmd, DRAW_LIST_DECOUPLED_BLEND);
        vkCmdEndRendering(cmd);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    });

    pass(rec, "shadelAllocate", [&, frame, rectGroups](VkCommandBuffer cmd) {
        if (rectGroups) dispatchFrame(gpu, cmd, d.allocate, frame, rectGroups);
        computeToCompute(cmd);
        // The level wants (marking and this pass) are read back after the frame.
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
            VK_ACCESS_2_HOST_READ_BIT);
    });
}

void recordDecoupledShading(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene&) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;

    pass(rec, "workQueues", [&, frame](VkCommandBuffer cmd) {
        recordProgramListsClear(gpu, cmd, d.programs.get());
        dispatchFrame(gpu, cmd, d.queueSetup, frame, 1);
        computeToCompute(cmd);
        dispatchRouting(gpu, cmd, d, d.fillQueue, frame,
                        offsetof(gpu::GpuShadelCounters, fillDispatch));
        computeToCompute(cmd);
        dispatchFrame(gpu, cmd, d.dispatchSetup, frame, 1);
        recordProgramListsSetup(gpu, cmd, d.programs.get());
        computeToCompute(cmd);
    });

    // Preserved layers: chunks whose inputs did not change copy last frame's shadels.
    pass(rec, "carryOver", [&, frame](VkCommandBuffer cmd) {
        // The shade storage's buffers: reconstruction two frames ago (raster or compute
        // resolve) read this frame's, so this pass's writes and the shading pass's after it
        // wait for those reads; last frame's shading and carry-over wrote last frame's, which
        // both passes read.
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        dispatchCounted(gpu, cmd, d, d.carryOver, frame,
                        offsetof(gpu::GpuShadelCounters, copyDispatch));
        // Chunks on objects a changed region meets: carried over here unless one of their
        // shadels lies in a region, else appended to their class's list, whose dispatch sizes
        // are then set again. (Spectra's classify decides for its whole queue instead.)
        if (d.nearChange.pipeline && !usesChunkSpectra(r)) {
            dispatchRouting(gpu, cmd, d, d.nearChange, frame,
                            offsetof(gpu::GpuShadelCounters, nearChangeDispatch));
            computeToCompute(cmd);
            dispatchFrame(gpu, cmd, d.dispatchSetup, frame, 1);
            recordProgramListsSetup(gpu, cmd, d.programs.get());
            computeToCompute(cmd);
        }
    });

    recordDecalCulling(r, rec, frame); // the decal lists of screen tiles and queued chunks

    if (usesChunkSpectra(r)) // --spectra: chunks binned by the lighting features they need
        pass(rec, "shadelChunkSpectra",
             [&, frame](VkCommandBuffer cmd) { recordChunkSpectraClassify(r, cmd, frame); });

    pass(rec, "shadelShading", [&, frame](VkCommandBuffer cmd) {
        if (usesChunkSpectra(r)) { // one permutation per spectrum (render/lighting)
            recordChunkSpectraShading(r, cmd, frame);
        } else {
            // One pipeline per shading class, each over its list; no barrier between: the
            // classes' chunks are disjoint.
            for (uint32_t c = 0; c < SHADE_CLASSES; ++c)
                dispatchCounted(gpu, cmd, d, d.shade[c], frame,
                                offsetof(gpu::GpuShadelCounters, classDispatch) +
                                    c * sizeof(glm::uvec4));
        }
        // The material programs' stages over their lists (render/materials).
        recordMaterialProgramStages(gpu, cmd, d.programs.get(), frame);
        // The shade storage this pass and carry-over wrote, read by reconstruction (raster:
        // fragment; --marking visibility: the compute resolve) and the transparency passes.
        memoryBarrier(
            cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
            VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
            VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    });

    if (r.visibility) { // forward (hybrid) objects rastered, then the compute resolve
        pass(rec, "hybridForward",
             [&, frame](VkCommandBuffer cmd) { recordHybridForward(r, cmd, frame); });
        pass(rec, "resolveCompute",
             [&, frame](VkCommandBuffer cmd) { recordResolveCompute(r, cmd, frame); });
        return;
    }
    // Decoupled objects read their shadels; forward objects (hybrid) shade as usual.
    pass(rec, "reconstruction", [&, frame](VkCommandBuffer cmd) {
        beginSceneColorPass(r, cmd, true);
        bind(gpu, cmd, d.reconstruct);
        pushConstants(gpu, cmd, RasterPush{frame, 0});
        drawCameraList(r, cmd, DRAW_LIST_DECOUPLED, shadingIndices(r));
        drawForwardLists(r, cmd, frame);
        recordBackground(r, cmd, frame, false);
        vkCmdEndRendering(cmd);
    });
}

void recordDecoupledPostPasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (r.settings.visualize != Visualize::Sheet) return;
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    pass(rec, "sheetView", [&, frame](VkCommandBuffer cmd) {
        uint32_t rowsInUse = 16;
        for (const gpu::GpuShadelRect& rect : d.rects)
            rowsInUse = std::max(rowsInUse, rect.rect.y + rect.rect.w);
        struct {
            uint64_t frame;
            uint64_t pixels;
            uint32_t width, height, rowsInUse;
        } push{frame, address(gpu, r.pixels), r.settings.width, r.settings.height, rowsInUse};
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        bind(gpu, cmd, d.sheetView);
        pushConstants(gpu, cmd, push);
        vkCmdDispatch(cmd, (r.settings.width + 7) / 8, (r.settings.height + 7) / 8, 1);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                      VK_ACCESS_2_HOST_READ_BIT);
    });
}

} // namespace shadel
