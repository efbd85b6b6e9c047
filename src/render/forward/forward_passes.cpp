#include "render/forward/forward_passes.h"

#include "render/background/background.h"
#include "render/culling/culling.h"
#include "render/debug/inspect.h"
#include "render/post/tone_curve.h"
#include "render/post/tonemap.h"
#include "render/renderer.h"

namespace shadel {

namespace {
void setViewport(VkCommandBuffer cmd, uint32_t w, uint32_t h) {
    VkViewport vp{0, 0, float(w), float(h), 0, 1};
    VkRect2D scissor{{0, 0}, {w, h}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void drawList(Renderer& r, VkCommandBuffer cmd, BufferHandle draws, VkDeviceSize countOffset,
              uint32_t list) {
    Gpu& gpu = *r.gpu;
    vkCmdDrawIndexedIndirectCount(cmd, vkBuffer(gpu, draws),
                                  VkDeviceSize(list) * r.maxDraws * sizeof(gpu::DrawIndexedCommand),
                                  vkBuffer(gpu, r.drawCounts), countOffset + list * 4, r.maxDraws,
                                  sizeof(gpu::DrawIndexedCommand));
}

// The forward opaque lists by material class, each shaded by a pipeline with only the class's
// material features compiled in (Renderer::forwardOpaque[k]).
struct ForwardClass {
    uint32_t list;
    uint32_t materialFeatures; // kMaterialFeatures of its pipeline
    const char* pipelineName;
};
constexpr ForwardClass kForwardClasses[kForwardClassCount] = {
    {DRAW_LIST_OPAQUE, 0u, "forwardOpaque"},
    {DRAW_LIST_OPAQUE_TEXTURED, MATERIAL_FEATURE_TEXTURES, "forwardOpaqueTextured"},
    {DRAW_LIST_OPAQUE_FEATURED, MATERIAL_FEATURES_ALL, "forwardOpaqueFeatured"}};

// One camera list exactly (drawCameraList draws the opaque lists as one), side by side.
void drawOneCameraList(Renderer& r, VkCommandBuffer cmd, uint32_t list, BufferHandle indices) {
    Gpu& gpu = *r.gpu;
    setViewport(cmd, r.internalWidth, r.internalHeight);
    vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, indices ? indices : r.sceneIndices), 0,
                         VK_INDEX_TYPE_UINT32);
    for (uint32_t side = 0; side < DRAW_SIDE_COUNT; ++side) {
        setDrawSide(cmd, side);
        uint32_t slot = list * DRAW_SIDE_COUNT + side;
        drawList(r, cmd, r.draws, 0, slot);
        drawPhase2List(r, cmd, slot); // occlusion culling's second phase (render/culling)
    }
}
} // namespace

void setDrawSide(VkCommandBuffer cmd, uint32_t side) {
    bool both = (side & ~DRAW_SIDE_MIRRORED) == DRAW_SIDE_BOTH;
    vkCmdSetCullMode(cmd, both ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT);
    vkCmdSetFrontFace(cmd, (side & DRAW_SIDE_MIRRORED) != 0u ? VK_FRONT_FACE_CLOCKWISE
                                                             : VK_FRONT_FACE_COUNTER_CLOCKWISE);
}

uint32_t drawSideOf(bool doubleSided, const glm::mat4& transform) {
    return (doubleSided ? DRAW_SIDE_BOTH : DRAW_SIDE_FRONT) +
           (glm::determinant(glm::mat3(transform)) < 0.0f ? DRAW_SIDE_MIRRORED : 0u);
}

BufferHandle shadingIndices(const Renderer& r) {
    return r.settings.inspectX >= 0 ? r.sceneVisibilityIndices : r.sceneIndices;
}

uint32_t shadingVisibilityVertices(const Renderer& r) {
    return r.settings.inspectX >= 0 ? VISIBILITY_VERTICES_ALL : VISIBILITY_VERTICES_OFF;
}

// The forward pipeline of material class k, writing scene colour or display pixels.
static GraphicsPipelineDesc forwardClassPipeline(const Renderer& r, uint32_t k, bool display) {
    GraphicsPipelineDesc opaque;
    opaque.vertexShader = "forward_forward.vert.spv";
    opaque.fragmentShader = "forward_forward.frag.spv";
    opaque.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    opaque.depthFormat = VK_FORMAT_D32_SFLOAT;
    opaque.depthWrite = false;
    opaque.depthCompare = VK_COMPARE_OP_EQUAL; // the prepass resolved visibility
    opaque.dynamicCulling = true;              // per list side (drawCameraList)
    opaque.specialization = shaderPrintSpecialization(r.settings.inspectX >= 0);
    opaque.specialization.push_back(
        {VISIBILITY_VERTICES_CONSTANT_ID, shadingVisibilityVertices(r)});
    if (r.settings.distanceFieldLighting)
        opaque.specialization.push_back({DISTANCE_FIELD_LIGHTING_CONSTANT_ID, 1u});
    // A screen tile's lights that read no texture run in a loop without that code (spectra per
    // light, shaders/common/lighting.glsl); other lists leave that loop empty.
    if (r.forwardSplitsTileLights)
        opaque.specialization.push_back({SPECTRUM_LIGHT_SPLIT_CONSTANT_ID, 1u});
    // One pipeline per material class, with only the class's material features compiled in (as
    // the shadel path's shading classes): a CPU device's SIMD group runs the code of a branch
    // none of its lanes takes, so compiled-in features cost every pixel.
    opaque.name = kForwardClasses[k].pipelineName;
    opaque.specialization.push_back(
        {MATERIAL_FEATURES_CONSTANT_ID, kForwardClasses[k].materialFeatures});
    if (display) { // the tonemap fused into it (render/post/tonemap.h)
        opaque.name += "Display";
        opaque.colorFormats = {VK_FORMAT_R8G8B8A8_UNORM};
        opaque.specialization.push_back({FORWARD_DISPLAY_OUTPUT_CONSTANT_ID, 1u});
    }
    return opaque;
}

void createForwardPipelines(Renderer& r) {
    Gpu& gpu = *r.gpu;
    r.instanceCull = createComputePipeline(gpu, "instanceCull", "forward_instance_cull.comp.spv");
    GraphicsPipelineDesc depth;
    depth.name = "depthPrepass";
    depth.vertexShader = "forward_forward.vert.spv";
    depth.fragmentShader = r.alphaMasked ? "forward_depth.frag.spv" : ""; // (Renderer::alphaMasked)
    depth.depthFormat = VK_FORMAT_D32_SFLOAT;
    depth.dynamicCulling = true; // per list side (drawCameraList)
    r.depthPrepass = createGraphicsPipeline(gpu, depth);
    // Scene colour: the hybrid objects of decoupled frames draw with them too.
    for (uint32_t k = 0; k < kForwardClassCount; ++k)
        r.forwardOpaque[k] = createGraphicsPipeline(gpu, forwardClassPipeline(r, k, false));
}

void prepareForwardPipelines(Renderer& r) {
    if (!r.tonemapFused || r.settings.mode != RenderMode::Forward || r.forwardDisplay[0].pipeline)
        return;
    for (uint32_t k = 0; k < kForwardClassCount; ++k)
        r.forwardDisplay[k] = createGraphicsPipeline(*r.gpu, forwardClassPipeline(r, k, true));
}

void destroyForwardPipelines(Renderer& r) {
    for (Pipeline* p : {&r.instanceCull, &r.depthPrepass}) destroy(*r.gpu, *p);
    for (Pipeline& p : r.forwardOpaque) destroy(*r.gpu, p);
    for (Pipeline& p : r.forwardDisplay) destroy(*r.gpu, p);
}

void recordInstanceCull(Renderer& r, VkCommandBuffer cmd, uint64_t frame, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    vkCmdFillBuffer(cmd, vkBuffer(gpu, r.drawCounts), 0, VK_WHOLE_SIZE, 0);
    recordCullingReset(r, cmd);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, r.instanceCull);
    // One dispatch for every view: the camera (with occlusion culling, its first phase: what was
    // visible last frame), the sun's whole-scene map and the per-view cascade and spot lists.
    InstanceCullPush push{frame,
                          address(gpu, r.draws),
                          address(gpu, r.drawCounts),
                          r.maxDraws,
                          1,
                          r.settings.occlusion ? CullLastVisible : CullSinglePass};
    push.sunDraws = address(gpu, r.shadowDraws);
    push.sunCounts = address(gpu, r.drawCounts) + DRAW_CAMERA_SLOTS * 4;
    recordInstanceCullDispatch(r, cmd, push, scene.instanceCount);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT, VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
}

