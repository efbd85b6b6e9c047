#include "render/shadel/decoupled.h"
#include "render/decals/decals.h"

#include <algorithm>
#include <cstring>
#include <future>

#include <nlohmann/json.hpp>

#include "core/block_allocator.h"
#include "core/error.h"
#include "core/log.h"
#include "render/background/background.h"
#include "render/culling/instance_grid.h"
#include "render/debug/inspect.h"
#include "render/forward/forward_passes.h"
#include "render/oit/oit.h"
#include "render/renderer.h"
#include "render/shadel/capacity_control.h"
#include "render/shadel/coarse_visit.h"
#include "render/shadel/material_rate.h"
#include "render/shadel/reuse_invalidation.h"
#include "render/shadel/shade_storage.h"
#include "render/shadel/texture_rate.h"
#include "render/shadel/visibility.h"

namespace shadel {

// Shaders address objects in place with this stride (ShadelObjectRef in bindless.glsl).
static_assert(sizeof(gpu::GpuShadelObject) == GPU_SHADEL_OBJECT_BYTES);

namespace {

// The virtual sheet is split into one column of blocks per MIP level; finer levels need more
// room (an object's MIP k rect is a quarter of its MIP k-1 rect, but never below one block).
constexpr uint32_t kRegionWidths1024[SHADEL_MAX_MIPS] = {448, 224, 112, 64, 48, 32, 32, 32, 16, 16};

struct SheetRegion {
    uint32_t x0 = 0, width = 0;
    std::unique_ptr<BlockAllocator2D> allocator;
};

// An object's rects in the sheet: levels firstMip .. mipCount-1 (finer levels only while the
// camera can need them). The fields a steady frame reads come first (kSlotHotBytes): the rest
// is read only when levels are placed or windows updated.
struct ObjectSlot {
    bool allocated = false;
    bool decoupledLastFrame = false; // its rects were in last frame's list (maps hold its marks)
    bool newThisFrame = false; // taken from the pool this frame: its instance's GPU entry is zero
    // Skipping the level-window update (updateObjectRects): its inputs are the wants of the
    // level and its neighbours and the level's current window, and the update leaves a window
    // that the same inputs keep. So when the wants read back equal the ones the last update saw
    // (wantsSettled, set by finishDecoupledFrame), the levels are the same as then (firstMip
    // unchanged for two frames) and no placement failed (windowRetry), it would keep them all.
    bool wantsSettled = false;
    bool windowRetry = false; // a window's new rect did not fit: try again next frame
    // Whether a light with sharp edges reaches the instance (material_rate.h), as of the sharp
    // lights' version (0: not yet asked).
    uint32_t sharpLightsVersion = 0;
    bool sharpLit = false;
    uint32_t firstMip = 0;
    uint32_t mipCount = 0;
    uint64_t firstMipChanged = 0; // frame number firstMip last changed (levels added/dropped)
    std::array<uint64_t, SHADEL_MAX_MIPS> levelSince{}; // frame number each level was placed
    std::array<glm::uvec4, SHADEL_MAX_MIPS> rects{};
    // Level windows: where each level's rect sits in the level (origin in level blocks; the
    // rect's z, w are its size), and the level blocks last frame's samples wanted there
    // (min x, min y, max x + 1, max y + 1; empty when min >= max), valid for the frame
    // numbered wantedFor - 1 (one frame of readback latency; 0: no feedback yet).
    std::array<glm::uvec2, SHADEL_MAX_MIPS> windowOrigin{};
    std::array<BlockId, SHADEL_MAX_MIPS> ids{};
    std::array<glm::uvec4, SHADEL_MAX_MIPS> wanted{};
    std::array<uint64_t, SHADEL_MAX_MIPS> wantedFor{};
    // A level whose window moved this frame (movedAt: the frame number) was placed anew; where
    // it was (rect, window origin), so last frame's shadels still in the new window are carried
    // over (GpuShadelObject::prevRect*).
    std::array<glm::uvec4, SHADEL_MAX_MIPS> movedFromRect{};
    std::array<glm::uvec2, SHADEL_MAX_MIPS> movedFromWindow{};
    std::array<uint64_t, SHADEL_MAX_MIPS> movedAt{};
};
constexpr size_t kSlotHotBytes = offsetof(ObjectSlot, ids);

constexpr uint32_t kNoSlot = ~0u;

// What the coarse allocation keeps of every instance: 12 bytes. The rest (ObjectSlot and the
// GpuShadelObject's CPU copy, ~0.9 KB) lives in a slot of a pool, held only while the instance
// has sheet rects or a non-zero GpuShadelObject, so the memory a frame walks follows the view,
// not the world (at 1M instances, per-instance arrays of that size spread the few hundred
// visited objects over ~0.9 GB: a cache and TLB miss per field).
struct InstanceEntry {
    uint32_t slot = kNoSlot;
    uint32_t visitedFrame = 0; // frame number + 1 when visited this frame (0: not)
    uint32_t seenFrame = 0;    // frame number + 1 when the GPU saw it last frame
};

// The part of a level a rect holds, in level blocks.
struct LevelWindow {
    glm::uvec2 origin{0}, size{0};
};

struct FrameCounters {
    gpu::GpuShadelCounters counters;
    uint32_t objectsDecoupled = 0;
    uint32_t objectsForward = 0;
    uint32_t objectsSmallForward = 0;
    uint32_t objectsSheetLimited = 0;
    uint32_t objectsRateBiased = 0; // objects whose material shades them coarser (material_rate.h)
    uint32_t objectsRateTextured = 0; // of them, textured: limited by their texels (texture_rate.h)
    float rateBiasSum = 0.0f;         // of their rate biases, over the decoupled objects
    uint64_t rectBlocks = 0;
    uint64_t wholeLevelBlocks = 0; // what the same levels would take whole (no windows)
    uint32_t windowMoves = 0;      // level rects placed again because their window changed
    float shadingBias = 0.0f;      // the bias this frame was shaded with
    uint32_t objectsReusable = 0;  // objects with any level whose shadels may be carried over
    std::array<uint32_t, SHADEL_MAX_MIPS> firstMipHistogram{};
};

} // namespace

struct DecoupledState {
    uint32_t sheetBlocks = 1024;  // 64k x 64k shadels
    uint32_t storageSize = 4096;  // shadels per side of the physical storage
    float frustumMargin = 0.1f;   // fraction of an object's radius
    float baseShadingBias = 0.0f; // --shading-bias
    float shadingBias = 0.0f;     // this frame's: base + the capacity controller's
    bool capacityControl = true;
    CapacityController controller;
    float trilinearBand = 1.0f;
    std::vector<SheetRegion> regions;
    std::vector<InstanceEntry> instances; // per instance
    // A bit per instance: it holds a slot (InstanceEntry::slot). The visit skips the instances of
    // the grid's answer that the camera leaves forward and that hold nothing (at 100k instances
    // ~9 in 10 of them) on this bit (12 KB) instead of their entries (1.2 MB, scattered reads).
    std::vector<uint64_t> holdsSlot;
    std::vector<ObjectSlot> slots;                 // the pool (InstanceEntry::slot)
    std::vector<gpu::GpuShadelObject> slotObjects; // per slot: its instance's GpuShadelObject
    // Per slot: what its instance's entry in objectBuffer holds (valid unless newThisFrame), so
    // an unchanged entry (most of them while the camera stands still) is not written again: the
    // entries are scattered over the whole world's buffer (272 MB at 1M instances), and each
    // write costs cache and TLB misses.
    std::vector<gpu::GpuShadelObject> slotObjectsUploaded;
    std::vector<uint32_t> freeSlots;
    // The coarse allocation visits only instances near the view (render/culling/instance_grid.h)
    // and those it touched last frame, so its cost follows the view, not the world's size.
    InstanceGrid grid;
    // The visit's first half (coarse_visit.h): this frame's, computed inline or taken from the
    // frontend worker, which computes the next frame's beside this frame's backend (double
    // buffered: the worker fills one while the frame reads the other). The pending one is
    // tagged with its frame number and declared after the grid it reads, so it is joined
    // (std::async's future) before the grid is destroyed.
    CoarseVisitPolicy visitPolicy;
    CoarseVisit coarseVisit, spareVisit; // spare: the last frame's, its vectors reused
    struct PendingVisit {
        std::future<CoarseVisit> visit;
        uint64_t frame = 0;
    };
    PendingVisit pendingVisit;
    FrontendVisitStats visitStats;
    std::vector<uint32_t> visit;   // this frame's instances to decide
    std::vector<uint32_t> touched; // instances with a GpuShadelObject entry or sheet rects
    std::vector<gpu::GpuShadelRect> rects;
    uint32_t rectBlockCount = 0;
    bool levelWindows = true;      // --level-windows
    uint64_t wholeLevelBlocks = 0; // this frame's levels, whole
    uint32_t windowMoves = 0;
    uint32_t capacityChunks = 0;
    uint32_t objectsDecoupled = 0, objectsForward = 0, objectsSmallForward = 0;
    uint32_t objectsSheetLimited = 0; // finer levels wanted but no sheet room: clamped
    MaterialRate materialRate;        // --material-rate (RenderSettings::materialRate) tunables
    SharpLights sharpLights;          // the lights that keep plain materials at the full rate
    uint32_t objectsRateBiased = 0;
    uint32_t objectsRateTextured = 0;
    float rateBiasSum = 0.0f;
    std::array<uint32_t, SHADEL_MAX_MIPS> firstMipHistogram{};

