// After the GPU finished: the decoupled frame's counters read back (and the level wants that
// place next frame's windows), and the statistics over the frames rendered so far.
#include <algorithm>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/log.h"
#include "render/shadel/decoupled_state.h"

namespace shadel {

void finishDecoupledFrame(Renderer& r) {
    DecoupledState& d = *r.decoupled;
    FrameCounters f;
    std::memcpy(&f.counters, mapped(*r.gpu, d.counters), sizeof(f.counters));
    finishMaterialProgramsFrame(*r.gpu, d.programs.get(), f.counters.shadeCount);
    f.objectsDecoupled = d.objectsDecoupled;
    f.objectsForward = d.objectsForward;
    f.objectsSmallForward = d.objectsSmallForward;
    f.objectsSheetLimited = d.objectsSheetLimited;
    f.objectsRateBiased = d.objectsRateBiased;
    f.objectsRateTextured = d.objectsRateTextured;
    f.rateBiasSum = d.rateBiasSum;
    f.firstMipHistogram = d.firstMipHistogram;
    f.rectBlocks = d.rectBlockCount;
    f.wholeLevelBlocks = d.wholeLevelBlocks;
    f.windowMoves = d.windowMoves;
    // Level windows: what this frame's samples wanted of each level places next frame's windows.
    const auto* wants = static_cast<const glm::uvec4*>(mapped(*r.gpu, d.levelWants));
    for (size_t i = 0; d.levelWindows && i < d.rects.size(); ++i) { // off: nothing reads them
        const gpu::GpuShadelRect& rect = d.rects[i];
        ObjectSlot& o = d.slots[d.instances[rect.object].slot]; // has rects: holds a slot
        glm::uvec4 w = wants[i];
        glm::uvec4 wanted = w.z == 0 ? glm::uvec4(0) // nothing wanted
                                     : glm::uvec4(0xFFFFu - w.x, 0xFFFFu - w.y, w.z, w.w);
        // Settled: every level's wants, valid this frame, are the same next frame (an object's
        // rects are listed in order from its firstMip).
        bool same = o.wantedFor[rect.mip] == d.frameNumber + 1 && o.wanted[rect.mip] == wanted;
        o.wantsSettled = (rect.mip == o.firstMip || o.wantsSettled) && same;
        o.wanted[rect.mip] = wanted;
        o.wantedFor[rect.mip] = d.frameNumber + 2; // next frame's number + 1 (0: none yet)
    }
    f.shadingBias = d.shadingBias;
    f.objectsReusable = d.objectsReusable;
    d.history.push_back(f);
    d.frameNumber++;
    // Next frame's bias from this frame's counts (one frame of latency, as with a ring of
    // readback buffers on a pipelined GPU).
    if (d.capacityControl)
        updateCapacityControl(d.controller, f.counters.chunksRequested, d.capacityChunks);
    if (f.counters.chunksOverflowed)
        SHADEL_WARN("shade storage full: %u of %u marked chunks did not fit (%u chunks capacity); "
                    "those samples were shaded forward",
                    f.counters.chunksOverflowed, f.counters.chunksRequested, d.capacityChunks);
}

void decoupledStats(const Renderer& r, nlohmann::json& s) {
    const DecoupledState& d = *r.decoupled;
    if (d.history.empty()) return;
    const FrameCounters& last = d.history.back();
    materialProgramStats(d.programs.get(), s);
    uint64_t misses = 0, overflowSamples = 0;
    for (const FrameCounters& f : d.history) {
        misses += f.counters.reconstructionMisses;
        overflowSamples += f.counters.overflowSamples;
    }
    // Stored: every allocated chunk (the MIP chain's density); shaded: those not carried over.
    uint64_t chunksStored = last.counters.chunksAllocated;
    uint64_t chunksShaded =
        chunksStored - std::min<uint64_t>(last.counters.chunksReused, chunksStored);
    uint64_t stored = chunksStored * SHADEL_CHUNK * SHADEL_CHUNK;
    uint64_t shaded = chunksShaded * SHADEL_CHUNK * SHADEL_CHUNK;
    uint64_t covered = s.value("pixels_covered", uint64_t(0));
    s["shadels_shaded"] = shaded;
    s["shadels_stored"] = stored;
    s["shadels_reused"] = stored - shaded;
    s["reuse"] = d.reuse;
    s["reuse_refresh_period"] = d.refreshPeriod;
    s["objects_reusable"] = last.objectsReusable;
    // Over the frames after the first (the first has nothing to reuse), when there are any.
    uint64_t storedSum = 0, reusedSum = 0;
    for (size_t i = d.history.size() > 1 ? 1 : 0; i < d.history.size(); ++i) {
        storedSum += d.history[i].counters.chunksAllocated;
        reusedSum += d.history[i].counters.chunksReused;
    }
    s["reuse_fraction"] = storedSum ? double(reusedSum) / double(storedSum) : 0.0;
    // Why the rest was shaded, as fractions of the same stored chunks (over the same frames):
    // what a better reuse could still win, and from where.
    const char* const reasonNames[SHADEL_SHADED_REASONS] = {"not_reusable", "new",        "refresh",
                                                            "near_change",  "rt_history", "view"};
    nlohmann::json because = nlohmann::json::object();
    for (uint32_t k = 0; k < SHADEL_SHADED_REASONS; ++k) {
        uint64_t sum = 0;
        for (size_t i = d.history.size() > 1 ? 1 : 0; i < d.history.size(); ++i)
            sum += d.history[i].counters.shadedBecause[k];
        because[reasonNames[k]] = storedSum ? double(sum) / double(storedSum) : 0.0;
    }
    s["shaded_because"] = because;
    // Shadels per covered pixel: the storage's density (shaded or carried over).
    s["shadels_per_pixel"] = covered ? double(stored) / double(covered) : 0.0;
    s["chunks_allocated"] = last.counters.chunksAllocated;
    s["chunks_requested"] = last.counters.chunksRequested;
    s["chunks_overflowed"] = last.counters.chunksOverflowed;
    s["chunks_capacity"] = d.capacityChunks;
    s["shading_bias"] = last.shadingBias;
    s["capacity_control"] = d.capacityControl;
    // Per frame, for the capacity controller's trace.
    nlohmann::json biasTrace = nlohmann::json::array(), overflowTrace = nlohmann::json::array();
    for (const FrameCounters& f : d.history) {
        biasTrace.push_back(f.shadingBias);
        overflowTrace.push_back(f.counters.chunksOverflowed);
    }
    s["shading_bias_per_frame"] = biasTrace;
    s["chunks_overflowed_per_frame"] = overflowTrace;
    s["trilinear_band"] = d.trilinearBand;
    s["material_samples"] = r.settings.materialSamples;
    s["reconstruction_misses"] = misses;
    s["overflow_samples"] = overflowSamples;
    s["marked_blocks"] = last.counters.markedBlocks;
    s["chunks_shaded"] = chunksShaded;
    // The queued chunks of each shading class (shade.comp): plain materials have every material
    // feature compiled out; only supersampled ones (point-function procedurals) supersample.
    s["chunks_by_shading_class"] = {
        {"plain", last.counters.classCount[SHADE_QUEUE_PLAIN - 1]},
        {"featured", last.counters.classCount[SHADE_QUEUE_FEATURED - 1]},
        {"supersampled", last.counters.classCount[SHADE_QUEUE_SUPERSAMPLED - 1]},
        {"textured", last.counters.classCount[SHADE_QUEUE_TEXTURED - 1]}};
    nlohmann::json perMip = nlohmann::json::array();
    for (uint32_t k = 0; k < SHADEL_MAX_MIPS; ++k) perMip.push_back(last.counters.chunksPerMip[k]);
    s["chunks_per_mip"] = perMip;
    // Pixels drawn from shadels whose MIP-0 shadel is larger than the pixel (the image can only
    // be blurrier than forward there), over the pixels reconstructed from shadels.
    s["reconstructed_pixels_sampled"] = last.counters.reconstructedPixels; // 1 of every 2x2
    s["magnified_pixel_fraction"] =
        last.counters.reconstructedPixels
            ? double(last.counters.magnifiedPixels) / double(last.counters.reconstructedPixels)
            : 0.0;
    s["objects_decoupled"] = last.objectsDecoupled;
    s["objects_forward"] = last.objectsForward; // small (hybrid) + no sheet space
    s["objects_forward_small"] = last.objectsSmallForward;
    s["objects_sheet_limited"] = last.objectsSheetLimited;
    // Material shading rate: the objects shaded coarser than their footprint asks for, and the
    // mean bias over all decoupled objects (MIPs).
    s["material_rate"] = r.settings.materialRate;
    s["objects_rate_biased"] = last.objectsRateBiased;
    // Of them, textured ones: biased only where the view magnifies their textures.
    s["objects_rate_textured"] = last.objectsRateTextured;
    s["material_rate_bias_mean"] =
        last.objectsDecoupled ? double(last.rateBiasSum) / double(last.objectsDecoupled) : 0.0;
    nlohmann::json firstMips = nlohmann::json::array();
    for (uint32_t k = 0; k < SHADEL_MAX_MIPS; ++k) firstMips.push_back(last.firstMipHistogram[k]);
    s["objects_by_first_mip"] = firstMips;
    s["sheet_blocks_allocated"] = last.rectBlocks; // rect blocks of every level in use
    s["sheet_blocks_touched"] = last.counters.markedBlocks;
    s["level_windows"] = d.levelWindows;
    s["sheet_blocks_whole_levels"] = last.wholeLevelBlocks; // the same levels without windows
    s["level_window_moves"] = last.windowMoves;
    s["window_fallback_pixel_fraction"] =
        last.counters.reconstructedPixels
            ? double(last.counters.windowFallbackPixels) / double(last.counters.reconstructedPixels)
            : 0.0;
    // Of all pixels, those whose window lagged more than a level: shaded forward (camera cuts).
    s["window_forward_pixel_fraction"] =
        last.counters.reconstructedPixels
            ? double(last.counters.windowForwardPixels) / double(last.counters.reconstructedPixels)
            : 0.0;
    // Compute marking: the quads its first pass could not mark on one triangle, by the pass that
    // took them (shaders/shadel/mark_quad.glsl; per_pixel includes the two-triangle quads whose
    // triangles' levels differ).
    if (r.visibility)
        s["marking_listed_quads"] = {{"two_triangles", last.counters.markQuadsTwoTriangles},
                                     {"per_pixel", last.counters.markQuadsPerPixel}};
    s["sheet_shadels"] = uint64_t(d.sheetBlocks) * SHADEL_BLOCK;
    // The occupancy bookkeeping per shadel (~1.5 bits when chunks are full): the 64-bit mask +
    // 32-bit offset of every block in use, over the shadels its marked chunks hold.
    uint64_t shadelsMarked = uint64_t(last.counters.chunksRequested) * 64;
    s["occupancy_bits_per_shadel"] =
        shadelsMarked ? double(last.counters.markedBlocks) * 96.0 / double(shadelsMarked) : 0.0;
    // The whole sheet's bookkeeping for this frame (every allocated rect block) per shadel.
    s["sheet_bits_per_shadel"] = stored ? double(last.rectBlocks) * 96.0 / double(stored) : 0.0;
    // Frontend/backend overlap (coarse_visit.h): where the frames' grid visits came from.
    const FrontendVisitStats& v = d.visitStats;
    s["frontend"] = {{"prefetched_visits", v.prefetched},
                     {"inline_visits", v.inlineVisits},
                     {"readback_visits", v.readbackVisits},
                     {"visits_not_prefetched_playback", v.skippedPlayback},
                     {"visits_discarded", v.discarded},
                     {"visit_worker_cpu_ms", v.workerCpuMs},
                     {"wait_ms", v.waitMs}};
    s["storage_used"] =
        d.capacityChunks ? double(last.counters.chunksAllocated) / d.capacityChunks : 0.0;
}

} // namespace shadel
