#pragma once
// The GPU-driven world's culling state: per-mesh LOD chains chosen on the GPU by
// projected error, per-view counts, and two-phase hierarchical-Z occlusion culling of the
// camera view. The cull itself is shaders/forward/instance_cull.comp (its helpers live in
// shaders/culling/cull.glsl); this owns what it reads and writes besides the draw lists.
//
// Occlusion (--occlusion on), after the depth prepass of phase 1 (what was visible last frame):
//   hizBuild            the prepass depth reduced to a pyramid of farthest depths
//   instanceCullPhase2  every frustum-visible instance tested against it; the visible ones that
//                       phase 1 did not draw go to the phase-2 lists, visibility kept for the
//                       next frame
//   depthPrepassPhase2  the phase-2 lists complete the depth
// Every later camera pass draws both lists (drawCameraList).
//
// Shadow views (--shadow-culling per-view, the default): the same instanceCull dispatch that
// fills the camera's and the sun's whole-scene lists tests every instance against each sun
// cascade's box and each shadow-casting spot's frustum and appends it to that view's own list,
// so a cascade or a spot draws only its casters (drawShadowViewList). LODs: the camera's choice
// in every view (shadows match what is drawn). --shadow-culling whole-scene: every cascade and
// spot draws the sun's list (every caster of the scene), for comparison.
#include <memory>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/shared_types.h"
#include "rhi/frame.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;

// Push constants of instance_cull.comp.
struct InstanceCullPush {
    uint64_t frame;
    uint64_t draws; // the camera's lists
    uint64_t counts;
    uint32_t maxDraws;
    uint32_t shadowViews; // 1: the shadow views too (the sun's and the per-view lists)
    uint32_t phase;       // CullPhase
    uint32_t pad = 0;
    uint64_t visibleList = 0; // phase 2: count + ids of the visible instances (read back)
    uint64_t sunDraws = 0;    // the sun's whole-scene lists
    uint64_t sunCounts = 0;
};
enum CullPhase : uint32_t { CullSinglePass = 0, CullLastVisible = 1, CullRest = 2 };

struct CullingState;
struct CullingStateDeleter {
    void operator()(CullingState* state) const;
};
using CullingStatePtr = std::unique_ptr<CullingState, CullingStateDeleter>;

CullingStatePtr createCulling(Renderer& r, const GpuScene& scene);
void destroyCulling(Renderer& r, CullingStatePtr& state);

// CPU side of a frame: the CullingFrame constants (O(1) in the instance count).
void prepareCullingFrame(Renderer& r, const GpuScene& scene, gpu::FrameConstants& constants);
// Inside the instanceCull pass, before the dispatches: zero the counts and the phase-2 lists.
void recordCullingReset(Renderer& r, VkCommandBuffer cmd);
// One dispatch of instance_cull.comp over every instance (pipeline bound), counted for the stats
// ("culling": "dispatches").
void recordInstanceCullDispatch(Renderer& r, VkCommandBuffer cmd, const InstanceCullPush& push,
                                uint32_t instances);
// --occlusion on: the three passes above, after the depth prepass.
void recordOcclusionPasses(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene& scene);
// Inside a raster pass drawing the camera's list: the phase-2 part of it (nothing without
// occlusion culling).
void drawPhase2List(Renderer& r, VkCommandBuffer cmd, uint32_t list);
// Inside a shadow view's depth pass (index buffer bound): draws the casters of view
// CULL_VIEW_CASCADE0 + i or CULL_VIEW_SPOT0 + i (its own list, or the sun's with whole-scene
// culling).
void drawShadowViewList(Renderer& r, VkCommandBuffer cmd, uint32_t view);
// After the GPU finished the frame: keep its counts for the stats (and, with occlusion, the
// visible set).
void finishCullingFrame(Renderer& r);
// With occlusion culling, the instances the camera saw last frame (the GPU's culled set, so CPU
// work per visible object follows what is seen, not the world); null before the first frame or
// without occlusion culling.
const std::vector<uint32_t>* visibleLastFrame(const Renderer& r);
// "instances_drawn", "triangles_drawn" (camera) and "culling": the per-view table (camera,
// shadow = the sun's whole-scene map, sun_cascade_N, spot_shadow_N).
void cullingStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
