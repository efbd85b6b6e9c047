#include "render/oit/oit.h"

#include <algorithm>

#include "core/error.h"
#include "core/log.h"
#include "render/forward/forward_passes.h"
#include "render/particles/particles.h"
#include "render/shadel/decoupled.h"
#include "rhi/rendering.h"

namespace shadel {

struct OitState {
    std::vector<uint32_t> blended;      // instances with a blended material, scene order
    std::vector<uint32_t> draws;        // this frame's, in drawing order
    std::vector<gpu::GpuMesh> meshes;   // the scene's (draws are recorded from the CPU list)
    std::vector<uint32_t> instanceMesh; // per instance
    std::vector<uint8_t> doubleSided;   // per instance: its material's
    std::vector<uint32_t> drawSide;     // per instance: this frame's DRAW_SIDE_* (drawSideOf)
    // WBOIT targets: accumulation (sum of premultiplied colour * w, sum of coverage * w) and
    // revealage (R: product of 1 - opacity; G: the same over plain alpha layers; A: summed
    // additiveness).
    TextureHandle accum, reveal;
    RenderTargetView accumTarget, revealTarget;
    TextureReadView accumRead, revealRead;
    uint32_t decoupledDraws = 0; // blended instances shaded in shadel space this frame
    Pipeline accumulate, composite, sorted;
    Pipeline reconstruct; // decoupled mode: transparent surfaces read their shadels
};

void OitStateDeleter::operator()(OitState* state) const {
    delete state;
}

namespace {

VkPipelineColorBlendAttachmentState blendState(VkBlendFactor srcColor, VkBlendFactor dstColor,
                                               VkBlendFactor srcAlpha, VkBlendFactor dstAlpha) {
    VkPipelineColorBlendAttachmentState b{};
    b.blendEnable = VK_TRUE;
    b.srcColorBlendFactor = srcColor;
    b.dstColorBlendFactor = dstColor;
    b.colorBlendOp = VK_BLEND_OP_ADD;
    b.srcAlphaBlendFactor = srcAlpha;
    b.dstAlphaBlendFactor = dstAlpha;
    b.alphaBlendOp = VK_BLEND_OP_ADD;
    b.colorWriteMask = 0xF;
    return b;
}

void setViewport(VkCommandBuffer cmd, uint32_t w, uint32_t h) {
    VkViewport vp{0, 0, float(w), float(h), 0, 1};
    VkRect2D scissor{{0, 0}, {w, h}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

bool boxOutside(const std::array<glm::vec4, 6>& planes, glm::vec3 bmin, glm::vec3 bmax) {
    for (const glm::vec4& p : planes) {
        glm::vec3 v(p.x >= 0 ? bmax.x : bmin.x, p.y >= 0 ? bmax.y : bmin.y,
                    p.z >= 0 ? bmax.z : bmin.z);
        if (glm::dot(glm::vec3(p), v) + p.w < 0.0f) return true;
    }
    return false;
}

uint64_t splitmix(uint64_t& state) {
    uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

void drawInstance(VkCommandBuffer cmd, const gpu::GpuMesh& mesh, uint32_t instance) {
    vkCmdDrawIndexed(cmd, mesh.indexCount, 1, mesh.firstIndex, mesh.vertexOffset, instance);
}

} // namespace

std::vector<uint32_t> shuffledOrder(uint32_t n, uint64_t seed) {
    std::vector<uint32_t> order(n);
    for (uint32_t i = 0; i < n; ++i) order[i] = i;
    uint64_t state = seed;
    for (uint32_t i = n; i > 1; --i) std::swap(order[i - 1], order[splitmix(state) % i]);
    return order;
}

TextureHandle createWboitTarget(Gpu& gpu, const char* name, uint32_t width, uint32_t height) {
    TextureDesc t;
    t.name = name;
    t.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    t.width = width;
    t.height = height;
    t.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    TextureHandle h = createTexture(gpu, t);
    if (!h) throw DeviceError(format("out of GPU memory for the %s target", name));
    return h;
}

std::vector<VkPipelineColorBlendAttachmentState> wboitAttachmentBlends() {
    // Seed: "MRT0: (1)S + (1)D; MRT1: (0)S + (1-S)D for colour, (1)S + (1)D for alpha".
    return {blendState(VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE,
                       VK_BLEND_FACTOR_ONE),
            blendState(VK_BLEND_FACTOR_ZERO, VK_BLEND_FACTOR_ONE_MINUS_SRC_COLOR,
                       VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE)};
}

OitStatePtr createOit(Renderer& r, const GpuScene& scene) {
    OitStatePtr state(new OitState());
    OitState& o = *state;
    for (uint32_t i = 0; i < scene.instanceCount; ++i) {
        uint32_t m = scene.instanceInfo[i].material;
        if (m < scene.materialInfo.size() &&
            (scene.materialInfo[m].flags & MATERIAL_ALPHA_BLEND) != 0u)
            o.blended.push_back(i);
    }
    bool particles = r.settings.particles && !scene.emitters.empty(); // they draw into the targets
    if (o.blended.empty() && !particles) return nullptr;
    o.meshes = scene.meshInfo;
    for (uint32_t i = 0; i < scene.instanceCount; ++i)
        o.instanceMesh.push_back(scene.instanceInfo[i].mesh);
    for (uint32_t i = 0; i < scene.instanceCount; ++i) {
        uint32_t m = scene.instanceInfo[i].material;
        o.doubleSided.push_back(m < scene.materialInfo.size() &&
                                (scene.materialInfo[m].flags & MATERIAL_DOUBLE_SIDED) != 0u);
    }
    Gpu& gpu = *r.gpu;

    o.accum = createWboitTarget(gpu, "oit.accumulation", r.internalWidth, r.internalHeight);
    o.reveal =
        createWboitTarget(gpu, "oit.revealageAdditiveness", r.internalWidth, r.internalHeight);
    o.accumTarget = createRenderTargetView(gpu, o.accum);
    o.revealTarget = createRenderTargetView(gpu, o.reveal);
    o.accumRead = createReadView(gpu, o.accum);
    o.revealRead = createReadView(gpu, o.reveal);

    GraphicsPipelineDesc acc;
    acc.name = "oitAccumulate";
    acc.vertexShader = "forward_forward.vert.spv";
    acc.fragmentShader = "oit_accumulate.frag.spv";
    acc.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT};
    acc.depthFormat = VK_FORMAT_D32_SFLOAT;
    acc.depthWrite = false; // against the opaque depth only, never against each other
    acc.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    acc.dynamicCulling = true; // per instance (drawInstance) or list side (drawCameraList)
    acc.attachmentBlends = wboitAttachmentBlends();
    o.accumulate = createGraphicsPipeline(gpu, acc);
    if (r.settings.mode == RenderMode::Decoupled) {
        GraphicsPipelineDesc recon = acc;
        recon.name = "oitReconstruct";
        recon.fragmentShader = "oit_reconstruct.frag.spv";
        o.reconstruct = createGraphicsPipeline(gpu, recon);
    }

    GraphicsPipelineDesc comp;
    comp.name = "oitComposite";
    comp.vertexShader = "oit_fullscreen.vert.spv";
    comp.fragmentShader = "oit_composite.frag.spv";
    comp.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    comp.depthTest = false;
    comp.depthWrite = false;
    comp.cullMode = VK_CULL_MODE_NONE;
    comp.attachmentBlends = {blendState(VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                                        VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA)};
    o.composite = createGraphicsPipeline(gpu, comp);

    // Sorted reference: premultiplied "over"; each instance's back faces (double-sided
    // materials), then its front faces (exact for convex shapes such as the glass sphere).
    GraphicsPipelineDesc sorted;
    sorted.name = "sortedTransparency";
    sorted.vertexShader = "forward_forward.vert.spv";
    sorted.fragmentShader = "oit_sorted.frag.spv";
    sorted.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    sorted.depthFormat = VK_FORMAT_D32_SFLOAT;
    sorted.depthWrite = false;
    sorted.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    sorted.dynamicCulling = true; // back faces, then front faces (recordTransparencyPasses)
    sorted.attachmentBlends = {blendState(VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
                                          VK_BLEND_FACTOR_ONE,
                                          VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA)};
    o.sorted = createGraphicsPipeline(gpu, sorted);
    return state;
}

void destroyOit(Renderer& r, OitStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    OitState& o = *state;
    for (Pipeline* p : {&o.accumulate, &o.composite, &o.sorted}) destroy(gpu, *p);
    if (o.reconstruct.pipeline) destroy(gpu, o.reconstruct);
    destroy(gpu, o.accumTarget);
    destroy(gpu, o.revealTarget);
    destroy(gpu, o.accumRead);
    destroy(gpu, o.revealRead);
    destroy(gpu, o.accum);
    destroy(gpu, o.reveal);
    state.reset();
}

void prepareTransparentDraws(Renderer& r, const GpuScene& scene, const CameraView& camera) {
    if (!r.oit) return;
    OitState& o = *r.oit;
    o.draws.clear();
    auto planes = frustumPlanes(camera.proj * camera.view);
    o.decoupledDraws = 0;
    o.drawSide.resize(scene.instanceCount);
    for (uint32_t i : o.blended) {
        const gpu::GpuInstance& inst = scene.instanceInfo[i];
        o.drawSide[i] = drawSideOf(o.doubleSided[i], inst.model); // the transform may animate
        if (drawnDecoupled(r, i)) {
            o.decoupledDraws++; // the GPU lists it (DRAW_LIST_DECOUPLED_BLEND)
            continue;
        }
        if (!boxOutside(planes, inst.worldMin, inst.worldMax)) o.draws.push_back(i);
    }
    if (r.settings.shuffleDraws) {
        std::vector<uint32_t> order =
            shuffledOrder(uint32_t(o.draws.size()), r.settings.shuffleSeed);
        std::vector<uint32_t> shuffled(o.draws.size());
        for (size_t k = 0; k < order.size(); ++k) shuffled[k] = o.draws[order[k]];
        o.draws = std::move(shuffled);
    }
    if (r.settings.oit == OitMode::Sorted) {
        // Back to front by the view depth of the bounds' centre; ties by instance id, so the
        // reference does not depend on --shuffle-draws.
        glm::vec3 forward = -glm::vec3(glm::transpose(camera.view)[2]);
        std::vector<std::pair<float, uint32_t>> keyed;
        for (uint32_t i : o.draws) {
            const gpu::GpuInstance& inst = scene.instanceInfo[i];
            glm::vec3 c = 0.5f * (inst.worldMin + inst.worldMax);
            keyed.push_back({glm::dot(c - camera.position, forward), i});
        }
        std::sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) {
            return a.first != b.first ? a.first > b.first : a.second < b.second;
        });
        for (size_t k = 0; k < keyed.size(); ++k) o.draws[k] = keyed[k].second;
    }
}

uint32_t decoupledTransparentDraws(const Renderer& r) {
    return r.oit ? r.oit->decoupledDraws : 0u;
}

const std::vector<uint32_t>& transparentDrawOrder(const Renderer& r) {
    static const std::vector<uint32_t> none;
    return r.oit ? r.oit->draws : none;
}

void beginWboitTargets(Renderer& r, VkCommandBuffer cmd, bool clear) {
    Gpu& gpu = *r.gpu;
    OitState& o = *r.oit;
    for (TextureHandle t : {o.accum, o.reveal}) {
        if (clear)
            imageBarrier(
                cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                0, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
        else // blending onto what an earlier pass accumulated
            imageBarrier(
                cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
    }
    VkRenderingAttachmentInfo color[2]{};
    RenderTargetView views[2] = {o.accumTarget, o.revealTarget};
    for (int k = 0; k < 2; ++k) {
        color[k].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        color[k].imageView = vkView(gpu, views[k]);
        color[k].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        color[k].loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        color[k].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    }
    color[0].clearValue.color = {{0.0f, 0.0f, 0.0f, 0.0f}};
    color[1].clearValue.color = {{1.0f, 1.0f, 0.0f, 0.0f}}; // nothing hides, nothing adds
    VkRenderingAttachmentInfo depth{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    depth.imageView = vkView(gpu, r.depthTarget);
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
    ri.renderArea = {{0, 0}, {r.internalWidth, r.internalHeight}};
    ri.layerCount = 1;
    ri.colorAttachmentCount = 2;
    ri.pColorAttachments = color;
    ri.pDepthAttachment = &depth;
    vkCmdBeginRendering(cmd, &ri);
    setViewport(cmd, r.internalWidth, r.internalHeight);
}

// The scene colour and depth were last written by earlier passes' attachments.
static void afterOpaquePasses(VkCommandBuffer cmd) {
    memoryBarrier(cmd,
                  VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                      VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT |
                      VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                      VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

bool transparencyThisFrame(const Renderer& r) {
    return r.oit && (!r.oit->draws.empty() || r.oit->decoupledDraws != 0 || particlesThisFrame(r));
}

void recordTransparencyPasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!transparencyThisFrame(r)) return;
    Gpu& gpu = *r.gpu;
    OitState& o = *r.oit;
    auto meshOf = [&](uint32_t instance) -> const gpu::GpuMesh& {
        return o.meshes[o.instanceMesh[instance]];
    };

    if (r.settings.oit == OitMode::Sorted) {
        pass(rec, "sortedTransparency", [&, frame, meshOf](VkCommandBuffer cmd) {
            afterOpaquePasses(cmd);
            beginSceneColorPass(r, cmd, false);
            setViewport(cmd, r.internalWidth, r.internalHeight);
            vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
            bind(gpu, cmd, o.sorted);
            pushConstants(gpu, cmd, RasterPush{frame, 0});
            for (uint32_t i : o.draws) {
                // A double-sided instance's back faces, then its front faces; a single-sided
                // one's front faces only.
                setDrawSide(cmd, o.drawSide[i]); // its front face
                if (o.doubleSided[i]) {
                    vkCmdSetCullMode(cmd, VK_CULL_MODE_FRONT_BIT);
                    drawInstance(cmd, meshOf(i), i);
                }
                vkCmdSetCullMode(cmd, VK_CULL_MODE_BACK_BIT);
                drawInstance(cmd, meshOf(i), i);
            }
            vkCmdEndRendering(cmd);
        });
        return;
    }

    pass(rec, "oitAccumulate", [&, frame, meshOf](VkCommandBuffer cmd) {
        afterOpaquePasses(cmd);
        beginWboitTargets(r, cmd, true);
        bind(gpu, cmd, o.accumulate);
        pushConstants(gpu, cmd, RasterPush{frame, 0});
        vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
        for (uint32_t i : o.draws) {
            setDrawSide(cmd, o.drawSide[i]);
            drawInstance(cmd, meshOf(i), i);
        }
        if (o.decoupledDraws) { // reconstructed from shadel space into the same targets
            bind(gpu, cmd, o.reconstruct);
            pushConstants(gpu, cmd, RasterPush{frame, 0});
            drawCameraList(r, cmd, DRAW_LIST_DECOUPLED_BLEND);
        }
        vkCmdEndRendering(cmd);
    });
    recordParticleSprites(r, rec, frame); // GPU particles, into the same targets

    pass(rec, "oitComposite", [&, frame](VkCommandBuffer cmd) {
        for (TextureHandle t : {o.accum, o.reveal})
            imageBarrier(
                cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        beginRendering(cmd, r.internalWidth, r.internalHeight, {{vkView(gpu, r.hdrTarget)}});
        bind(gpu, cmd, o.composite);
        struct {
            uint64_t frame;
            uint32_t accumSlot, revealSlot, halfAccumSlot, halfRevealSlot;
        } push{frame, slot(gpu, o.accumRead).value, slot(gpu, o.revealRead).value, NO_TEXTURE,
               NO_TEXTURE};
        particleHalfResTargets(r, push.halfAccumSlot, push.halfRevealSlot);
        pushConstants(gpu, cmd, push);
        vkCmdDraw(cmd, 3, 1, 0, 0);
        vkCmdEndRendering(cmd);
    });
}

} // namespace shadel
