#include "render/shadel/visibility.h"

#include "core/assert.h"
#include "core/error.h"
#include "render/debug/inspect.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"

namespace shadel {

struct VisibilityState {
    TextureHandle ids; // "visibilityBuffer": R32G32_UINT {instance, triangle}
    RenderTargetView idsTarget;
    TextureReadView idsRead;
    TextureWriteView hdrWrite; // the scene colour target as a storage image (resolve)
    // "reconstructionAddress" (decoupled only): 16 bytes per pixel, the levels' footprints the
    // compute marking marked, read by the resolve (shaders/shadel/resolve_address.glsl).
    BufferHandle address;
    // "resolveRebuildList" (decoupled only): the pixels the resolve leaves to its rebuild pass
    // (misses, overflow, camera cuts) and that pass's indirect arguments
    // (shaders/shadel/resolve_pixel.glsl ResolveRebuildList).
    BufferHandle rebuildList;
    // "markQuadList" (decoupled only): the quads marking's first pass leaves to its later two
    // (those not on one decoupled triangle), with their indirect arguments
    // (shaders/shadel/mark_quad.glsl MarkQuadList).
    BufferHandle markList;
    // resolveInline rebuilds its rare pixels itself (debug views, --inspect); resolve lists them
    // for resolveRebuild, sized by resolveRebuildArgs. Each of the three per output: [0] scene
    // colour, [1] display pixels (the tonemap fused into the resolve: render/post/tonemap.h).
    Pipeline prepass, mark, markTwoTriangles, markListed, markTwoTrianglesArgs, markListedArgs,
        resolveRebuildArgs;
    std::array<Pipeline, 2> resolve, resolveInline, resolveRebuild;
};

void VisibilityStateDeleter::operator()(VisibilityState* state) const {
    delete state;
}

namespace {
// The lists' headers (shaders/shadel/resolve_pixel.glsl ResolveRebuildList,
// shaders/shadel/mark_quad.glsl MarkQuadList): indirect arguments and counts, cleared each frame.
constexpr VkDeviceSize kRebuildListHeaderBytes = 32;
constexpr VkDeviceSize kMarkListHeaderBytes = 48;
constexpr VkDeviceSize kMarkListPixelDispatchOffset = 16; // MarkQuadList::pixelDispatch

struct ComputePush {
    uint64_t frame;
    uint32_t visibilitySlot;
    uint32_t width;
    uint32_t height;
    uint32_t hdrSlot;
    uint64_t address;
    uint64_t rebuildList;
    uint64_t markList;
    uint64_t displayPixels; // the resolve's: the readback when the tonemap is fused, else 0
};

ComputePush computePush(Renderer& r, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    VisibilityState& v = *r.visibility;
    return {frame,
            slot(gpu, v.idsRead).value,
            r.internalWidth,
            r.internalHeight,
            slot(gpu, v.hdrWrite).value,
            v.address ? address(gpu, v.address) : 0u,
            v.rebuildList ? address(gpu, v.rebuildList) : 0u,
            v.markList ? address(gpu, v.markList) : 0u,
            r.tonemapFused ? address(gpu, r.pixels) : 0u};
}

void dispatchPixels(Renderer& r, VkCommandBuffer cmd) {
    // One invocation per 2x2 quad, 8x8 invocations per group: 16x16 pixels.
    vkCmdDispatch(cmd, (r.internalWidth + 15) / 16, (r.internalHeight + 15) / 16, 1);
}

// After a pass that listed work: sizes the pass over the list (`args`, one invocation, writes
// its indirect arguments at `dispatchOffset` of the list) and runs it (`pass`).
void dispatchListed(Renderer& r, VkCommandBuffer cmd, const ComputePush& push, BufferHandle list,
                    VkDeviceSize dispatchOffset, const Pipeline& args, const Pipeline& pass) {
    Gpu& gpu = *r.gpu;
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, args);
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, 1, 1, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT);
    bind(gpu, cmd, pass);
    pushConstants(gpu, cmd, push);
    vkCmdDispatchIndirect(cmd, vkBuffer(gpu, list), dispatchOffset);
}