    BufferHandle frameInfo;    // gpu::ShadelFrame (upload)
    BufferHandle objectBuffer; // GpuShadelObject[] (upload)
    BufferHandle rectBuffer;   // GpuShadelRect[] (upload)
    BufferHandle levelWants;   // uvec4 per rect: the level blocks samples wanted (readback)
    // Two frames of occupancy and offset map (this frame's at parity, last frame's at the other),
    // so a chunk finds where its shadels were last frame.
    std::array<BufferHandle, 2> occupancy; // uint64 per block
    std::array<BufferHandle, 2> offsetMap; // uint per block
    // uvec4 per storage slot: where its chunk was seen from when shaded (ShadelFrame::chunkViews)
    std::array<BufferHandle, 2> chunkViews;
    // --visualize reuse: uint per storage slot, why its chunk was shaded or that it was carried
    // over (ShadelFrame::chunkReasons); made by the first frame that shows the view (the
    // viewer's debug view may switch to it at any frame), absent otherwise.
    BufferHandle chunkReasons;
    uint64_t frameNumber = 0; // frames prepared so far
    uint32_t parity() const { return uint32_t(frameNumber & 1); }
    bool reuse = true;
    uint32_t refreshPeriod = 16; // --reuse-refresh
    uint32_t objectsReusable = 0;
    uint32_t shadeOptional = 0; // SHADE_OPTIONAL_* of the shading pipelines
    BufferHandle allocId;       // uint per block (upload: written by the CPU allocator)
    BufferHandle counters;      // GpuShadelCounters (readback, also indirect args)
    BufferHandle markedBlocks;  // uvec4 per marked block, capacityChunks of them
    BufferHandle queue;         // GpuShadelWork[capacity]: chunks to shade
    BufferHandle copyQueue;     // GpuShadelWork[capacity]: chunks carried over from last frame
    // uint[SHADE_CLASSES + 1][capacity]: queue entries by shading class, then near change
    BufferHandle classQueues;
    BufferHandle changedVolumes;        // ChangedVolume[SHADEL_MAX_CHANGED_VOLUMES] (upload)
    std::vector<ChangedVolume> changes; // this frame's (render/shadel/reuse_invalidation.h)
    bool changesOverflow = false;       // more than the buffer holds: everything changed
    ShadeStorage storage;
    // shade: one pipeline per shading class (SHADE_QUEUE_* - 1), each over its class's list.
    // nearChange: --reuse only (shaders/shadel/near_change.comp).
    Pipeline clear, allocate, queueSetup, fillQueue, dispatchSetup, carryOver, nearChange,
        sheetView, mark, markTransparent, reconstruct;
    std::array<Pipeline, SHADE_CLASSES> shade;
    std::vector<FrameCounters> history;
};

void DecoupledStateDeleter::operator()(DecoupledState* state) const {
    delete state;
}

static BufferHandle need(BufferHandle b, const char* what) {
    if (!b) throw DeviceError(format("out of GPU memory for the decoupled path's %s", what));
    return b;
}

// --capture names of the decoupled frame (render/debug/capture.h), read after the frame: the
// layers, masks and offsets at the parity of the frame just rendered.
static void registerDecoupledCaptures(Renderer& r, DecoupledState& d) {
    Gpu& gpu = *r.gpu;
    auto done = [&d] { return uint32_t((d.frameNumber + 1) & 1); }; // frameNumber moved on
    // The chunk-linear buffers laid out as the 2-D atlas their slots tile.
    registerCapture(r.captures, "storage.radiance", "shade storage: lit radiance (EXR)",
                    CaptureKind::Hdr, [&gpu, &d, done] {
                        return readShadeLayerAtlas(gpu, d.storage, done(), SHADEL_LAYER_RADIANCE);
                    });
    registerCapture(r.captures, "storage.material",
                    "shade storage: base colour, roughness in alpha (PNG)", CaptureKind::Display,
                    [&gpu, &d, done] {
                        return readShadeLayerAtlas(gpu, d.storage, done(), SHADEL_LAYER_MATERIAL);
                    });
    registerCapture(r.captures, "occupancy", "chunks marked per sheet block, 0..64 (heat PNG)",
                    CaptureKind::Mask, [&gpu, &d, done] {
                        return readMaskGrid(gpu, d.occupancy[done()], d.sheetBlocks);
                    });
    registerCapture(r.captures, "sheet", "virtual sheet blocks by owner object and MIP (PNG)",
                    CaptureKind::Labels,
                    [&gpu, &d] { return readLabelGrid(gpu, d.allocId, d.sheetBlocks); });
}

DecoupledStatePtr createDecoupled(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    if (scene.shadelMeshes.size() != scene.meshInfo.size()) // (a points-only file has none)
        throw InputError(
            "--mode decoupled needs a baked scene (internal: uploadScene without bake)");
    DecoupledStatePtr state(new DecoupledState());
    DecoupledState& d = *state;
    const RenderSettings& rs = r.settings;
    if (rs.shadeStorageSize < 64 || rs.shadeStorageSize % 64 || rs.shadeStorageSize > 16384)
        throw InputError(
            format("--storage %u: expected a multiple of 64 in [64, 16384]", rs.shadeStorageSize));
    if (rs.sheetShadels < 65536 || rs.sheetShadels > 262144 || rs.sheetShadels % 65536)
        throw InputError(
            format("--sheet %u: expected 65536, 131072, 196608 or 262144", rs.sheetShadels));
    d.storageSize = rs.shadeStorageSize;
    d.baseShadingBias = rs.shadingBias;
    d.shadingBias = rs.shadingBias;
    d.capacityControl = rs.capacityControl;
    d.trilinearBand = std::clamp(rs.trilinearBand, 0.0f, 1.0f);
    d.sheetBlocks = rs.sheetShadels / SHADEL_BLOCK;
    uint32_t x = 0;
    for (uint32_t k = 0; k < SHADEL_MAX_MIPS; ++k) {
        SheetRegion region;
        region.x0 = x;
        region.width = std::max(1u, kRegionWidths1024[k] * d.sheetBlocks / 1024);
        region.allocator =
            std::make_unique<BlockAllocator2D>(Extent<2>{region.width, d.sheetBlocks});
        x += region.width;
        d.regions.push_back(std::move(region));
    }
    d.instances.assign(scene.instanceCount, InstanceEntry{});
    d.holdsSlot.assign((size_t(scene.instanceCount) + 63) / 64, 0);
    uint64_t blocks = uint64_t(d.sheetBlocks) * d.sheetBlocks;
    uint32_t chunksPerSide = d.storageSize / SHADEL_CHUNK;
    d.capacityChunks = chunksPerSide * chunksPerSide;

    auto upload = [&](const char* name, VkDeviceSize bytes) {
        return need(createBuffer(gpu, {name, bytes, 0, MemoryKind::Upload}), name);
    };
    auto device = [&](const char* name, VkDeviceSize bytes, VkBufferUsageFlags usage = 0) {
        return need(createBuffer(gpu, {name, bytes, usage, MemoryKind::DeviceLocal}), name);
    };
    d.frameInfo = upload("shadel.frame", sizeof(gpu::ShadelFrame));
    d.changedVolumes =
        upload("shadel.changedVolumes", SHADEL_MAX_CHANGED_VOLUMES * sizeof(ChangedVolume));
    VkDeviceSize objectBytes =
        VkDeviceSize(std::max(scene.instanceCount, 1u)) * sizeof(gpu::GpuShadelObject);
    d.objectBuffer = upload("shadel.objects", objectBytes);
    // Every object starts forward; frames rewrite only the entries they visit.
    std::memset(mapped(gpu, d.objectBuffer), 0, objectBytes);
    d.grid.build(scene.instanceInfo);
    d.visitPolicy.viewportHeight = float(r.internalHeight);
    d.visitPolicy.frustumMargin = d.frustumMargin;
    d.visitPolicy.forwardBelowPixels = rs.forwardBelowPixels;
    d.visitPolicy.blendedForward = rs.oit != OitMode::Wboit;
    d.visitPolicy.sheetAllMips = rs.sheetAllMips;
    size_t maxRects = std::max<size_t>(scene.instanceCount, 1) * SHADEL_MAX_MIPS;
    d.rectBuffer = upload("shadel.rects", maxRects * sizeof(gpu::GpuShadelRect));
    d.levelWants =
        need(createBuffer(gpu, {"shadel.levelWants", maxRects * 16, 0, MemoryKind::Readback}),
             "level wants");
    d.levelWindows = rs.levelWindows && !rs.sheetAllMips;
    d.occupancy = {device("shadel.chunkOccupancy.frame0", blocks * 8),
                   device("shadel.chunkOccupancy.frame1", blocks * 8)};
    d.offsetMap = {device("shadel.offsetMap.frame0", blocks * 4),
                   device("shadel.offsetMap.frame1", blocks * 4)};
    // Zeroed once: the clear pass only zeroes the blocks in use each frame, and memory reused
    // from an earlier renderer would otherwise show stale marks (--capture occupancy reads every
    // block).
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        for (BufferHandle b : {d.occupancy[0], d.occupancy[1], d.offsetMap[0], d.offsetMap[1]})
            vkCmdFillBuffer(cmd, vkBuffer(gpu, b), 0, VK_WHOLE_SIZE, 0);
    });
    d.allocId = upload("shadel.allocId", blocks * 4);
    std::memset(mapped(gpu, d.allocId), 0, blocks * 4);
    d.counters =
        need(createBuffer(gpu, {"shadel.counters", sizeof(gpu::GpuShadelCounters),
                                VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, MemoryKind::Readback}),
             "counters");

    // Out of GPU memory for the storage: degrade to a smaller one (reported), not fail.
    while (!createShadeStorage(gpu, d.storageSize, d.storage)) {
        if (d.storageSize <= 512)
            throw DeviceError(format("out of GPU memory for a %u^2 shade storage", d.storageSize));
        SHADEL_WARN("out of GPU memory for a %u^2 shade storage; trying %u^2", d.storageSize,
                    d.storageSize / 2);
        d.storageSize /= 2;
    }
    d.capacityChunks = (d.storageSize / SHADEL_CHUNK) * (d.storageSize / SHADEL_CHUNK);
    d.reuse = rs.reuse;
    d.refreshPeriod = std::max(rs.reuseRefreshPeriod, 1u);
    // Sized once from storage (a listed block holds >= 1 chunk), so no frame allocates.
    d.markedBlocks = device("shadel.markedBlocks", VkDeviceSize(d.capacityChunks) * 16);
    d.queue =
        device("shadel.workQueue", VkDeviceSize(d.capacityChunks) * sizeof(gpu::GpuShadelWork));
    d.copyQueue = device("shadel.carryOverQueue",
                         VkDeviceSize(d.capacityChunks) * sizeof(gpu::GpuShadelWork));
    d.classQueues = device("shadel.shadeClassQueues",
                           VkDeviceSize(d.capacityChunks) * (SHADE_CLASSES + 1) * sizeof(uint32_t));
    d.chunkViews = {device("shadel.chunkViews.frame0", VkDeviceSize(d.capacityChunks) * 16),
                    device("shadel.chunkViews.frame1", VkDeviceSize(d.capacityChunks) * 16)};

    d.clear = createComputePipeline(gpu, "shadelClear", "shadel_clear.comp.spv");
    d.allocate = createComputePipeline(gpu, "shadelAllocate", "shadel_allocate.comp.spv");
    d.queueSetup = createComputePipeline(gpu, "shadelQueueSetup", "shadel_queue_setup.comp.spv");
    d.fillQueue = createComputePipeline(gpu, "shadelFillQueue", "shadel_fill_queue.comp.spv");
    d.dispatchSetup =
        createComputePipeline(gpu, "shadelDispatchSetup", "shadel_dispatch_setup.comp.spv");
    d.carryOver = createComputePipeline(gpu, "shadelCarryOver", "shadel_carry_over.comp.spv");
    if (d.reuse)
        d.nearChange =
            createComputePipeline(gpu, "shadelNearChange", "shadel_near_change.comp.spv");
    std::vector<std::pair<uint32_t, uint32_t>> shadeConstants;
    if (r.settings.distanceFieldLighting) // render/distance_fields: far shadows + AO per shadel
        shadeConstants.push_back({DISTANCE_FIELD_LIGHTING_CONSTANT_ID, 1u});
    // What this renderer can use (render/renderer.cpp creates the decal, ray tracing and debug
    // line states from the same settings and scene).
    uint32_t optional = 0u;
    if (r.settings.rt.enabled()) optional |= SHADE_OPTIONAL_RT;
    if (r.settings.decals && !scene.decals.empty()) optional |= SHADE_OPTIONAL_DECALS;
    if (r.settings.debugLines & DEBUG_LINES_CHUNKS) optional |= SHADE_OPTIONAL_DEBUG_LINES;
    if (d.reuse) optional |= SHADE_OPTIONAL_REUSE;
    if (shadelsCullLightsPerChunk(r, scene)) optional |= SHADE_OPTIONAL_CHUNK_LIGHTS;
    shadeConstants.push_back({SHADE_OPTIONAL_CONSTANT_ID, optional});
    d.shadeOptional = optional;
    // The shading classes (SHADEL_OBJECT_* flags set per object below): plain materials with
    // every material feature compiled out, featured ones, supersampled procedurals, textured
    // ones with every feature but textures compiled out.
    const char* const classNames[SHADE_CLASSES] = {"shadelShadePlain", "shadelShadeFeatured",
                                                   "shadelShadeSupersampled",
                                                   "shadelShadeTextured"};
    std::vector<ComputePipelineDesc> classes;
    for (uint32_t c = 0; c < SHADE_CLASSES; ++c) {
        auto constants = shadeConstants;
        constants.push_back({SHADE_QUEUE_CONSTANT_ID, SHADE_QUEUE_PLAIN + c});
        if (c == SHADE_QUEUE_PLAIN - 1) constants.push_back({MATERIAL_FEATURES_CONSTANT_ID, 0u});
        if (c == SHADE_QUEUE_TEXTURED - 1)
            constants.push_back({MATERIAL_FEATURES_CONSTANT_ID, MATERIAL_FEATURE_TEXTURES});
        classes.push_back({classNames[c], "shadel_shade.comp.spv", constants});
    }
    // Compiled side by side: the four are the renderer's largest pipelines.
    std::vector<Pipeline> shade = createComputePipelines(gpu, classes);
    for (uint32_t c = 0; c < SHADE_CLASSES; ++c) d.shade[c] = shade[c];
    d.sheetView = createComputePipeline(gpu, "shadelSheetView", "shadel_sheet_view.comp.spv");
    GraphicsPipelineDesc mark;
    mark.name = "shadelMark";
    mark.vertexShader = "forward_forward.vert.spv";
    mark.fragmentShader = "shadel_mark.frag.spv";
    mark.depthFormat = VK_FORMAT_D32_SFLOAT;
    mark.depthWrite = false;
    mark.depthCompare = VK_COMPARE_OP_EQUAL;
    mark.dynamicCulling = true; // per list side (drawCameraList), as the prepass
    d.mark = createGraphicsPipeline(gpu, mark);
    GraphicsPipelineDesc markTransparent = mark;
    markTransparent.name = "shadelMarkTransparent";
    markTransparent.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL; // in front of opaque depth
    d.markTransparent = createGraphicsPipeline(gpu, markTransparent);
    GraphicsPipelineDesc recon = mark;
    recon.name = "shadelReconstruct";
    recon.fragmentShader = "shadel_reconstruct.frag.spv";
    recon.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    recon.specialization = shaderPrintSpecialization(r.settings.inspectX >= 0);
    recon.specialization.push_back({VISIBILITY_VERTICES_CONSTANT_ID, shadingVisibilityVertices(r)});
    d.reconstruct = createGraphicsPipeline(gpu, recon);
    registerDecoupledCaptures(r, d);
    return state;
}