void recordShadowMap(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    beginShadowAtlas(gpu, cmd, r.sunShadow, vkBuffer(gpu, r.sceneIndices));
    pushConstants(gpu, cmd, RasterPush{frame, 1});
    drawSunShadowList(r, cmd);
    endShadowAtlas(gpu, cmd, r.sunShadow);
}

void drawSunShadowList(Renderer& r, VkCommandBuffer cmd) {
    drawList(r, cmd, r.shadowDraws, DRAW_CAMERA_SLOTS * 4, DRAW_LIST_OPAQUE);
}

void drawCameraList(Renderer& r, VkCommandBuffer cmd, uint32_t list, BufferHandle indices) {
    if (list != DRAW_LIST_OPAQUE) return drawOneCameraList(r, cmd, list, indices);
    // The forward opaque surfaces are a list per material class (kForwardClasses); only the
    // forward shading tells them apart.
    for (const ForwardClass& c : kForwardClasses) drawOneCameraList(r, cmd, c.list, indices);
}

void sceneDepthToSampled(Renderer& r, VkCommandBuffer cmd, VkPipelineStageFlags2 readers) {
    imageBarrier(cmd, vkImage(*r.gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                 VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, readers,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void sceneDepthToAttachment(Renderer& r, VkCommandBuffer cmd, VkPipelineStageFlags2 readers) {
    imageBarrier(cmd, vkImage(*r.gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                 readers, 0,
                 VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                 VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

void beginSceneDepthPass(Renderer& r, VkCommandBuffer cmd, bool clear) {
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = vkView(*r.gpu, r.depthTarget);
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {0.0f, 0}; // reversed Z
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {r.internalWidth, r.internalHeight}};
    ri.layerCount = 1;
    ri.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &ri);
}

void recordDepthPrepass(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    VkImage image = vkImage(gpu, r.depth);
    imageBarrier(
        cmd, image, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
        VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0,
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
    beginSceneDepthPass(r, cmd, true);
    bind(gpu, cmd, r.depthPrepass);
    pushConstants(gpu, cmd, RasterPush{frame, 0});
    drawPrepassListsAndEnd(r, cmd, r.sceneIndices);
}

void drawPrepassListsAndEnd(Renderer& r, VkCommandBuffer cmd, BufferHandle indices) {
    drawCameraList(r, cmd, DRAW_LIST_OPAQUE, indices);
    drawCameraList(r, cmd, DRAW_LIST_DECOUPLED, indices);
    vkCmdEndRendering(cmd);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                      VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

// Colour (`target`, cleared to `sky` with alpha 0, or loaded) over the prepass depth.
static void beginColorPass(Renderer& r, VkCommandBuffer cmd, TextureHandle image,
                           RenderTargetView target, glm::vec3 sky, bool clear) {
    Gpu& gpu = *r.gpu;
    if (clear)
        imageBarrier(cmd, vkImage(gpu, image), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_COPY_BIT, 0,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
    VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    color.imageView = vkView(gpu, target);
    color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.clearValue.color = {{sky.x, sky.y, sky.z, 0.0f}};
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = vkView(gpu, r.depthTarget);
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {r.internalWidth, r.internalHeight}};
    ri.layerCount = 1;
    ri.colorAttachmentCount = 1;
    ri.pColorAttachments = &color;
    ri.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &ri);
}

void beginSceneColorPass(Renderer& r, VkCommandBuffer cmd, bool clear) {
    beginColorPass(r, cmd, r.hdr, r.hdrTarget, r.skyColor, clear);
}

// Each material class's list by its own pipeline (scene colour, or display pixels when fused).
static void drawForwardLists(Renderer& r, VkCommandBuffer cmd, uint64_t frame,
                             const std::array<Pipeline, kForwardClassCount>& pipelines) {
    Gpu& gpu = *r.gpu;
    for (uint32_t k = 0; k < kForwardClassCount; ++k) {
        bind(gpu, cmd, pipelines[k]);
        pushConstants(gpu, cmd, RasterPush{frame, 0});
        drawOneCameraList(r, cmd, kForwardClasses[k].list, shadingIndices(r));
    }
    // The blended instances (DRAW_LIST_BLEND) are drawn after every opaque surface by the
    // transparency passes (render/oit), from a CPU list that can be shuffled or sorted.
}

void drawForwardLists(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    drawForwardLists(r, cmd, frame, r.forwardOpaque);
}

void recordForwardShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    if (r.tonemapFused) { // display pixels (render/post/tonemap.h): the sky as the display shows it
        glm::vec3 clear = r.settings.backgroundEnvironment
                              ? displayColor(r.skyColor, r.settings.exposure, r.settings.tonemap)
                              : r.settings.backgroundColor; // exactly the colour asked for
        beginColorPass(r, cmd, r.display, r.displayTarget, clear, true);
        drawForwardLists(r, cmd, frame, r.forwardDisplay);
        recordBackground(r, cmd, frame, true);
    } else {
        beginSceneColorPass(r, cmd, true);
        drawForwardLists(r, cmd, frame, r.forwardOpaque);
        recordBackground(r, cmd, frame, false);
    }
    vkCmdEndRendering(cmd);
}

} // namespace shadel
