#include "render/culling/culling.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/log.h"
#include "render/camera.h"
#include "render/forward/forward_passes.h"
#include "render/lighting/spot_shadows.h"
#include "render/lighting/sun_cascades.h"
#include "render/renderer.h"

namespace shadel {

struct CullingState {
    BufferHandle frame;      // host-visible gpu::CullingFrame
    BufferHandle stats;      // gpu::GpuCullStats, read back
    BufferHandle visibility; // uint per instance (camera, last frame)
    // Occlusion only.
    BufferHandle pyramid;     // float, every level packed
    BufferHandle phase2Draws; // DrawIndexedCommand[DRAW_CAMERA_SLOTS * maxDraws]
    BufferHandle phase2Counts;
    BufferHandle visibleList;               // uint[1 + instances]: count, then ids (read back)
    std::vector<uint32_t> visibleLastFrame; // in instance order
    std::vector<uint64_t> visibleBits;      // (finishCullingFrame's sort)
    bool haveVisible = false;
    std::vector<glm::uvec2> levelSize;
    std::vector<uint32_t> levelOffset;
    Pipeline hizBuild;
    gpu::GpuCullStats last{}; // the last finished frame's counts
    uint32_t instances = 0;
    // instance_cull.comp dispatches this / last frame (counted while recording, which may run on
    // several threads at once: rhi/frame.h)
    std::atomic<uint32_t> dispatches{0};
    uint32_t lastDispatches = 0;
    // --shadow-culling per-view: one list per cascade and shadow-casting spot.
    BufferHandle shadowViews;      // gpu::GpuShadowCullView[lists] (upload)
    BufferHandle shadowViewDraws;  // DrawIndexedCommand[lists * maxDraws]
    BufferHandle shadowViewCounts; // uint[lists]
    uint32_t cascades = 0, spots = 0;
    // The list of view CULL_VIEW_CASCADE0 + i (i < cascades) and CULL_VIEW_SPOT0 + i, none
    // (~0u) with whole-scene culling.
    uint32_t listOf(uint32_t view) const {
        if (!shadowViewDraws) return ~0u;
        if (view >= CULL_VIEW_SPOT0)
            return view - CULL_VIEW_SPOT0 < spots ? cascades + view - CULL_VIEW_SPOT0 : ~0u;
        return view - CULL_VIEW_CASCADE0 < cascades ? view - CULL_VIEW_CASCADE0 : ~0u;
    }
};

void CullingStateDeleter::operator()(CullingState* state) const {
    delete state;
}

namespace {
struct HizPush {
    uint64_t pyramid;
    uint32_t srcOffset, dstOffset;
    glm::uvec2 srcSize, dstSize;
    uint32_t depthSlot, fromDepth;
};
} // namespace

CullingStatePtr createCulling(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    CullingStatePtr c(new CullingState);
    c->instances = scene.instanceCount;
    VkDeviceSize perInstance = VkDeviceSize(std::max(scene.instanceCount, 1u)) * 4;
    c->frame =
        createBuffer(gpu, {"culling.frame", sizeof(gpu::CullingFrame), 0, MemoryKind::Upload});
    c->stats =
        createBuffer(gpu, {"culling.stats", sizeof(gpu::GpuCullStats), 0, MemoryKind::Readback});
    c->visibility = createBuffer(gpu, {"culling.visibleLastFrame", perInstance});
    bool ok = c->frame && c->stats && c->visibility;
    c->cascades = sunCascadeCount(r);
    c->spots = spotShadowCount(r);
    uint32_t lists = c->cascades + c->spots;
    if (r.settings.shadowCulling == ShadowCulling::PerView && lists > 0) {
        c->shadowViews =
            createBuffer(gpu, {"culling.shadowViews", lists * sizeof(gpu::GpuShadowCullView), 0,
                               MemoryKind::Upload});
        c->shadowViewDraws =
            createBuffer(gpu, {"draws.shadowViews",
                               VkDeviceSize(lists) * r.maxDraws * sizeof(gpu::DrawIndexedCommand),
                               VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
        c->shadowViewCounts = createBuffer(
            gpu, {"draws.shadowViewCounts", lists * 4u, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
        ok = ok && c->shadowViews && c->shadowViewDraws && c->shadowViewCounts;
    }
    if (r.settings.occlusion) {
        glm::uvec2 size(r.internalWidth, r.internalHeight);
        uint32_t texels = 0;
        while (true) {
            c->levelSize.push_back(size);
            c->levelOffset.push_back(texels);
            texels += size.x * size.y;
            if (size.x == 1 && size.y == 1) break;
            size = glm::max((size + 1u) / 2u, glm::uvec2(1));
        }
        c->pyramid = createBuffer(gpu, {"culling.depthPyramid", VkDeviceSize(texels) * 4});
        VkDeviceSize drawBytes =
            VkDeviceSize(DRAW_CAMERA_SLOTS) * r.maxDraws * sizeof(gpu::DrawIndexedCommand);
        c->phase2Draws = createBuffer(
            gpu, {"draws.cameraPhase2", drawBytes, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
        c->phase2Counts = createBuffer(gpu, {"draws.cameraPhase2Counts", DRAW_CAMERA_SLOTS * 4,
                                             VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT});
        c->visibleList =
            createBuffer(gpu, {"culling.visibleList", perInstance + 4, 0, MemoryKind::Readback});
        ok = ok && c->pyramid && c->phase2Draws && c->phase2Counts && c->visibleList;
        c->hizBuild = createComputePipeline(gpu, "hizBuild", "culling_hiz_build.comp.spv");
    }
    if (!ok) {
        destroyCulling(r, c);
        throw DeviceError("out of GPU memory for the culling buffers");
    }
    // Nothing was visible before the first frame: phase 1 draws nothing, phase 2 everything
    // the (empty) pyramid does not hide.
    std::vector<uint32_t> zeros(perInstance / 4, 0u);
    uploadBuffer(gpu, c->visibility, zeros.data(), perInstance);
    return c;
}

void destroyCulling(Renderer& r, CullingStatePtr& c) {
    if (!c) return;
    Gpu& gpu = *r.gpu;
    for (BufferHandle b :
         {c->frame, c->stats, c->visibility, c->pyramid, c->phase2Draws, c->phase2Counts,
          c->visibleList, c->shadowViews, c->shadowViewDraws, c->shadowViewCounts})
        if (b) destroy(gpu, b);
    if (c->hizBuild.pipeline) destroy(gpu, c->hizBuild);
    c.reset();
}

void prepareCullingFrame(Renderer& r, const GpuScene& scene, gpu::FrameConstants& constants) {
    Gpu& gpu = *r.gpu;
    CullingState& c = *r.culling;
    c.dispatches = 0;
    gpu::CullingFrame f{};
    f.meshLods = address(gpu, scene.meshLods);
    f.stats = address(gpu, c.stats);
    f.visibility = address(gpu, c.visibility);
    f.hiz = c.pyramid ? address(gpu, c.pyramid) : 0;
    f.lod = r.settings.lod ? 1u : 0u;
    f.lodErrorPixels = r.settings.lodErrorPixels;
    // P[1][1] = cot(fov / 2): a length l at distance d spans l * P[1][1] * height / 2 / d pixels.
    f.lodScale = std::abs(constants.proj[1][1]) * 0.5f * float(r.internalHeight); // y is flipped
    f.occlusion = r.settings.occlusion ? 1u : 0u;
    // Not with GI: the reflective shadow maps draw the shadow list and need every normal.
    f.proxyShadows = r.settings.proxyShadows && !r.gi ? 1u : 0u;
    f.sceneMinY = scene.bounds.valid() ? scene.bounds.min.y : -1e30f;
    // A sun map to keep must hold every caster a later camera may see shadows of.
    f.sunList = r.sunShadowCache.listThisFrame;
    if (!c.levelSize.empty()) {
        f.hizLevels = uint32_t(c.levelSize.size());
        f.hizSize = c.levelSize[0];
    }
    if (c.shadowViewDraws) {
        // This frame's cascades and spots (prepareShadows ran before): a view per one with a map.
        std::vector<gpu::GpuShadowCullView> views;
        auto add = [&](const glm::mat4& viewProj, uint32_t view, uint32_t kind) {
            gpu::GpuShadowCullView v{};
            auto planes = frustumPlanes(viewProj);
            // Sides and far (planes 0-3, 5): depth clamp keeps nearer casters in the map.
            for (int p = 0; p < 4; ++p) v.planes[p] = planes[p];
            v.planes[4] = planes[5];
            v.view = view;
            v.list = c.listOf(view);
            v.kind = kind;
            views.push_back(v);
        };
        for (uint32_t i = 0; i < c.cascades; ++i)
            add(sunCascadeViewProj(r, i), CULL_VIEW_CASCADE0 + i, CULL_SHADOW_VIEW_CASCADE);
        glm::mat4 viewProj;
        for (uint32_t i = 0; i < c.spots; ++i)
            if (spotShadowViewProj(r, i, viewProj))
                add(viewProj, CULL_VIEW_SPOT0 + i, CULL_SHADOW_VIEW_SPOT);
        std::memcpy(mapped(gpu, c.shadowViews), views.data(),
                    views.size() * sizeof(gpu::GpuShadowCullView));
        f.shadowViews = address(gpu, c.shadowViews);
        f.shadowViewDraws = address(gpu, c.shadowViewDraws);
        f.shadowViewCounts = address(gpu, c.shadowViewCounts);
        f.shadowViewCount = uint32_t(views.size());
    }
    std::memcpy(mapped(gpu, c.frame), &f, sizeof(f));
    constants.culling = address(gpu, c.frame);
}

void recordCullingReset(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    CullingState& c = *r.culling;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, c.stats), 0, VK_WHOLE_SIZE, 0);
    if (c.phase2Counts) vkCmdFillBuffer(cmd, vkBuffer(gpu, c.phase2Counts), 0, VK_WHOLE_SIZE, 0);
    if (c.visibleList) vkCmdFillBuffer(cmd, vkBuffer(gpu, c.visibleList), 0, 4, 0);
    if (c.shadowViewCounts)
        vkCmdFillBuffer(cmd, vkBuffer(gpu, c.shadowViewCounts), 0, VK_WHOLE_SIZE, 0);
}

void recordInstanceCullDispatch(Renderer& r, VkCommandBuffer cmd, const InstanceCullPush& push,
                                uint32_t instances) {
    pushConstants(*r.gpu, cmd, push);
    if (instances) vkCmdDispatch(cmd, (instances + 63) / 64, 1, 1);
    r.culling->dispatches++;
}

void recordOcclusionPasses(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    CullingState& c = *r.culling;
    pass(rec, "hizBuild", [&](VkCommandBuffer cmd) {
        sceneDepthToSampled(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
        bind(gpu, cmd, c.hizBuild);
        for (size_t k = 0; k < c.levelSize.size(); ++k) {
            HizPush push{};
            push.pyramid = address(gpu, c.pyramid);
            push.dstOffset = c.levelOffset[k];
            push.dstSize = c.levelSize[k];
            push.fromDepth = k == 0;
            push.depthSlot = slot(gpu, r.depthRead).value;
            if (k > 0) push.srcOffset = c.levelOffset[k - 1], push.srcSize = c.levelSize[k - 1];
            pushConstants(gpu, cmd, push);
            vkCmdDispatch(cmd, (push.dstSize.x + 7) / 8, (push.dstSize.y + 7) / 8, 1);
            memoryBarrier(
                cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        }
        // Back to a depth target (contents kept) for the phase-2 prepass.
        sceneDepthToAttachment(r, cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT);
    });
    pass(rec, "instanceCullPhase2", [&, frame](VkCommandBuffer cmd) {
        bind(gpu, cmd, r.instanceCull);
        InstanceCullPush push{
            frame,   address(gpu, c.phase2Draws), address(gpu, c.phase2Counts), r.maxDraws, 0,
            CullRest};
        push.visibleList = address(gpu, c.visibleList);
        recordInstanceCullDispatch(r, cmd, push, scene.instanceCount);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                      VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
    });
    pass(rec, "depthPrepassPhase2", [&, frame](VkCommandBuffer cmd) {
        beginSceneDepthPass(r, cmd, false);
        bind(gpu, cmd, r.depthPrepass);
        VkViewport vp{0, 0, float(r.internalWidth), float(r.internalHeight), 0, 1};
        VkRect2D scissor{{0, 0}, {r.internalWidth, r.internalHeight}};
        vkCmdSetViewport(cmd, 0, 1, &vp);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        pushConstants(gpu, cmd, RasterPush{frame, 0});
        vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
        for (uint32_t list : {DRAW_LIST_OPAQUE, DRAW_LIST_OPAQUE_TEXTURED,
                              DRAW_LIST_OPAQUE_FEATURED, DRAW_LIST_DECOUPLED})
            for (uint32_t side = 0; side < DRAW_SIDE_COUNT; ++side) {
                setDrawSide(cmd, side);
                drawPhase2List(r, cmd, list * DRAW_SIDE_COUNT + side);
            }
        vkCmdEndRendering(cmd);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                          VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                          VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    });
}

void drawPhase2List(Renderer& r, VkCommandBuffer cmd, uint32_t list) { // list: a camera slot
    CullingState* c = r.culling.get();
    if (!c || !c->phase2Draws) return;
    Gpu& gpu = *r.gpu;
    vkCmdDrawIndexedIndirectCount(cmd, vkBuffer(gpu, c->phase2Draws),
                                  VkDeviceSize(list) * r.maxDraws * sizeof(gpu::DrawIndexedCommand),
                                  vkBuffer(gpu, c->phase2Counts), list * 4, r.maxDraws,
                                  sizeof(gpu::DrawIndexedCommand));
}

void drawShadowViewList(Renderer& r, VkCommandBuffer cmd, uint32_t view) {
    Gpu& gpu = *r.gpu;
    const CullingState& c = *r.culling;
    uint32_t list = c.listOf(view);
    if (list == ~0u) { // whole-scene: the sun's opaque casters
        drawSunShadowList(r, cmd);
        return;
    }
    vkCmdDrawIndexedIndirectCount(cmd, vkBuffer(gpu, c.shadowViewDraws),
                                  VkDeviceSize(list) * r.maxDraws * sizeof(gpu::DrawIndexedCommand),
                                  vkBuffer(gpu, c.shadowViewCounts), VkDeviceSize(list) * 4,
                                  r.maxDraws, sizeof(gpu::DrawIndexedCommand));
}

void finishCullingFrame(Renderer& r) {
    CullingState& c = *r.culling;
    std::memcpy(&c.last, mapped(*r.gpu, c.stats), sizeof(gpu::GpuCullStats));
    c.lastDispatches = c.dispatches.load();
    if (c.visibleList) {
        const uint32_t* list = static_cast<const uint32_t*>(mapped(*r.gpu, c.visibleList));
        uint32_t count = std::min(list[0], c.instances);
        // The GPU appends in whatever order its invocations ran. The decoupled allocation
        // visits this list in order, and the order decides where each object's chunks are
        // stored (and so which chunks take their refresh turn): in instance order, a frame's
        // storage layout and stats depend on the scene and camera alone, not on the device's
        // scheduling. Sorted through a bit per instance: linear in the instances / 64 and the
        // list, where a comparison sort of 100k visible instances costs milliseconds.
        c.visibleBits.assign((c.instances + 63) / 64, 0);
        for (uint32_t i = 0; i < count; ++i)
            if (list[1 + i] < c.instances)
                c.visibleBits[list[1 + i] >> 6] |= 1ull << (list[1 + i] & 63);
        c.visibleLastFrame.clear();
        for (uint32_t w = 0; w < c.visibleBits.size(); ++w)
            for (uint64_t bits = c.visibleBits[w]; bits != 0; bits &= bits - 1)
                c.visibleLastFrame.push_back(w * 64 + uint32_t(std::countr_zero(bits)));
        c.haveVisible = true;
    }
}

const std::vector<uint32_t>* visibleLastFrame(const Renderer& r) {
    const CullingState* c = r.culling.get();
    return c && c->haveVisible ? &c->visibleLastFrame : nullptr;
}

void cullingStats(const Renderer& r, nlohmann::json& s) {
    const CullingState& c = *r.culling;
    const gpu::GpuCullStats& st = c.last;
    // Whole-scene culling: the cascades and spots draw the sun's list (its counts).
    auto view = [&](uint32_t drawnView) {
        uint32_t v = drawnView >= CULL_VIEW_CASCADE0 && c.listOf(drawnView) == ~0u
                         ? CULL_VIEW_SHADOW
                         : drawnView;
        nlohmann::json j = {{"instances", c.instances},
                            {"frustum_visible", st.frustumVisible[v]},
                            {"instances_drawn", st.instancesDrawn[v]},
                            {"triangles_drawn", st.trianglesDrawn[v]},
                            {"vertices_drawn", st.verticesDrawn[v]},
                            {"culled_fraction",
                             c.instances ? 1.0 - double(st.instancesDrawn[v]) / c.instances : 0.0}};
        if (v == CULL_VIEW_CAMERA) {
            j["occlusion_culled"] = st.occlusionCulled;
            j["drawn_in_phase1"] = st.drawnLastFrameVisible;
        }
        return j;
    };
    s["instances_drawn"] = st.instancesDrawn[CULL_VIEW_CAMERA];
    s["triangles_drawn"] = st.trianglesDrawn[CULL_VIEW_CAMERA];
    s["culling"] = {
        {"lod", r.settings.lod ? "on" : "off"},
        {"occlusion", r.settings.occlusion ? "on" : "off"},
        {"proxy_shadows", r.settings.proxyShadows && !r.gi ? "on" : "off"},
        {"dispatches", c.lastDispatches},
        {"shadow_culling",
         r.settings.shadowCulling == ShadowCulling::PerView ? "per-view" : "whole-scene"},
        {"views", {{"camera", view(CULL_VIEW_CAMERA)}, {"shadow", view(CULL_VIEW_SHADOW)}}}};
    nlohmann::json& views = s["culling"]["views"];
    for (uint32_t i = 0; i < c.cascades; ++i)
        views["sun_cascade_" + std::to_string(i)] = view(CULL_VIEW_CASCADE0 + i);
    glm::mat4 unused;
    for (uint32_t i = 0; i < c.spots; ++i) // the spots with a map
        if (spotShadowViewProj(r, i, unused))
            views["spot_shadow_" + std::to_string(i)] = view(CULL_VIEW_SPOT0 + i);
}

} // namespace shadel