void destroyDecoupled(Renderer& r, DecoupledStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *state;
    for (Pipeline* p :
         {&d.clear, &d.allocate, &d.queueSetup, &d.fillQueue, &d.dispatchSetup, &d.carryOver,
          &d.nearChange, &d.sheetView, &d.mark, &d.markTransparent, &d.reconstruct})
        destroy(gpu, *p);
    for (Pipeline& p : d.shade) destroy(gpu, p);
    destroyShadeStorage(gpu, d.storage);
    for (BufferHandle b :
         {d.frameInfo, d.changedVolumes, d.objectBuffer, d.rectBuffer, d.levelWants, d.occupancy[0],
          d.occupancy[1], d.offsetMap[0], d.offsetMap[1], d.allocId, d.counters, d.markedBlocks,
          d.queue, d.copyQueue, d.classQueues, d.chunkViews[0], d.chunkViews[1]})
        destroy(gpu, b);
    if (d.chunkReasons) destroy(gpu, d.chunkReasons);
    state.reset();
}

static void writeAllocId(Gpu& gpu, DecoupledState& d, const glm::uvec4& rect, uint32_t value) {
    auto* ids = static_cast<uint32_t*>(mapped(gpu, d.allocId));
    for (uint32_t y = rect.y; y < rect.y + rect.w; ++y)
        for (uint32_t x = rect.x; x < rect.x + rect.z; ++x)
            ids[size_t(y) * d.sheetBlocks + x] = value;
}

