// The decoupled path's state: its sheet, buffers and pipelines, created once per renderer.
#include <algorithm>
#include <cstring>

#include "core/error.h"
#include "core/log.h"
#include "render/debug/inspect.h"
#include "render/forward/forward_passes.h"
#include "render/oit/oit.h"
#include "render/shadel/decoupled_state.h"
#include "render/shadel/visibility.h"

namespace shadel {

namespace {

// The virtual sheet is split into one column of blocks per MIP level; finer levels need more
// room (an object's MIP k rect is a quarter of its MIP k-1 rect, but never below one block).
constexpr uint32_t kRegionWidths1024[SHADEL_MAX_MIPS] = {448, 224, 112, 64, 48, 32, 32, 32, 16, 16};

void checkDecoupledSettings(const RenderSettings& rs) {
    if (rs.shadeStorageSize < 64 || rs.shadeStorageSize % 64 || rs.shadeStorageSize > 16384)
        throw InputError(
            format("--storage %u: expected a multiple of 64 in [64, 16384]", rs.shadeStorageSize));
    if (rs.sheetShadels < 65536 || rs.sheetShadels > 262144 || rs.sheetShadels % 65536)
        throw InputError(
            format("--sheet %u: expected 65536, 131072, 196608 or 262144", rs.sheetShadels));
}

// The settings the frames read, the sheet's level columns and the per-instance entries.
void setUpSheet(const RenderSettings& rs, const GpuScene& scene, DecoupledState& d) {
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
    uint32_t chunksPerSide = d.storageSize / SHADEL_CHUNK;
    d.capacityChunks = chunksPerSide * chunksPerSide;
    d.levelWindows = rs.levelWindows && !rs.sheetAllMips;
}

// The coarse allocation's instance grid and the policy of its visit (coarse_visit.h).
void setUpCoarseVisit(const Renderer& r, const GpuScene& scene, DecoupledState& d) {
    const RenderSettings& rs = r.settings;
    d.grid.build(scene.instanceInfo);
    d.visitPolicy.viewportHeight = float(r.internalHeight);
    d.visitPolicy.frustumMargin = d.frustumMargin;
    d.visitPolicy.forwardBelowPixels = rs.forwardBelowPixels;
    d.visitPolicy.blendedForward = rs.oit != OitMode::Wboit;
    d.visitPolicy.sheetAllMips = rs.sheetAllMips;
}

BufferHandle uploadBuffer(Gpu& gpu, const char* name, VkDeviceSize bytes) {
    return need(createBuffer(gpu, {name, bytes, 0, MemoryKind::Upload}), name);
}

BufferHandle deviceBuffer(Gpu& gpu, const char* name, VkDeviceSize bytes,
                          VkBufferUsageFlags usage = 0) {
    return need(createBuffer(gpu, {name, bytes, usage, MemoryKind::DeviceLocal}), name);
}

// The buffers the CPU writes every frame (frame info, changed volumes, objects, rects, block
// owners), the level wants it reads back, and the sheet's occupancy masks and offset maps.
void createSheetBuffers(Gpu& gpu, const GpuScene& scene, DecoupledState& d) {
    uint64_t blocks = uint64_t(d.sheetBlocks) * d.sheetBlocks;
    d.frameInfo = uploadBuffer(gpu, "shadel.frame", sizeof(gpu::ShadelFrame));
    d.changedVolumes = uploadBuffer(gpu, "shadel.changedVolumes",
                                    SHADEL_MAX_CHANGED_VOLUMES * sizeof(ChangedVolume));
    VkDeviceSize objectBytes =
        VkDeviceSize(std::max(scene.instanceCount, 1u)) * sizeof(gpu::GpuShadelObject);
    d.objectBuffer = uploadBuffer(gpu, "shadel.objects", objectBytes);
    // Every object starts forward; frames rewrite only the entries they visit.
    std::memset(mapped(gpu, d.objectBuffer), 0, objectBytes);
    size_t maxRects = std::max<size_t>(scene.instanceCount, 1) * SHADEL_MAX_MIPS;
    d.rectBuffer = uploadBuffer(gpu, "shadel.rects", maxRects * sizeof(gpu::GpuShadelRect));
    d.levelWants =
        need(createBuffer(gpu, {"shadel.levelWants", maxRects * 16, 0, MemoryKind::Readback}),
             "level wants");
    d.occupancy = {deviceBuffer(gpu, "shadel.chunkOccupancy.frame0", blocks * 8),
                   deviceBuffer(gpu, "shadel.chunkOccupancy.frame1", blocks * 8)};
    d.offsetMap = {deviceBuffer(gpu, "shadel.offsetMap.frame0", blocks * 4),
                   deviceBuffer(gpu, "shadel.offsetMap.frame1", blocks * 4)};
    // Zeroed once: the clear pass only zeroes the blocks in use each frame, and memory reused
    // from an earlier renderer would otherwise show stale marks (--capture occupancy reads every
    // block).
    immediateSubmit(gpu, [&](VkCommandBuffer cmd) {
        for (BufferHandle b : {d.occupancy[0], d.occupancy[1], d.offsetMap[0], d.offsetMap[1]})
            vkCmdFillBuffer(cmd, vkBuffer(gpu, b), 0, VK_WHOLE_SIZE, 0);
    });
    d.allocId = uploadBuffer(gpu, "shadel.allocId", blocks * 4);
    std::memset(mapped(gpu, d.allocId), 0, blocks * 4);
    d.counters =
        need(createBuffer(gpu, {"shadel.counters", sizeof(gpu::GpuShadelCounters),
                                VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, MemoryKind::Readback}),
             "counters");
}

// The shade storage and the per-chunk buffers sized from it.
void createStorage(Gpu& gpu, const RenderSettings& rs, DecoupledState& d) {
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
    d.markedBlocks = deviceBuffer(gpu, "shadel.markedBlocks", VkDeviceSize(d.capacityChunks) * 16);
    d.queue = deviceBuffer(gpu, "shadel.workQueue",
                           VkDeviceSize(d.capacityChunks) * sizeof(gpu::GpuShadelWork));
    d.copyQueue = deviceBuffer(gpu, "shadel.carryOverQueue",
                               VkDeviceSize(d.capacityChunks) * sizeof(gpu::GpuShadelWork));
    d.classQueues =
        deviceBuffer(gpu, "shadel.shadeClassQueues",
                     VkDeviceSize(d.capacityChunks) * (SHADE_CLASSES + 1) * sizeof(uint32_t));
    d.chunkViews = {
        deviceBuffer(gpu, "shadel.chunkViews.frame0", VkDeviceSize(d.capacityChunks) * 16),
        deviceBuffer(gpu, "shadel.chunkViews.frame1", VkDeviceSize(d.capacityChunks) * 16)};
}

// The SHADE_OPTIONAL_* parts this renderer can use (render/renderer.cpp creates the decal, ray
// tracing and debug line states from the same settings and scene).
uint32_t shadeOptionalParts(const Renderer& r, const GpuScene& scene, const DecoupledState& d) {
    uint32_t optional = 0u;
    if (r.settings.rt.enabled()) optional |= SHADE_OPTIONAL_RT;
    if (r.settings.decals && !scene.decals.empty()) optional |= SHADE_OPTIONAL_DECALS;
    if (r.settings.debugLines & DEBUG_LINES_CHUNKS) optional |= SHADE_OPTIONAL_DEBUG_LINES;
    if (d.reuse) optional |= SHADE_OPTIONAL_REUSE;
    if (shadelsCullLightsPerChunk(r, scene)) optional |= SHADE_OPTIONAL_CHUNK_LIGHTS;
    return optional;
}

// The compute passes: clearing, allocation, queues, carry-over, one shading pipeline per shading
// class, the sheet view.
void createComputePipelines(const Renderer& r, const GpuScene& scene, DecoupledState& d) {
    Gpu& gpu = *r.gpu;
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
    uint32_t optional = shadeOptionalParts(r, scene, d);
    shadeConstants.push_back({SHADE_OPTIONAL_CONSTANT_ID, optional});
    d.shadeOptional = optional;
    // The shading classes (SHADEL_OBJECT_* flags set per object by prepareDecoupledFrame): plain
    // materials with every material feature compiled out, featured ones, supersampled
    // procedurals, textured ones with every feature but textures compiled out.
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
}

// The raster passes: marking (opaque, and transparent layers) and reconstruction.
void createRasterPipelines(const Renderer& r, DecoupledState& d) {
    Gpu& gpu = *r.gpu;
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
}

// --capture names of the decoupled frame (render/debug/capture.h), read after the frame: the
// layers, masks and offsets at the parity of the frame just rendered.
void registerDecoupledCaptures(Renderer& r, DecoupledState& d) {
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

} // namespace

void DecoupledStateDeleter::operator()(DecoupledState* state) const {
    delete state;
}

BufferHandle need(BufferHandle b, const char* what) {
    if (!b) throw DeviceError(format("out of GPU memory for the decoupled path's %s", what));
    return b;
}

DecoupledStatePtr createDecoupled(Renderer& r, const GpuScene& scene) {
    if (scene.shadelMeshes.size() != scene.meshInfo.size()) // (a points-only file has none)
        throw InputError(
            "--mode decoupled needs a baked scene (internal: uploadScene without bake)");
    checkDecoupledSettings(r.settings);
    DecoupledStatePtr state(new DecoupledState());
    DecoupledState& d = *state;
    setUpSheet(r.settings, scene, d);
    setUpCoarseVisit(r, scene, d);
    // Material programs first: a bad program file or stage ends the run before anything else
    // is created.
    d.programs = createMaterialPrograms(*r.gpu, scene, d.capacityChunks);
    createSheetBuffers(*r.gpu, scene, d);
    createStorage(*r.gpu, r.settings, d);
    createComputePipelines(r, scene, d);
    createRasterPipelines(r, d);
    registerDecoupledCaptures(r, d);
    return state;
}

uint32_t pollMaterialPrograms(Renderer& r, std::vector<std::string>& errors) {
    if (!r.decoupled) return 0;
    // Their materials reshade as edited ones do (render/scene_edits.h).
    return pollMaterialPrograms(*r.gpu, r.decoupled->programs.get(), errors,
                                r.edits.materialsChanged);
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
    destroyMaterialPrograms(gpu, d.programs);
    destroyShadeStorage(gpu, d.storage);
    for (BufferHandle b :
         {d.frameInfo, d.changedVolumes, d.objectBuffer, d.rectBuffer, d.levelWants, d.occupancy[0],
          d.occupancy[1], d.offsetMap[0], d.offsetMap[1], d.allocId, d.counters, d.markedBlocks,
          d.queue, d.copyQueue, d.classQueues, d.chunkViews[0], d.chunkViews[1]})
        destroy(gpu, b);
    if (d.chunkReasons) destroy(gpu, d.chunkReasons);
    state.reset();
}

} // namespace shadel
