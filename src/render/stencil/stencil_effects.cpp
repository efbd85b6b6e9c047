#include "render/stencil/stencil_effects.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "core/error.h"
#include "core/log.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"
#include "render/screenspace/screen_space.h"
#include "render/stencil/screen_rects.h"
#include "stencil/stencil_bits.h"

namespace shadel {

namespace {
constexpr VkFormat kMaskFormat = VK_FORMAT_R8_UNORM;
constexpr VkPipelineStageFlags2 kFragmentTests =
    VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
constexpr VkPipelineStageFlags2 kFragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
constexpr VkAccessFlags2 kStorageReadWrite =
    VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr VkAccessFlags2 kDepthStencilReadWrite =
    VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
} // namespace

// One instance drawn by the marks: its LOD-0 index range (the default, LODs off).
struct MarkDraw {
    uint32_t indexCount, firstIndex;
    int32_t vertexOffset;
    uint32_t instance;
    glm::vec3 worldMin, worldMax;
    bool mirrored; // its transform mirrors: clockwise front faces
};

struct StencilEffectsState {
    StencilEffects mode = StencilEffects::On;
    VkFormat depthStencilFormat = VK_FORMAT_UNDEFINED;
    TextureHandle depthStencil, mask;
    VkImageView depthStencilView = VK_NULL_HANDLE; // both aspects (the rhi's depth views: depth)
    RenderTargetView maskTarget;
    TextureReadView maskRead;
    Pipeline depthCopy, markWater, markVisible, markHidden, water, outline;
    std::vector<MarkDraw> waterDraws, characterDraws;
};

void StencilEffectsStateDeleter::operator()(StencilEffectsState* s) const {
    delete s;
}

namespace {

// D32_SFLOAT_S8_UINT keeps the prepass depth bit for bit; D24S8 would round it (the equal test
// of the water mark would then miss), so it is the fallback only.
VkFormat pickDepthStencilFormat(const Gpu& gpu) {
    for (VkFormat f : {VK_FORMAT_D32_SFLOAT_S8_UINT, VK_FORMAT_D24_UNORM_S8_UINT}) {
        VkFormatProperties props{};
        vkGetPhysicalDeviceFormatProperties(gpu.device.physical, f, &props);
        if (props.optimalTilingFeatures & VK_FORMAT_FEATURE_DEPTH_STENCIL_ATTACHMENT_BIT) return f;
    }
    throw DeviceError("--stencil-effects: the device has no depth-stencil attachment format");
}

VkStencilOpState stencilOps(VkCompareOp compare, uint32_t bits, VkStencilOp pass) {
    VkStencilOpState s{};
    s.failOp = VK_STENCIL_OP_KEEP;
    s.depthFailOp = VK_STENCIL_OP_KEEP;
    s.passOp = pass;
    s.compareOp = compare;
    s.compareMask = bits;
    s.writeMask = pass == VK_STENCIL_OP_KEEP ? 0u : bits;
    s.reference = bits;
    return s;
}

VkPipelineColorBlendAttachmentState maskBlend(bool write) {
    VkPipelineColorBlendAttachmentState b{};
    b.colorWriteMask = write ? VkColorComponentFlags(VK_COLOR_COMPONENT_R_BIT) : 0u;
    b.blendEnable = write;
    b.srcColorBlendFactor = b.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
    b.colorBlendOp = VK_BLEND_OP_MAX; // a visible character wins over a hidden one
    b.srcAlphaBlendFactor = b.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
    b.alphaBlendOp = VK_BLEND_OP_MAX;
    return b;
}

void viewportAndScissor(VkCommandBuffer cmd, uint32_t w, uint32_t h) {
    VkViewport vp{0.0f, 0.0f, float(w), float(h), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, {w, h}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void beginDepthStencil(Renderer& r, StencilEffectsState& s, VkCommandBuffer cmd, bool mark,
                       VkRect2D area = {}) {
    if (mark || area.extent.width == 0) area = {{0, 0}, {r.internalWidth, r.internalHeight}};
    VkRenderingAttachmentInfo ds{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    ds.imageView = s.depthStencilView;
    ds.imageLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    ds.loadOp = mark ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    ds.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    ds.clearValue.depthStencil = {0.0f, 0};
    VkRenderingAttachmentInfo mask{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    mask.imageView = vkView(*r.gpu, s.maskTarget);
    mask.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    mask.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    mask.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = area;
    ri.layerCount = 1;
    ri.colorAttachmentCount = mark ? 1 : 0;
    ri.pColorAttachments = &mask;
    ri.pDepthAttachment = &ds;
    ri.pStencilAttachment = &ds;
    vkCmdBeginRendering(cmd, &ri);
    viewportAndScissor(cmd, r.internalWidth, r.internalHeight);
    vkCmdSetScissor(cmd, 0, 1, &area);
}

void drawMarks(Renderer& r, VkCommandBuffer cmd, const Pipeline& p,
               const std::vector<MarkDraw>& draws, uint64_t frame, bool cullBack) {
    if (draws.empty()) return;
    bind(*r.gpu, cmd, p);
    pushConstants(*r.gpu, cmd, RasterPush{frame, 0});
    for (const MarkDraw& d : draws) {
        setDrawSide(cmd, (cullBack ? DRAW_SIDE_FRONT : DRAW_SIDE_BOTH) +
                             (d.mirrored ? DRAW_SIDE_MIRRORED : 0u));
        vkCmdDrawIndexed(cmd, d.indexCount, 1, d.firstIndex, d.vertexOffset, d.instance);
    }
}

// Disjoint rects covering every pixel the instances' world boxes can cover (a coarse stand-in
// for hierarchical stencil: lavapipe tests the stencil per pixel, so a full-screen triangle over
// a few stencil pixels still costs a test per pixel; the rects keep the tests near them). The
// effects write only their own stencil pixels, which the instances cover, so a margin of a pixel
// for rounding is enough (the outline lies inside the silhouette).
std::vector<PixelRect> effectRects(const Renderer& r, const std::vector<MarkDraw>& draws,
                                   const glm::mat4& viewProj) {
    int w = int(r.internalWidth), h = int(r.internalHeight);
    std::vector<PixelRect> boxes;
    for (const MarkDraw& d : draws) {
        PixelRect box = projectedBoxRect(viewProj, d.worldMin, d.worldMax, w, h, 1);
        if (!box.empty()) boxes.push_back(box);
    }
    return disjointCover(boxes);
}

gpu::ScreenSpacePush effectPush(Renderer& r, const StencilEffectsState& s, uint64_t frame) {
    gpu::ScreenSpacePush push = screenSpacePush(r, frame);
    push.characterMaskSlot = slot(*r.gpu, s.maskRead).value;
    return push;
}

} // namespace

StencilEffectsStatePtr createStencilEffects(Renderer& r, const Scene& scene,
                                            const GpuScene& gpuScene, StencilEffects mode) {
    Gpu& gpu = *r.gpu;
    auto s = StencilEffectsStatePtr(new StencilEffectsState);
    s->mode = mode;
    s->depthStencilFormat = pickDepthStencilFormat(gpu);
    for (uint32_t i = 0; i < gpuScene.instanceInfo.size(); ++i) {
        const gpu::GpuInstance& inst = gpuScene.instanceInfo[i];
        const gpu::GpuMesh& mesh = gpuScene.meshInfo[inst.mesh];
        MarkDraw d{mesh.indexCount,
                   mesh.firstIndex,
                   mesh.vertexOffset,
                   i,
                   inst.worldMin,
                   inst.worldMax,
                   glm::determinant(glm::mat3(inst.model)) < 0.0f};
        uint32_t cls = (gpuScene.materialInfo[inst.material].flags >> MATERIAL_CLASS_SHIFT) &
                       MATERIAL_CLASS_MASK;
        if (cls == uint32_t(SurfaceClass::Water)) s->waterDraws.push_back(d);
        if (i < scene.instances.size() && scene.instances[i].character)
            s->characterDraws.push_back(d);
    }

    TextureDesc ds;
    ds.name = "stencil.depthStencil";
    ds.format = s->depthStencilFormat;
    ds.width = r.internalWidth;
    ds.height = r.internalHeight;
    ds.usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT;
    s->depthStencil = createTexture(gpu, ds);
    TextureDesc mask = ds;
    mask.name = "stencil.characterMask";
    mask.format = kMaskFormat;
    mask.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    s->mask = createTexture(gpu, mask);
    if (!s->depthStencil || !s->mask)
        throw DeviceError("out of GPU memory for the stencil effects' targets");
    VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    vi.image = vkImage(gpu, s->depthStencil);
    vi.viewType = VK_IMAGE_VIEW_TYPE_2D;
    vi.format = s->depthStencilFormat;
    vi.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT, 0, 1, 0, 1};
    VK_CHECK(vkCreateImageView(gpu.device.device, &vi, nullptr, &s->depthStencilView));
    setName(gpu.device, s->depthStencilView, VK_OBJECT_TYPE_IMAGE_VIEW,
            std::string("stencil.depthStencil.view"));
    s->maskTarget = createRenderTargetView(gpu, s->mask);
    s->maskRead = createReadView(gpu, s->mask);

    GraphicsPipelineDesc copy;
    copy.name = "stencilDepthCopy";
    copy.vertexShader = "oit_fullscreen.vert.spv";
    copy.fragmentShader = "stencil_depth_copy.frag.spv";
    copy.colorFormats = {kMaskFormat};
    copy.attachmentBlends = {maskBlend(false)};
    copy.depthFormat = s->depthStencilFormat;
    copy.depthCompare = VK_COMPARE_OP_ALWAYS;
    copy.cullMode = VK_CULL_MODE_NONE;
    s->depthCopy = createGraphicsPipeline(gpu, copy);

    // The marks: the prepass's vertex shader (invariant position: its depth exactly), no depth
    // writes, stencil bits set where the depth test passes.
    GraphicsPipelineDesc mark = copy;
    mark.vertexShader = "forward_forward.vert.spv";
    mark.fragmentShader = "stencil_character_mark.frag.spv";
    mark.depthWrite = false;
    mark.stencilTest = true;
    mark.dynamicCulling = true; // both sides for water, front faces for characters (drawMarks)
    mark.name = "stencilMarkWater";
    mark.depthCompare = VK_COMPARE_OP_EQUAL; // the visible water surface
    mark.stencil = stencilOps(VK_COMPARE_OP_ALWAYS, STENCIL_WATER, VK_STENCIL_OP_REPLACE);
    s->markWater = createGraphicsPipeline(gpu, mark);
    mark.name = "stencilMarkCharacterVisible";
    mark.attachmentBlends = {maskBlend(true)};
    mark.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL; // reversed Z: in front or the surface
    mark.stencil = stencilOps(VK_COMPARE_OP_ALWAYS, STENCIL_CHARACTER | STENCIL_CHARACTER_VISIBLE,
                              VK_STENCIL_OP_REPLACE);
    mark.specialization = {{0, std::bit_cast<uint32_t>(1.0f)}};
    s->markVisible = createGraphicsPipeline(gpu, mark);
    mark.name = "stencilMarkCharacterHidden";
    mark.depthCompare = VK_COMPARE_OP_LESS; // behind what the prepass kept
    mark.stencil = stencilOps(VK_COMPARE_OP_ALWAYS, STENCIL_CHARACTER, VK_STENCIL_OP_REPLACE);
    mark.specialization = {{0, std::bit_cast<uint32_t>(float(CHARACTER_MASK_HIDDEN))}};
    s->markHidden = createGraphicsPipeline(gpu, mark);

    // The effects: full-screen triangles, no colour attachment (they load and store the scene
    // colour as a storage image), the stencil test EQUAL to their bit unless full-screen.
    GraphicsPipelineDesc effect;
    effect.vertexShader = "oit_fullscreen.vert.spv";
    effect.depthFormat = s->depthStencilFormat;
    effect.depthTest = false;
    effect.depthWrite = false;
    effect.cullMode = VK_CULL_MODE_NONE;
    bool culled = mode != StencilEffects::FullScreen;
    effect.stencilTest = culled;
    effect.name = culled ? "waterComposite" : "waterCompositeFullScreen";
    effect.fragmentShader = "stencil_water_composite.frag.spv";
    effect.stencil = stencilOps(VK_COMPARE_OP_EQUAL, STENCIL_WATER, VK_STENCIL_OP_KEEP);
    s->water = createGraphicsPipeline(gpu, effect);
    effect.name = culled ? "characterOutline" : "characterOutlineFullScreen";
    effect.fragmentShader = "stencil_character_outline.frag.spv";
    effect.stencil = stencilOps(VK_COMPARE_OP_EQUAL, STENCIL_CHARACTER, VK_STENCIL_OP_KEEP);
    s->outline = createGraphicsPipeline(gpu, effect);
    SHADEL_INFO("stencil effects: %zu water and %zu character instances, %s", s->waterDraws.size(),
                s->characterDraws.size(),
                mode == StencilEffects::On            ? "stencil-culled in their screen rects"
                : mode == StencilEffects::OnUnbounded ? "stencil-culled, full-screen triangles"
                                                      : "full-screen");
    return s;
}

void destroyStencilEffects(Renderer& r, StencilEffectsState& s) {
    Gpu& gpu = *r.gpu;
    for (Pipeline* p :
         {&s.depthCopy, &s.markWater, &s.markVisible, &s.markHidden, &s.water, &s.outline})
        destroy(gpu, *p);
    destroy(gpu, s.maskTarget);
    destroy(gpu, s.maskRead);
    if (s.depthStencilView) vkDestroyImageView(gpu.device.device, s.depthStencilView, nullptr);
    destroy(gpu, s.mask);
    destroy(gpu, s.depthStencil);
}

uint32_t characterMaskSlot(const Renderer& r, const StencilEffectsState& s) {
    return slot(*r.gpu, s.maskRead).value;
}

void recordStencilEffects(Renderer& r, FrameRecorder& rec, uint64_t frame,
                          const glm::mat4& viewProj) {
    if (!r.stencilEffects || !r.screenSpace) return;
    StencilEffectsState& s = *r.stencilEffects;
    Gpu& gpu = *r.gpu;
    gpu::ScreenSpacePush push = effectPush(r, s, frame);
    VkImage depthStencil = vkImage(gpu, s.depthStencil);
    constexpr VkImageAspectFlags kBoth = VK_IMAGE_ASPECT_DEPTH_BIT | VK_IMAGE_ASPECT_STENCIL_BIT;

    pass(rec, "stencilMark", [&, push, depthStencil, frame](VkCommandBuffer cmd) {
        // The scene depth is sampled by the copy; the targets start undefined every frame.
        imageBarrier(cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kFragmentTests,
                     VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, kFragment,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        imageBarrier(cmd, depthStencil, kBoth, VK_IMAGE_LAYOUT_UNDEFINED,
                     VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, kFragmentTests,
                     kDepthStencilReadWrite, kFragmentTests, kDepthStencilReadWrite);
        imageBarrier(cmd, vkImage(gpu, s.mask), VK_IMAGE_ASPECT_COLOR_BIT,
                     VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, kFragment,
                     0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                         VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        beginDepthStencil(r, s, cmd, true);
        bind(gpu, cmd, s.depthCopy);
        pushConstants(gpu, cmd, push);
        vkCmdDraw(cmd, 3, 1, 0, 0);
        vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
        drawMarks(r, cmd, s.markWater, s.waterDraws, frame, false);
        // Front faces only: a character's far side is not "hidden".
        drawMarks(r, cmd, s.markVisible, s.characterDraws, frame, true);
        drawMarks(r, cmd, s.markHidden, s.characterDraws, frame, true);
        vkCmdEndRendering(cmd);
        imageBarrier(cmd, vkImage(gpu, r.depth), VK_IMAGE_ASPECT_DEPTH_BIT,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL, kFragment,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, kFragmentTests, kDepthStencilReadWrite);
        imageBarrier(
            cmd, vkImage(gpu, s.mask), VK_IMAGE_ASPECT_COLOR_BIT,
            VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
            VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
            kFragment, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        memoryBarrier(cmd, kFragmentTests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                      kFragmentTests, kDepthStencilReadWrite);
        // The effects load and store the scene colour as a storage image.
        imageBarrier(cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT,
                     VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                     VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, kFragment, kStorageReadWrite);
    });
    auto effect = [&](const char* name, const Pipeline& p, const std::vector<MarkDraw>& draws,
                      bool last) {
        // Stencil-culled: one full-screen triangle per disjoint rect its instances can cover,
        // each scissored to its rect (none when they are all off-screen); unbounded: one
        // triangle over the whole target, the stencil test alone culling; the full-screen
        // version covers the whole target without the stencil test, as its name says.
        bool bounded = s.mode == StencilEffects::On;
        const VkRect2D whole{{0, 0}, {r.internalWidth, r.internalHeight}};
        std::vector<VkRect2D> rects;
        if (bounded)
            for (const PixelRect& pr : effectRects(r, draws, viewProj))
                rects.push_back(
                    {{pr.x0, pr.y0}, {uint32_t(pr.x1 - pr.x0), uint32_t(pr.y1 - pr.y0)}});
        else
            rects.push_back(whole);
        // The render area: the rects' bounds (a pixel when there is nothing to draw).
        VkRect2D area{{0, 0}, {1, 1}};
        if (!rects.empty()) {
            int x0 = r.internalWidth, y0 = r.internalHeight, x1 = 0, y1 = 0;
            for (const VkRect2D& rc : rects) {
                x0 = std::min(x0, rc.offset.x);
                y0 = std::min(y0, rc.offset.y);
                x1 = std::max(x1, rc.offset.x + int(rc.extent.width));
                y1 = std::max(y1, rc.offset.y + int(rc.extent.height));
            }
            area = {{x0, y0}, {uint32_t(x1 - x0), uint32_t(y1 - y0)}};
        }
        pass(rec, name, [&, rects, area, last, push](VkCommandBuffer cmd) {
            beginDepthStencil(r, s, cmd, false, area);
            bind(gpu, cmd, p);
            pushConstants(gpu, cmd, push);
            for (const VkRect2D& rc : rects) {
                vkCmdSetScissor(cmd, 0, 1, &rc);
                vkCmdDraw(cmd, 3, 1, 0, 0);
            }
            vkCmdEndRendering(cmd);
            if (!last)
                memoryBarrier(cmd, kFragment, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, kFragment,
                              kStorageReadWrite);
            else // back to what transparency and tonemapping expect
                imageBarrier(
                    cmd, vkImage(gpu, r.hdr), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_GENERAL,
                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, kFragment, kStorageReadWrite,
                    VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        });
    };
    bool full = s.mode == StencilEffects::FullScreen;
    effect(full ? "waterCompositeFullScreen" : "waterComposite", s.water, s.waterDraws, false);
    effect(full ? "characterOutlineFullScreen" : "characterOutline", s.outline, s.characterDraws,
           true);
}

} // namespace shadel