static void freeLevel(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t k) {
    if (!o.ids[k].valid()) return;
    d.regions[k].allocator->remove(o.ids[k]);
    writeAllocId(gpu, d, o.rects[k], 0);
    o.ids[k] = BlockId{};
}

static void freeObject(Gpu& gpu, DecoupledState& d, ObjectSlot& o) {
    for (uint32_t k = 0; k < o.mipCount; ++k) freeLevel(gpu, d, o, k);
    o.allocated = false;
}

static glm::uvec2 levelBlocks(const ShadelMeshInfo& mesh, uint32_t k) {
    uint32_t w = std::max(1u, mesh.mip0Size.x >> k), h = std::max(1u, mesh.mip0Size.y >> k);
    return {(w + SHADEL_BLOCK - 1) / SHADEL_BLOCK, (h + SHADEL_BLOCK - 1) / SHADEL_BLOCK};
}

// Level windows. The finest levels of a large object are mostly unread: of builtin:default's
// 7814 rect blocks at 1280x720, 796 hold a marked chunk (the rest is occluded, off screen or
// seen at a coarser MIP, which only the GPU's marks can tell). So a fine level's rect holds
// only a window of the level: the blocks last frame's samples wanted there (marked, or wanted
// but read coarser because the window did not hold them: marking.glsl wantLevel), plus a
// margin for the view's motion; a level nothing wanted holds no blocks at all (most levels of
// builtin:many's 4000 small objects). A sample outside the window reads the next coarser level
// for a frame (counted: window_fallback_pixel_fraction), never a hole; one lagging by more than
// a level (a camera cut) is shaded forward instead (window_forward_pixel_fraction, shadel.glsl
// windowFallbackTooDeep). The coarsest level and levels with no feedback yet (just placed) are
// held whole.

static LevelWindow wholeLevel(const ShadelMeshInfo& mesh, uint32_t k) {
    return {glm::uvec2(0), levelBlocks(mesh, k)};
}

static LevelWindow currentWindow(const ObjectSlot& o, uint32_t k) {
    return {o.windowOrigin[k], {o.rects[k].z, o.rects[k].w}};
}

// The window the level should hold this frame: the wanted blocks, grown on each side by one
// block and a quarter of their extent (the view's motion over a frame), within the level.
// The level blocks last frame wanted at level k or at its neighbours k - 1 and k + 1 (scaled
// to level k): a surface moving across a LOD boundary then finds the next level already
// there. {lo, hi} in level k blocks, lo >= hi when nothing was wanted.
static std::pair<glm::uvec2, glm::uvec2> wantedBlocks(const DecoupledState& d, const ObjectSlot& o,
                                                      const ShadelMeshInfo& mesh, uint32_t k) {
    glm::uvec2 lo{~0u}, hi{0u};
    auto add = [&](uint32_t level, auto toK) {
        if (level >= mesh.mipCount || o.wantedFor[level] != d.frameNumber + 1) return;
        const glm::uvec4& w = o.wanted[level];
        if (w.x >= w.z || w.y >= w.w) return;
        auto [a, b] = toK(glm::uvec2(w.x, w.y), glm::uvec2(w.z, w.w));
        lo = glm::min(lo, a);
        hi = glm::max(hi, b);
    };
    add(k, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a, b}; });
    if (k > 0)
        add(k - 1, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a / 2u, (b + 1u) / 2u}; });
    add(k + 1, [](glm::uvec2 a, glm::uvec2 b) { return std::pair{a * 2u, b * 2u}; });
    glm::uvec2 size = levelBlocks(mesh, k);
    return {glm::min(lo, size), glm::min(hi, size)};
}

static LevelWindow targetWindow(const DecoupledState& d, const ObjectSlot& o,
                                const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow whole = wholeLevel(mesh, k);
    if (!d.levelWindows || k + 1 >= mesh.mipCount || o.wantedFor[k] != d.frameNumber + 1)
        return whole;
    auto [lo, hi] = wantedBlocks(d, o, mesh, k);
    // Nothing wanted (occluded, or seen only at other levels): an empty window; samples read
    // coarser and their wants bring the level back next frame.
    if (lo.x >= hi.x || lo.y >= hi.y) return {};
    glm::uvec2 margin = 1u + (hi - lo) / 4u;
    lo -= glm::min(lo, margin);
    hi = glm::min(hi + margin, whole.size);
    return {lo, hi - lo};
}

// Hysteresis: the level keeps its window (and its place; a moved window's shadels are carried
// over where the old window held them, but the blocks it newly holds are shaded) while the window
// holds the wanted blocks with one block to spare and is at most twice the target's area; a view
// hovering at an edge does not move the rect every frame.
static bool keepWindow(const DecoupledState& d, const ObjectSlot& o, const ShadelMeshInfo& mesh,
                       uint32_t k, LevelWindow target) {
    LevelWindow now = currentWindow(o, k);
    if (now.origin == target.origin && now.size == target.size) return true;
    LevelWindow whole = wholeLevel(mesh, k);
    if (target.size == whole.size) return false; // whole again (no feedback, or windows off)
    if (target.size.x * target.size.y == 0) return false; // nothing wanted: give it back
    // A non-empty target means something was wanted: it must stay inside with a block to spare.
    auto [lo, hi] = wantedBlocks(d, o, mesh, k);
    lo -= glm::min(lo, glm::uvec2(1u));
    hi = glm::min(hi + 1u, whole.size);
    if (glm::any(glm::lessThan(lo, now.origin)) ||
        glm::any(glm::greaterThan(hi, now.origin + now.size)))
        return false;
    return uint64_t(now.size.x) * now.size.y <= 2 * uint64_t(target.size.x) * target.size.y;
}

