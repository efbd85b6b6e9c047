#pragma once
// The decoupled path's state, shared by its parts: creation (decoupled_create.cpp), the sheet's
// level rects (shadel_sheet.h), the grid visit (decoupled_visit.cpp), the CPU frame
// (decoupled_prepare.cpp), recording (decoupled_record.cpp), readback and statistics
// (decoupled_stats.cpp). The renderer's interface is decoupled.h.
#include <array>
#include <cstddef>
#include <future>
#include <memory>
#include <vector>

#include "core/block_allocator.h"
#include "render/culling/instance_grid.h"
#include "render/materials/material_programs.h"
#include "render/renderer.h"
#include "render/shadel/capacity_control.h"
#include "render/shadel/coarse_visit.h"
#include "render/shadel/decoupled.h"
#include "render/shadel/material_rate.h"
#include "render/shadel/reuse_invalidation.h"
#include "render/shadel/shade_storage.h"

namespace shadel {

// Shaders address objects in place with this stride (ShadelObjectRef in bindless.glsl).
static_assert(sizeof(gpu::GpuShadelObject) == GPU_SHADEL_OBJECT_BYTES);

// One MIP level's column of blocks in the virtual sheet (decoupled_create.cpp sizes them).
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
    // The material programs (render/materials) and their chunk lists; none loaded: an empty set.
    MaterialProgramSetPtr programs;
    BufferHandle allocId;      // uint per block (upload: written by the CPU allocator)
    BufferHandle counters;     // GpuShadelCounters (readback, also indirect args)
    BufferHandle markedBlocks; // uvec4 per marked block, capacityChunks of them
    BufferHandle queue;        // GpuShadelWork[capacity]: chunks to shade
    BufferHandle copyQueue;    // GpuShadelWork[capacity]: chunks carried over from last frame
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

// Throws DeviceError naming `what` when the buffer could not be created.
BufferHandle need(BufferHandle b, const char* what);

// This frame's grid visit (decoupled_visit.cpp).
const CoarseVisit& takeCoarseVisit(Renderer& r, const GpuScene& scene, const CameraView& camera);

} // namespace shadel
