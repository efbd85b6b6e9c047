#pragma once
// The forward path's passes: GPU instance culling into indirect draw lists, the sun's shadow
// map, the depth prepass and forward shading. The decoupled path reuses the first three.
#include <cstdint>

#include <glm/mat4x4.hpp>

#include "rhi/handles.h"
#include "rhi/vk.h"

namespace shadel {

struct RasterPush { // push constants of every raster pass (shaders/forward/forward.vert)
    uint64_t frame;
    uint32_t shadowView;
};

struct Renderer;
struct GpuScene;

void createForwardPipelines(Renderer& r);
// The display-output pipelines, the first time a frame fuses the tonemap into forward shading
// (Renderer::tonemapFused), before its passes are recorded.
void prepareForwardPipelines(Renderer& r);
void destroyForwardPipelines(Renderer& r);

// Culls every instance on the GPU, in one dispatch, against the camera frustum, the sun's
// shadow volume and each cascade's and shadow-casting spot's view (render/culling/culling.h).
void recordInstanceCull(Renderer& r, VkCommandBuffer cmd, uint64_t frame, const GpuScene& scene);
void recordShadowMap(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
void recordDepthPrepass(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// Into the scene colour, or with the frame's tonemap fused into it (Renderer::tonemapFused) as
// display pixels into Renderer::display (render/post/tonemap.h).
void recordForwardShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// The forward-shaded opaque list inside an open scene colour pass; the decoupled frame draws it
// next to reconstruction (hybrid). Blended instances are drawn by render/oit.
void drawForwardLists(Renderer& r, VkCommandBuffer cmd, uint64_t frame);

// The sun's culled opaque casters (its whole-scene view): the sun's map, the whole-scene
// fallback of cascades and spots, and GI's reflective shadow maps draw it.
void drawSunShadowList(Renderer& r, VkCommandBuffer cmd);
// Shared by every raster pass that draws the culled camera list (decoupled passes too), from the
// scene's index buffer unless `indices` names another of the same layout (the visibility
// prepass's: GpuScene::visibilityIndices). Each list is drawn side by side (DRAW_SIDE_*), the
// cull mode set for each: the pipeline has GraphicsPipelineDesc::dynamicCulling.
void drawCameraList(Renderer& r, VkCommandBuffer cmd, uint32_t list, BufferHandle indices = {});
// The cull mode and front face of a draw of side `side` (DRAW_SIDE_*), for dynamicCulling
// pipelines: back faces culled for single-sided materials, none for double-sided ones; front
// faces clockwise for instances whose transform mirrors.
void setDrawSide(VkCommandBuffer cmd, uint32_t side);
// The side of an instance drawn on its own (the CPU lists of transparency and transmission).
uint32_t drawSideOf(bool doubleSided, const glm::mat4& transform);
// Begins depth-only rendering into the scene depth (cleared for the prepass, loaded after).
void beginSceneDepthPass(Renderer& r, VkCommandBuffer cmd, bool clear);
// --inspect prints the triangle under the pixel: forward shading and the raster reconstruction
// then draw the scene's visibility vertices (VISIBILITY_VERTICES_ALL), whose provoking vertex
// names it, from these indices (the same depth: the corners keep their order).
BufferHandle shadingIndices(const Renderer& r);
uint32_t shadingVisibilityVertices(const Renderer& r); // the pipelines' VISIBILITY_VERTICES_*
// Inside a prepass: draws the opaque and decoupled camera lists (what writes depth) from
// `indices`, ends rendering, and makes the depth visible to the passes that test against it.
void drawPrepassListsAndEnd(Renderer& r, VkCommandBuffer cmd, BufferHandle indices);
// The scene depth, written by the passes before, made readable by shaders of the `readers`
// stages (tile depth bounds, the HiZ pyramid, debug picking, soft particles) ...
void sceneDepthToSampled(Renderer& r, VkCommandBuffer cmd, VkPipelineStageFlags2 readers);
// ... then handed back, contents kept, to the depth tests of the passes after.
void sceneDepthToAttachment(Renderer& r, VkCommandBuffer cmd, VkPipelineStageFlags2 readers);
// Begins dynamic rendering into the HDR target with the prepass depth (loaded, not cleared).
void beginSceneColorPass(Renderer& r, VkCommandBuffer cmd, bool clearColor);

} // namespace shadel