static void setLevelRect(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object, uint32_t k,
                         const Placement<2>& placed, LevelWindow window) {
    o.ids[k] = placed.id;
    o.levelSince[k] = d.frameNumber;
    o.windowOrigin[k] = window.origin;
    o.rects[k] = {d.regions[k].x0 + placed.origin[0], placed.origin[1], window.size.x,
                  window.size.y};
    writeAllocId(gpu, d, o.rects[k], ((object + 1) << 4) | k);
}

static bool allocateLevel(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                          const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow window = targetWindow(d, o, mesh, k);
    auto placed = d.regions[k].allocator->insert(Extent<2>{window.size.x, window.size.y});
    if (!placed) return false;
    setLevelRect(gpu, d, o, object, k, *placed, window);
    return true;
}

// A level whose window changed is placed again (the new rect first, so a full sheet keeps the
// old window rather than losing the level).
static void updateLevelWindow(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                              const ShadelMeshInfo& mesh, uint32_t k) {
    LevelWindow target = targetWindow(d, o, mesh, k);
    if (keepWindow(d, o, mesh, k, target)) return;
    std::optional<Placement<2>> placed;
    if (target.size.x * target.size.y != 0) {
        placed = d.regions[k].allocator->insert(Extent<2>{target.size.x, target.size.y});
        if (!placed) {
            o.windowRetry = true;
            return;
        }
    }
    if (placed && o.ids[k].valid()) { // moved: what the old window held can be carried over
        o.movedFromRect[k] = o.rects[k];
        o.movedFromWindow[k] = o.windowOrigin[k];
        o.movedAt[k] = d.frameNumber;
    }
    freeLevel(gpu, d, o, k);
    d.windowMoves++;
    if (placed) return setLevelRect(gpu, d, o, object, k, *placed, target);
    o.levelSince[k] = d.frameNumber; // empty: no rect, no blocks
    o.windowOrigin[k] = glm::uvec2(0);
    o.rects[k] = {d.regions[k].x0, 0, 0, 0};
}

// Coarse CPU allocation (the CPU's estimate of the space an object can need): a potentially
// visible object gets rects from the finest MIP it can need this frame down to its coarsest;
// objects that leave the view give theirs back. Levels are added as the camera comes closer and
// dropped (with one level of slack, so a camera hovering at a boundary does not churn the sheet) as
// it moves away. Returns false when the object has no rects at all (drawn forward this frame).
static bool updateObjectRects(Gpu& gpu, DecoupledState& d, ObjectSlot& o, uint32_t object,
                              const ShadelMeshInfo& mesh, uint32_t wantFirst, bool wasDecoupled,
                              bool& limited) {
    limited = false;
    if (!o.allocated) {
        o.mipCount = mesh.mipCount;
        o.firstMip = mesh.mipCount;
        o.allocated = true;
        o.firstMipChanged = d.frameNumber;
    }
    uint32_t firstMip = o.firstMip;
    while (o.firstMip > wantFirst && allocateLevel(gpu, d, o, object, mesh, o.firstMip - 1))
        --o.firstMip;
    if (o.firstMip > wantFirst) limited = true; // the sheet is full: clamped to coarser levels
    while (o.firstMip + 1 < wantFirst) freeLevel(gpu, d, o, o.firstMip++);
    if (o.firstMip == o.mipCount) { // not even the coarsest level fits
        o.allocated = false;
        return false;
    }
    if (o.firstMip != firstMip) o.firstMipChanged = d.frameNumber;
    // The wants and levels are those the last update (last frame's) kept or placed: it would
    // keep every window again (most objects of a steady view).
    bool settled =
        wasDecoupled && o.wantsSettled && !o.windowRetry && o.firstMipChanged + 2 <= d.frameNumber;
    if (settled) return true;
    o.windowRetry = false;
    for (uint32_t k = o.firstMip; k < o.mipCount; ++k)
        if (o.levelSince[k] < d.frameNumber) updateLevelWindow(gpu, d, o, object, mesh, k);
    return true;
}

// How far the view of a carried-over chunk may turn before its specular visibly lags
// (GpuShadelObject::viewDriftCos holds its cosine, checked per chunk: shadel.glsl chunkViewTurned).
// Specular and Fresnel follow the view direction, and a specular lobe is about roughness^2 radians
// wide, so the direction from the chunk to the camera may turn by about that much. Only the
// specular part lags, and a dielectric reflects about F0 = 4% of the light specularly (metals all
// of it): the turn a lag of the whole lobe's width costs is scaled by that share (doubled for
// Fresnel's rise towards grazing angles), so a rough dielectric is carried over far longer than a
// polished metal. Roughness textures only lower the factor's roughness, so glossier texels than the
// factor can lag somewhat more.
// The specular share is measured against the darkest albedo channel: a saturated base colour
// lets a coloured light's specular dominate the channels it barely reflects (builtin:many's
// green trees under the pink street light: its red and blue are mostly specular, and their
// carried chunks lagged the view far enough to drop a frame to 29 dB against reuse off). Share =
// the GGX peak's specular (F0 = 4%, D = 1 / (pi alpha^2), over 4) against that channel's Lambert
// diffuse. The turn allowed, in lobe widths, is SPECULAR_SHARE_TOLERANCE / share within
// [SPECULAR_SHARE_MIN_GAIN, SPECULAR_SHARE_MAX_GAIN]: the lag a turn leaves is about share x
// turn / lobe, so the tolerance is roughly the error allowed in the darkest channel. A rough
// light-coloured dielectric (share ~8%) keeps the cap, the trees (share 0.25) 0.6 lobes.
// The tolerance, the least gain and the cap of the gain are chosen from sweeps of reuse
// fraction against the worst frame's PSNR (reuse on vs off) on builtin:default and builtin:many;
// docs/decoupled/README.md has them.
constexpr float SPECULAR_SHARE_MIN_GAIN = 0.5f;
constexpr float SPECULAR_SHARE_MAX_GAIN = 2.0f;
constexpr float SPECULAR_SHARE_TOLERANCE = 0.15f;
constexpr float SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT = 0.25f;

// Under an environment the specular reflects light from every direction, not only the lights'
// peaks: its share is then the reflected environment (Fresnel averaged over the hemisphere,
// F0 + (1 - F0) / 21, of about the light the diffuse receives) against the darkest channel's
// diffuse, whatever the roughness; the larger of the two shares sets the tolerance, and the
// gain may fall to SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT: a grazing view of a saturated material
// reflects mostly the environment, which a turn of half a lobe already shows at its rim.
static float viewDriftLimitFor(float roughness, float metallic, glm::vec3 baseColor,
                               bool environment) {
    constexpr float kPi = 3.14159265f;
    float lobeWidth = std::clamp(roughness * roughness, 0.01f, 0.4f);
    float specularPeak = 0.04f / (4.0f * kPi * lobeWidth * lobeWidth);
    float darkest = std::min({baseColor.r, baseColor.g, baseColor.b});
    float darkestDiffuse = std::max(darkest, 0.0f) * 0.96f / kPi;
    float dielectricShare = specularPeak / (specularPeak + darkestDiffuse);
    if (environment) {
        float reflected = (0.04f + 0.96f / 21.0f) / kPi;
        dielectricShare = std::max(dielectricShare, reflected / (reflected + darkestDiffuse));
    }
    float specularShare = glm::mix(dielectricShare, 1.0f, std::clamp(metallic, 0.0f, 1.0f));
    float minGain = environment ? SPECULAR_SHARE_MIN_GAIN_ENVIRONMENT : SPECULAR_SHARE_MIN_GAIN;
    float gain =
        std::clamp(SPECULAR_SHARE_TOLERANCE / specularShare, minGain, SPECULAR_SHARE_MAX_GAIN);
    return lobeWidth * gain;
}