// A pass over the pixel quads that lists what its common code does not handle for a second pass
// (marking: quads not on one triangle, and a third pass after: recordMarkingCompute; the
// resolve: misses, overflow, camera cuts): clears the list's header (after last frame's later
// passes read it, and last frame's readers of what `first` writes), runs `first`, sizes the
// second pass from the list's count (`args`, one invocation) and runs `second` by indirect
// dispatch. The list's header holds those arguments.
void dispatchWithList(Renderer& r, VkCommandBuffer cmd, const ComputePush& push, BufferHandle list,
                      VkDeviceSize headerBytes, const Pipeline& first, const Pipeline& args,
                      const Pipeline& second) {
    Gpu& gpu = *r.gpu;
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_DRAW_INDIRECT_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_INDIRECT_COMMAND_READ_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
    vkCmdFillBuffer(cmd, vkBuffer(gpu, list), 0, headerBytes, 0);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    bind(gpu, cmd, first);
    pushConstants(gpu, cmd, push);
    dispatchPixels(r, cmd);
    dispatchListed(r, cmd, push, list, 0, args, second);
}
} // namespace

VisibilityStatePtr createVisibility(Renderer& r) {
    Gpu& gpu = *r.gpu;
    VisibilityStatePtr state(new VisibilityState());
    VisibilityState& v = *state;
    TextureDesc ids;
    ids.name = "visibilityBuffer";
    ids.format = VK_FORMAT_R32G32_UINT;
    ids.width = r.internalWidth;
    ids.height = r.internalHeight;
    ids.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    v.ids = createTexture(gpu, ids);
    if (!v.ids) throw DeviceError("out of GPU memory for the visibility buffer");
    v.idsTarget = createRenderTargetView(gpu, v.ids);
    v.idsRead = createReadView(gpu, v.ids);
    v.hdrWrite = createWriteView(gpu, r.hdr);
    if (r.settings.mode == RenderMode::Decoupled) { // (tile shading reads only the IDs)
        // A buffer, not an RGBA32UI image: on lavapipe the image stores made the marking pass
        // cost as much more as the resolve saved. Laid out by 2x2 quads, as both passes walk.
        VkDeviceSize quads = VkDeviceSize((r.internalWidth + 1) / 2) * ((r.internalHeight + 1) / 2);
        v.address = createBuffer(gpu, {"reconstructionAddress", quads * 4 * 16});
        if (!v.address) throw DeviceError("out of GPU memory for the reconstruction addresses");
        // A header, then at most every pixel once.
        VkDeviceSize pixels = VkDeviceSize(r.internalWidth) * r.internalHeight;
        v.rebuildList = createBuffer(
            gpu, {"resolveRebuildList", kRebuildListHeaderBytes + pixels * 4,
                  VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        if (!v.rebuildList) throw DeviceError("out of GPU memory for the resolve's rebuild list");
        // A header, then two lists of a slot per quad each.
        v.markList = createBuffer(
            gpu, {"markQuadList", kMarkListHeaderBytes + 2 * quads * 4,
                  VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT});
        if (!v.markList) throw DeviceError("out of GPU memory for marking's quad list");
    }

    GraphicsPipelineDesc prepass;
    prepass.name = "visibilityPrepass";
    prepass.vertexShader = "forward_forward.vert.spv";
    prepass.fragmentShader = "shadel_visibility.frag.spv";
    prepass.specialization = {{ALPHA_MASK_CONSTANT_ID, r.alphaMasked ? 1u : 0u},
                              {VISIBILITY_VERTICES_CONSTANT_ID, VISIBILITY_VERTICES_PREPASS}};
    prepass.colorFormats = {VK_FORMAT_R32G32_UINT};
    prepass.depthFormat = VK_FORMAT_D32_SFLOAT;
    prepass.dynamicCulling = true; // per list side (drawCameraList), as the depth prepass
    v.prepass = createGraphicsPipeline(gpu, prepass);
    std::vector<ComputePipelineDesc> descs = {
        {"shadelMarkVisibility", "shadel_mark_visibility.comp.spv", {}}};
    if (v.rebuildList) {
        descs.push_back({"shadelResolveRebuildArgs", "shadel_resolve_rebuild_args.comp.spv", {}});
        descs.push_back({"shadelMarkTwoTriangles", "shadel_mark_two_triangles.comp.spv", {}});
        descs.push_back({"shadelMarkListed", "shadel_mark_listed.comp.spv", {}});
        descs.push_back({"shadelMarkTwoTrianglesArgs",
                         "shadel_mark_listed_args.comp.spv",
                         {{MARK_PIXEL_LIST_CONSTANT_ID, 0u}}});
        descs.push_back({"shadelMarkListedArgs",
                         "shadel_mark_listed_args.comp.spv",
                         {{MARK_PIXEL_LIST_CONSTANT_ID, 1u}}});
    }
    std::vector<Pipeline> built = createComputePipelines(gpu, descs); // side by side
    v.mark = built[0];
    if (v.rebuildList) {
        v.resolveRebuildArgs = built[1];
        v.markTwoTriangles = built[2];
        v.markListed = built[3];
        v.markTwoTrianglesArgs = built[4];
        v.markListedArgs = built[5];
    }
    registerTextureCapture(
        r.captures, gpu, "visibility", "visibility buffer: instance, triangle (PNG)",
        CaptureKind::Ids, [&v] { return v.ids; }, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    return state;
}

void destroyVisibility(Renderer& r, VisibilityStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    VisibilityState& v = *state;
    for (Pipeline* p : {&v.prepass, &v.mark, &v.markTwoTriangles, &v.markListed,
                        &v.markTwoTrianglesArgs, &v.markListedArgs, &v.resolveRebuildArgs})
        destroy(gpu, *p);
    for (auto* pipelines : {&v.resolve, &v.resolveInline, &v.resolveRebuild})
        for (Pipeline& p : *pipelines) destroy(gpu, p);
    destroy(gpu, v.hdrWrite);
    if (v.address) destroy(gpu, v.address);
    if (v.rebuildList) destroy(gpu, v.rebuildList);
    if (v.markList) destroy(gpu, v.markList);
    destroy(gpu, v.idsRead);
    destroy(gpu, v.idsTarget);
    destroy(gpu, v.ids);
    state.reset();
}

uint32_t visibilityBufferSlot(Renderer& r) {
    return slot(*r.gpu, r.visibility->idsRead).value;
}

uint32_t visibilityHdrWriteSlot(Renderer& r) {
    return slot(*r.gpu, r.visibility->hdrWrite).value;
}

void recordVisibilityPrepass(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    VisibilityState& v = *r.visibility;
    imageBarrier(
        cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
        VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
        VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, 0,
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
        VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT |
            VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
    imageBarrier(cmd, vkImage(gpu, v.ids), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
    VkRenderingAttachmentInfo color{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    color.imageView = vkView(gpu, v.idsTarget);
    color.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    color.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    color.clearValue.color.uint32[0] = 0xFFFFFFFFu; // VISIBILITY_NONE
    color.clearValue.color.uint32[1] = 0xFFFFFFFFu;
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = vkView(gpu, r.depthTarget);
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = {0.0f, 0}; // reversed Z
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {r.internalWidth, r.internalHeight}};
    ri.layerCount = 1;
    ri.colorAttachmentCount = 1;
    ri.pColorAttachments = &color;
    ri.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &ri);
    bind(gpu, cmd, v.prepass);
    pushConstants(gpu, cmd, RasterPush{frame, 0});
    drawPrepassListsAndEnd(r, cmd, r.sceneVisibilityIndices); // its triangles name themselves
    imageBarrier(cmd, vkImage(gpu, v.ids), VK_IMAGE_ASPECT_COLOR_BIT,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}

void recordMarkingCompute(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    VisibilityState& v = *r.visibility;
    SHADEL_ASSERT(v.markList); // (made with the decoupled mode)
    // Every pixel's address is written again, after last frame's resolve read them. First pass:
    // quads on one decoupled triangle, without per-pixel branches; second: the listed quads on
    // two triangles of one instance, the same way; third: the quads listed by either, pixel by
    // pixel (shaders/shadel/mark_quad.glsl).
    ComputePush push = computePush(r, frame);
    dispatchWithList(r, cmd, push, v.markList, kMarkListHeaderBytes, v.mark, v.markTwoTrianglesArgs,
                     v.markTwoTriangles);
    dispatchListed(r, cmd, push, v.markList, kMarkListPixelDispatchOffset, v.markListedArgs,
                   v.markListed);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void prepareResolvePipelines(Renderer& r) {
    if (!r.visibility || !r.decoupled) return;
    Gpu& gpu = *r.gpu;
    VisibilityState& v = *r.visibility;
    uint32_t display = r.tonemapFused ? 1u : 0u;
    if (v.resolveInline[display].pipeline) return;
    std::string suffix = display ? "Display" : "";
    std::pair<uint32_t, uint32_t> output{RESOLVE_DISPLAY_OUTPUT_CONSTANT_ID, display};
    std::vector<std::pair<uint32_t, uint32_t>> inlineRebuild =
        shaderPrintSpecialization(r.settings.inspectX >= 0);
    inlineRebuild.push_back({RESOLVE_REBUILD_INLINE_CONSTANT_ID, 1u});
    inlineRebuild.push_back(output);
    std::vector<ComputePipelineDesc> descs = {
        {"shadelResolveInlineRebuild" + suffix, "shadel_resolve.comp.spv", inlineRebuild}};
    if (v.rebuildList) {
        descs.push_back({"shadelResolve" + suffix,
                         "shadel_resolve.comp.spv",
                         {{RESOLVE_REBUILD_INLINE_CONSTANT_ID, 0u}, output}});
        descs.push_back(
            {"shadelResolveRebuild" + suffix, "shadel_resolve_rebuild.comp.spv", {output}});
    }
    std::vector<Pipeline> built = createComputePipelines(gpu, descs); // side by side
    v.resolveInline[display] = built[0];
    if (v.rebuildList) {
        v.resolve[display] = built[1];
        v.resolveRebuild[display] = built[2];
    }
}

void recordResolveCompute(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    // Shade storage (buffers) written by shadelShading and carry-over, read here.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
    // The forward (hybrid) pixels hybridForward drew: kept, or read to be tonemapped.
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    VisibilityState& v = *r.visibility;
    ComputePush push = computePush(r, frame);
    // Debug views and --inspect rebuild every decoupled pixel: the resolve does it inline.
    bool inlineRebuild =
        !v.rebuildList || r.settings.visualize != Visualize::None || r.settings.inspectX >= 0;
    uint32_t output = r.tonemapFused ? 1u : 0u;
    if (inlineRebuild) {
        bind(gpu, cmd, v.resolveInline[output]);
        pushConstants(gpu, cmd, push);
        dispatchPixels(r, cmd);
    } else {
        // The resolve lists its rare pixels (misses, overflow, camera cuts); the rebuild pass
        // shades them.
        dispatchWithList(r, cmd, push, v.rebuildList, kRebuildListHeaderBytes, v.resolve[output],
                         v.resolveRebuildArgs, v.resolveRebuild[output]);
    }
    if (r.tonemapFused) { // the frame's display pixels, read back
        memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                      VK_ACCESS_2_HOST_READ_BIT);
        return;
    }
    // The scene colour, to the passes that draw into it or read it after (the tonemap).
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                 VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
}

void recordHybridForward(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    // Only the forward instances' pixels are kept (the resolve writes every other one), so last
    // frame's contents are discarded; the last reads of the target were last frame's.
    imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                 0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
    beginSceneColorPass(r, cmd, false);
    drawForwardLists(r, cmd, frame);
    vkCmdEndRendering(cmd);
}

} // namespace shadel