// A slot for an instance that has none: a fresh ObjectSlot (no rects) and a zero GPU entry, as
// every instance without a slot has.
static uint32_t takeSlot(DecoupledState& d) {
    uint32_t s;
    if (d.freeSlots.empty()) {
        s = uint32_t(d.slots.size());
        d.slots.emplace_back();
        d.slotObjects.emplace_back();
        d.slotObjectsUploaded.emplace_back();
    } else {
        s = d.freeSlots.back();
        d.freeSlots.pop_back();
        d.slots[s] = ObjectSlot{};
        d.slotObjects[s] = gpu::GpuShadelObject{};
    }
    d.slots[s].newThisFrame = true;
    return s;
}

// The visited instances are scattered over per-instance arrays of the whole world (at 1M
// instances: 160 MB of GpuInstance, 12 MB of InstanceEntry, 272 MB of GpuShadelObject), so
// each visit starts with cache and TLB misses (builtin:many 1M: 37% of the coarse allocation's
// samples sat on the first GpuInstance load). Fetching a few visits ahead overlaps them.
// Two stages: an instance's entries first, then (its entry read by then) its slot.
constexpr size_t kPrefetchAhead = 8;

static void prefetchLines(const void* p, size_t bytes, int write) {
    const char* c = static_cast<const char*>(p);
    for (size_t o = 0; o < bytes; o += 64)
        write ? __builtin_prefetch(c + o, 1) : __builtin_prefetch(c + o, 0);
}

static void prefetchInstance(const DecoupledState& d, const GpuScene& scene, uint32_t i,
                             bool readsInstance) {
    __builtin_prefetch(&d.instances[i]);
    if (!readsInstance) return;
    const auto* inst = reinterpret_cast<const char*>(&scene.instanceInfo[i]);
    __builtin_prefetch(inst);                                        // model
    __builtin_prefetch(inst + offsetof(gpu::GpuInstance, worldMin)); // bounds, mesh, material
    __builtin_prefetch(inst + sizeof(gpu::GpuInstance) - 1);
}

static bool holdsSlot(const DecoupledState& d, uint32_t i) {
    return (d.holdsSlot[i >> 6] >> (i & 63)) & 1u;
}

static void setHoldsSlot(DecoupledState& d, uint32_t i, bool holds) {
    uint64_t bit = uint64_t(1) << (i & 63);
    d.holdsSlot[i >> 6] = holds ? d.holdsSlot[i >> 6] | bit : d.holdsSlot[i >> 6] & ~bit;
}

static void prefetchSlot(const DecoupledState& d, uint32_t i) {
    uint32_t s = d.instances[i].slot;
    if (s == kNoSlot) return;
    prefetchLines(&d.slots[s], kSlotHotBytes, 0);
    prefetchLines(&d.slotObjects[s], sizeof(gpu::GpuShadelObject), 1); // rewritten
}

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
static const CoarseVisit& takeCoarseVisit(Renderer& r, const GpuScene& scene,
                                          const CameraView& camera) {
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

void prepareDecoupledFrame(Renderer& r, const GpuScene& scene, const CameraView& camera,
                           gpu::FrameConstants& constants) {
    Gpu& gpu = *r.gpu;
    DecoupledState& d = *r.decoupled;
    auto planes = frustumPlanes(constants.viewProj);
    d.shadingBias = d.baseShadingBias + (d.capacityControl ? d.controller.bias : 0.0f);
    d.rects.clear();
    d.rectBlockCount = 0;
    d.wholeLevelBlocks = 0;
    d.windowMoves = 0;
    d.objectsDecoupled = d.objectsForward = d.objectsSmallForward = d.objectsSheetLimited = 0;
    d.objectsRateBiased = 0;
    d.objectsRateTextured = 0;
    d.rateBiasSum = 0.0f;
    d.firstMipHistogram.fill(0);
    d.objectsReusable = 0;
    d.changes =
        changedVolumes(r, scene, constants.sunDirection, glm::length(constants.sunColor) > 0.0f);
    d.changesOverflow = d.changes.size() > SHADEL_MAX_CHANGED_VOLUMES;
    if (r.settings.materialRate) { // (read every frame: the viewer switches it)
        const RtSettings& rt = r.settings.rt;
        bool sunSharp = rt.shadows || rt.ao || rt.gi || r.settings.sunCascades > 1;
        static const std::vector<Decal> kNoDecals;
        updateSharpLights(
            d.sharpLights, r.lightsLastFrame.empty() ? scene.lightInfo : r.lightsLastFrame,
            !r.changedLightVolumes.empty(), sunSharp, r.settings.decals ? scene.decals : kNoDecals);
    }
    if (!d.changesOverflow && !d.changes.empty())
        std::memcpy(mapped(gpu, d.changedVolumes), d.changes.data(),
                    d.changes.size() * sizeof(ChangedVolume));
    // Instances near the frustum's bounds, and last frame's (to free or clear what they held):
    // every other instance stays unwanted, with its zero entry and no rects.
    // With occlusion culling the GPU's visible set of last frame is the set to allocate for
    // (the CPU estimator and the GPU agree on what is seen); an instance that appears
    // is drawn forward for one frame. Otherwise the grid's answer for the frustum (the visit's
    // first half, coarse_visit.h: taken from the frontend worker or computed here), whose
    // instances come with their view of the camera already computed.
    d.visit.clear();
    const std::vector<uint32_t>* seen = visibleLastFrame(r);
    const uint32_t frameMark = uint32_t(d.frameNumber + 1); // visitedFrame, seenFrame
    const CoarseVisit* grid = nullptr;
    if (seen) {
        d.visitStats.readbackVisits++;
        d.visit.insert(d.visit.end(), seen->begin(), seen->end());
        for (uint32_t i : *seen) d.instances[i].seenFrame = frameMark;
    } else {
        grid = &takeCoarseVisit(r, scene, camera);
        d.visit.insert(d.visit.end(), grid->instances.begin(), grid->instances.end());
    }
    const size_t viewed = grid ? grid->views.size() : 0; // visit entries with their view
    d.visit.insert(d.visit.end(), d.touched.begin(), d.touched.end());
    d.touched.clear();
    // In the grid's answer, whether the view wants the instance decoupled.
    auto viewWants = [&](size_t v) { return grid->views[v].inFrustum && !grid->views[v].small; };
    for (size_t v = 0; v < d.visit.size(); ++v) {
        if (v + kPrefetchAhead < d.visit.size()) {
            size_t ahead = v + kPrefetchAhead;
            // Past the grid's answer (or with occlusion) the loop reads the instance itself;
            // in it, only where the view wants it decoupled (and its entry where it holds a slot).
            bool readsInstance = ahead >= viewed || viewWants(ahead);
            if (readsInstance || holdsSlot(d, d.visit[ahead]))
                prefetchInstance(d, scene, d.visit[ahead], readsInstance);
        }
        if (v + kPrefetchAhead / 2 < d.visit.size())
            prefetchSlot(d, d.visit[v + kPrefetchAhead / 2]);
        uint32_t i = d.visit[v];
        // Forward this frame and holding nothing, as before: nothing to decide or undo (the grid
        // lists an instance once, and d.touched only instances that hold a slot).
        if (v < viewed && !viewWants(v) && !holdsSlot(d, i)) {
            if (grid->views[v].inFrustum) d.objectsSmallForward++, d.objectsForward++;
            continue;
        }
        InstanceEntry& entry = d.instances[i];
        if (entry.visitedFrame == frameMark) continue;
        entry.visitedFrame = frameMark;
        // Hidden by occlusion last frame: its rects go back (it returns forward for a frame).
        bool hidden = seen && entry.seenFrame != frameMark;
        CoarseInstanceView view;
        if (v < viewed)
            view = grid->views[v];
        else if (!hidden)
            view = viewInstance(d.visitPolicy, scene, camera, planes, i);
        // (The visibility buffer sees only the nearest surface: with it, transparent surfaces
        // are marked by the raster pass below.)
        bool wanted = !hidden && view.inFrustum;
        bool small = wanted && view.small;
        if (small) d.objectsSmallForward++, d.objectsForward++;
        // Drawn forward: without a slot it holds nothing and its GPU entry is zero already (the
        // common case of the many small instances the GPU sees every frame: no slot churn).
        if ((!wanted || small) && entry.slot == kNoSlot) continue;
        if (entry.slot == kNoSlot) {
            entry.slot = takeSlot(d);
            setHoldsSlot(d, i, true);
        }
        ObjectSlot& o = d.slots[entry.slot];
        bool wasDecoupled = o.decoupledLastFrame;
        o.decoupledLastFrame = false;
        gpu::GpuShadelObject& g = d.slotObjects[entry.slot];
        g = gpu::GpuShadelObject{};
        if (!wanted || small) {
            if (o.allocated) freeObject(gpu, d, o);
            continue;
        }
        const gpu::GpuInstance& inst = scene.instanceInfo[i];
        const ShadelMeshInfo& mesh = scene.shadelMeshes[inst.mesh];
        // The material as this frame shades it (edited or as loaded: render/scene_edits).
        bool known = inst.material < scene.materialInfo.size();
        const gpu::GpuMaterial* material =
            known ? &currentMaterial(r, scene, inst.material) : nullptr;
        float roughness = known ? material->roughnessFactor : 1.0f;
        uint32_t features = known ? materialFeatures(*material) : MATERIAL_FEATURES_ALL;
        // Animated playback posed it anew (moved or deformed): its shadels are shaded again.
        bool reposed = i < r.reposedInstances.size() && r.reposedInstances[i] != 0;
        // Its shading rate (material_rate.h): the GPU adds it to every sample's LOD up to the
        // rate's bound (materialRateLod), so the finest level the object can need moves with it.
        // A textured material: the bias from the lowest roughness its texture gives, limited
        // per sample to where the view magnifies its textures (texture_rate.h). An edit that
        // changed its textures leaves their content unknown: the full rate.
        float rateRoughness = roughness;
        float texLod = SHADEL_TEXTURE_LOD_NONE;
        if ((features & MATERIAL_FEATURE_TEXTURES) != 0u) {
            const MaterialTexels* texels = inst.material < scene.materialTexels.size()
                                               ? &scene.materialTexels[inst.material]
                                               : nullptr;
            bool asLoaded = known && texels && texels->known &&
                            (material == &scene.materialInfo[inst.material] || // not edited
                             sameTextures(*material, scene.materialInfo[inst.material]));
            rateRoughness = asLoaded ? roughness * texels->roughnessScale : 0.0f;
            // Each UV set's textures against that set's mapping: the denser one sets the level.
            texLod = asLoaded ? std::min(textureLod(mesh.uvPerShadelLog2, texels->texelsPerUvLog2,
                                                    d.materialRate.shadelsPerTexel),
                                         textureLod(mesh.uv1PerShadelLog2, texels->texelsPerUv1Log2,
                                                    d.materialRate.shadelsPerTexel))
                              : -SHADEL_TEXTURE_LOD_NONE;
        }
        float rateBias = r.settings.materialRate
                             ? materialRateBias(d.materialRate, features, rateRoughness)
                             : 0.0f;
        if (rateBias > 0.0f) {
            if (o.sharpLightsVersion != d.sharpLights.version || reposed) {
                o.sharpLit = sharpLightReaches(d.sharpLights, inst.worldMin, inst.worldMax);
                o.sharpLightsVersion = d.sharpLights.version;
            }
            if (o.sharpLit) rateBias = 0.0f;
        }
        uint32_t wantFirst =
            finestMipFromLod(materialRateLod(view.lodBeforeBias + d.shadingBias, rateBias, texLod),
                             0.0f, mesh.mipCount);
        bool limited = false;
        // No room in the sheet: drawn forward this frame, retried next frame.
        if (!updateObjectRects(gpu, d, o, i, mesh, wantFirst, wasDecoupled, limited)) {
            d.objectsForward++;
            continue;
        }
        d.objectsSheetLimited += limited;
        d.objectsDecoupled++;
        o.decoupledLastFrame = true;
        // Preserved layers: a level's shadels may be carried over when last frame marked and
        // stored them at the same place (the object was decoupled and the level's rect is
        // older than this frame) and nothing the shading reads has changed. Instances and
        // materials are static unless animated playback reposes them; lights that moved
        // invalidate what they reach.
        // View-dependent terms (specular) drift with the camera: the shading pass reshades
        // every chunk at least once per refresh period.
        // A change that reaches the object (a light that changed, a caster that moved, its
        // shadow: reuse_invalidation.h): its chunks check their own shadels against the changed
        // regions (shade.comp); an unbounded one (or too many) changes everything.
        ChangeReach reach = d.changesOverflow
                                ? ChangeReach::Everything
                                : changeReach(d.changes, inst.worldMin, inst.worldMax);
        if (reach == ChangeReach::Bounded) g.flags |= SHADEL_OBJECT_NEAR_CHANGE;
        // Its material changed (texture streaming changed what a texture of it holds, or it
        // was edited): reshade it.
        bool restreamed =
            inst.material < r.changedMaterials.size() && r.changedMaterials[inst.material] != 0;
        bool inputsUnchanged =
            d.reuse && wasDecoupled && reach != ChangeReach::Everything && !restreamed && !reposed;
        for (uint32_t k = o.firstMip; k < mesh.mipCount && inputsUnchanged; ++k)
            if (o.levelSince[k] < d.frameNumber || o.movedAt[k] == d.frameNumber)
                g.reuseLevels |= 1u << k;
        float metallic = known ? material->metallicFactor : 1.0f;
        glm::vec3 baseColor = known ? glm::vec3(material->baseColorFactor) : glm::vec3(0.0f);
        g.viewDriftCos = std::cos(viewDriftLimitFor(roughness, metallic, baseColor,
                                                    r.environment.kind != EnvironmentKind::None));
        g.rateBias = rateBias;
        g.textureLod = rateBias > 0.0f ? texLod : SHADEL_TEXTURE_LOD_NONE;
        d.objectsRateTextured += rateBias > 0.0f && texLod < SHADEL_TEXTURE_LOD_NONE;
        d.objectsRateBiased += rateBias > 0.0f;
        d.rateBiasSum += rateBias;
        d.objectsReusable += g.reuseLevels != 0;
        d.firstMipHistogram[o.firstMip]++;
        g.mip0Size = mesh.mip0Size;
        g.mipCount = mesh.mipCount;
        g.firstMip = o.firstMip;
        g.flags |= SHADEL_OBJECT_DECOUPLED;
        // Its shading class (the pipeline that shades its chunks, shaders/shadel/shade.comp).
        if (features != 0u) g.flags |= SHADEL_OBJECT_FEATURED_MATERIAL;
        if (features == MATERIAL_FEATURE_TEXTURES) g.flags |= SHADEL_OBJECT_TEXTURED_MATERIAL;
        // Only point-function procedurals are supersampled (shaders/shadel/prefilter.glsl).
        if ((features & MATERIAL_FEATURE_PROCEDURAL) && r.settings.materialSamples >= 4)
            g.flags |= SHADEL_OBJECT_SUPERSAMPLED; // 2 x 2 samples at least
        g.firstRect = uint32_t(d.rects.size());
        for (uint32_t k = o.firstMip; k < mesh.mipCount; ++k) {
            g.idMapOffset[k] = mesh.idMapOffset[k];
            g.rect[k] = o.rects[k];
            g.window[k] = o.windowOrigin[k].x | (o.windowOrigin[k].y << 16);
            bool moved = o.movedAt[k] == d.frameNumber;
            glm::uvec4 prevRect = moved ? o.movedFromRect[k] : o.rects[k];
            glm::uvec2 prevWindow = moved ? o.movedFromWindow[k] : o.windowOrigin[k];
            g.prevRectOrigin[k] = prevRect.x | (prevRect.y << 16);
            g.prevRectSize[k] = prevRect.z | (prevRect.w << 16);
            g.prevWindow[k] = prevWindow.x | (prevWindow.y << 16);
            d.rects.push_back({o.rects[k], i, k, d.rectBlockCount, 0});
            d.rectBlockCount += o.rects[k].z * o.rects[k].w;
            glm::uvec2 whole = levelBlocks(mesh, k);
            d.wholeLevelBlocks += uint64_t(whole.x) * whole.y;
        }
    }
    auto* objects = static_cast<gpu::GpuShadelObject*>(mapped(gpu, d.objectBuffer));
    // Whether the slot's instance entry must be written: a new slot's entry is zero, another's
    // holds what was uploaded last.
    auto entryChanged = [&d](uint32_t s) {
        return d.slots[s].newThisFrame || std::memcmp(&d.slotObjectsUploaded[s], &d.slotObjects[s],
                                                      sizeof(gpu::GpuShadelObject)) != 0;
    };
    for (size_t v = 0; v < d.visit.size(); ++v) {
        // Two stages ahead: the slot's uploaded copy, then (compared by then) the GPU entry of
        // an instance that writes it. An instance without a slot writes nothing.
        if (v + 2 * kPrefetchAhead < d.visit.size()) {
            uint32_t j = d.visit[v + 2 * kPrefetchAhead];
            uint32_t s = holdsSlot(d, j) ? d.instances[j].slot : kNoSlot;
            if (s != kNoSlot)
                prefetchLines(&d.slotObjectsUploaded[s], sizeof(gpu::GpuShadelObject), 0);
        }
        if (v + kPrefetchAhead < d.visit.size()) {
            uint32_t j = d.visit[v + kPrefetchAhead];
            uint32_t s = holdsSlot(d, j) ? d.instances[j].slot : kNoSlot;
            if (s != kNoSlot && entryChanged(s))
                prefetchLines(&objects[j], sizeof(gpu::GpuShadelObject), 1);
        }
        uint32_t i = d.visit[v];
        // Holding no slot: forward, its entry zero (a visitedFrame left set by the loop above
        // is this frame's number, which no later frame matches).
        if (!holdsSlot(d, i)) continue;
        InstanceEntry& entry = d.instances[i];
        if (entry.visitedFrame != frameMark) continue;
        entry.visitedFrame = 0;              // once per instance (visit may list it twice)
        if (entry.slot == kNoSlot) continue; // forward, holding nothing: its entry stays zero
        ObjectSlot& o = d.slots[entry.slot];
        const gpu::GpuShadelObject& g = d.slotObjects[entry.slot];
        bool touched = g.flags != 0 || o.allocated;
        if (touched || !o.newThisFrame) { // else its entry is zero already
            if (entryChanged(entry.slot)) {
                objects[i] = g;
                d.slotObjectsUploaded[entry.slot] = g;
            }
        }
        o.newThisFrame = false;
        if (touched) {
            d.touched.push_back(i);
        } else { // nothing held: the slot goes back to the pool
            d.freeSlots.push_back(entry.slot);
            entry.slot = kNoSlot;
            setHoldsSlot(d, i, false);
        }
    }
    std::memcpy(mapped(gpu, d.rectBuffer), d.rects.data(),
                d.rects.size() * sizeof(gpu::GpuShadelRect));

    gpu::ShadelFrame s{};
    s.objects = address(gpu, d.objectBuffer);
    uint32_t now = d.parity(), prev = now ^ 1u;
    s.occupancy = address(gpu, d.occupancy[now]);
    s.offsetMap = address(gpu, d.offsetMap[now]);
    s.prevOccupancy = address(gpu, d.occupancy[prev]);
    s.prevOffsetMap = address(gpu, d.offsetMap[prev]);
    s.chunkViews = address(gpu, d.chunkViews[now]);
    s.prevChunkViews = address(gpu, d.chunkViews[prev]);
    bool showReuse = r.settings.visualize == Visualize::Reuse;
    if (showReuse && !d.chunkReasons)
        d.chunkReasons =
            need(createBuffer(gpu, {"shadel.chunkReasons", VkDeviceSize(d.capacityChunks) * 4, 0,
                                    MemoryKind::DeviceLocal}),
                 "shadel.chunkReasons");
    s.chunkReasons = showReuse ? address(gpu, d.chunkReasons) : 0u;
    s.allocId = address(gpu, d.allocId);
    s.counters = address(gpu, d.counters);
    s.rects = address(gpu, d.rectBuffer);
    s.markedBlocks = address(gpu, d.markedBlocks);
    s.queue = address(gpu, d.queue);
    s.copyQueue = address(gpu, d.copyQueue);
    s.classQueues = address(gpu, d.classQueues);
    s.idMaps = address(gpu, scene.idMaps);
    s.shadelUvs = address(gpu, scene.shadelUvs);
    s.sheetBlocks = d.sheetBlocks;
    s.rectCount = uint32_t(d.rects.size());
    s.rectBlockCount = d.rectBlockCount;
    for (uint32_t l = 0; l < SHADEL_LAYERS; ++l) {
        s.layers[l] = address(gpu, d.storage.frames[now][l]);
        s.prevLayers[l] = address(gpu, d.storage.frames[prev][l]);
    }
    s.changedVolumes = address(gpu, d.changedVolumes);
    s.levelWants = address(gpu, d.levelWants);
    s.changedVolumeCount = d.changesOverflow ? 0u : uint32_t(d.changes.size());
    s.frameNumber = uint32_t(d.frameNumber);
    s.reuse = d.reuse ? 1u : 0u;
    s.refreshPeriod = d.refreshPeriod;
    s.capacityChunks = d.capacityChunks;
    s.markedCapacity = d.capacityChunks;
    s.allocationCounters = std::clamp(r.settings.allocationCounters, 1u, SHADEL_COUNTERS);
    s.shadingBias = d.shadingBias;
    s.trilinearBand = d.trilinearBand;
    s.materialSamples = r.settings.materialSamples;
    for (uint32_t k = 0; k < SHADEL_MAX_MIPS; ++k) s.regionStart[k] = d.regions[k].x0;
    std::memcpy(mapped(gpu, d.frameInfo), &s, sizeof(s));
    constants.shadel = address(gpu, d.frameInfo);
    constants.shadingBias = d.shadingBias;
}

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
        dispatchFrame(gpu, cmd, d.queueSetup, frame, 1);
        computeToCompute(cmd);
        dispatchCounted(gpu, cmd, d, d.fillQueue, frame,
                        offsetof(gpu::GpuShadelCounters, fillDispatch));
        computeToCompute(cmd);
        dispatchFrame(gpu, cmd, d.dispatchSetup, frame, 1);
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
            dispatchCounted(gpu, cmd, d, d.nearChange, frame,
                            offsetof(gpu::GpuShadelCounters, nearChangeDispatch));
            computeToCompute(cmd);
            dispatchFrame(gpu, cmd, d.dispatchSetup, frame, 1);
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

bool drawnDecoupled(const Renderer& r, uint32_t instance) {
    const DecoupledState* d = r.decoupled.get();
    if (!d || instance >= d->instances.size()) return false;
    uint32_t slot = d->instances[instance].slot;
    return slot != kNoSlot && (d->slotObjects[slot].flags & SHADEL_OBJECT_DECOUPLED) != 0u;
}

void finishDecoupledFrame(Renderer& r) {
    DecoupledState& d = *r.decoupled;
    FrameCounters f;
    std::memcpy(&f.counters, mapped(*r.gpu, d.counters), sizeof(f.counters));
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
    // The seed's measure (~1.5 bits per shadel): the 64-bit occupancy mask + 32-bit offset of
    // every block in use, over the shadels its marked chunks hold.
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
