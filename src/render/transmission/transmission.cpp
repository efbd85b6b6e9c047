#include "render/transmission/transmission.h"

#include <algorithm>
#include <array>
#include <bit>
#include <vector>

#include "core/error.h"
#include "render/forward/forward_passes.h"
#include "render/renderer.h"
#include "rhi/rendering.h"

namespace shadel {

struct TransmissionState {
    std::vector<uint32_t> instances;    // transmissive instances, scene order
    std::vector<uint32_t> draws;        // this frame's
    std::vector<gpu::GpuMesh> meshes;   // the scene's (draws are recorded from the CPU list)
    std::vector<uint32_t> instanceMesh; // per instance
    std::vector<uint8_t> doubleSided;   // per instance: its material's
    std::vector<uint32_t> drawSide;     // per instance: this frame's DRAW_SIDE_* (drawSideOf)
    // The scene colour's copy behind the transmissive surfaces, with its whole MIP chain.
    TextureHandle background;
    TextureReadView backgroundRead;
    uint32_t levels = 1;
    Pipeline shading;
};

void TransmissionStateDeleter::operator()(TransmissionState* s) const {
    delete s;
}

namespace {

bool boxOutside(const std::array<glm::vec4, 6>& planes, glm::vec3 bmin, glm::vec3 bmax) {
    for (const glm::vec4& p : planes) {
        glm::vec3 v(p.x >= 0 ? bmax.x : bmin.x, p.y >= 0 ? bmax.y : bmin.y,
                    p.z >= 0 ? bmax.z : bmin.z);
        if (glm::dot(glm::vec3(p), v) + p.w < 0.0f) return true;
    }
    return false;
}

struct ShadingPush { // shaders/transmission/transmission.frag
    uint64_t frame;
    uint32_t shadowView;
    uint32_t backgroundSlot;
    uint32_t backgroundLevels;
};

// The scene colour into MIP 0 of the copy, then each MIP blitted (linear) from the one above;
// the copy ends readable by fragment shaders, the scene colour back as a colour attachment.
void recordBackgroundCopy(Renderer& r, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    TransmissionState& t = *r.transmission;
    VkImage hdr = vkImage(gpu, r.hdr), copy = vkImage(gpu, t.background);
    imageBarrier(cmd, hdr, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                 VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                 VK_ACCESS_2_TRANSFER_READ_BIT);
    // Last frame's reads of the copy were by the shading pass's fragments.
    imageBarrier(cmd, copy, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, 0,
                 VK_PIPELINE_STAGE_2_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, 0, t.levels);
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.extent = {r.internalWidth, r.internalHeight, 1};
    vkCmdCopyImage(cmd, hdr, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    int32_t w = int32_t(r.internalWidth), h = int32_t(r.internalHeight);
    for (uint32_t level = 1; level < t.levels; ++level) {
        imageBarrier(cmd, copy, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                     VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT, level - 1, 1);
        VkImageBlit blit{};
        blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level - 1, 0, 1};
        blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, level, 0, 1};
        blit.srcOffsets[1] = {w, h, 1};
        w = std::max(w / 2, 1), h = std::max(h / 2, 1);
        blit.dstOffsets[1] = {w, h, 1};
        vkCmdBlitImage(cmd, copy, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, copy,
                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
    }
    if (t.levels > 1)
        imageBarrier(cmd, copy, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                     VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                     VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                     VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, 0, t.levels - 1);
    imageBarrier(cmd, copy, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                 VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                 VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                 VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, t.levels - 1, 1);
    imageBarrier(cmd, hdr, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                 VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_TRANSFER_BIT,
                 VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                 VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT);
}

void recordShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    TransmissionState& t = *r.transmission;
    // The opaque passes' depth, to test and write against.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                      VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                  VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
    beginSceneColorPass(r, cmd, false);
    VkViewport vp{0, 0, float(r.internalWidth), float(r.internalHeight), 0, 1};
    VkRect2D scissor{{0, 0}, {r.internalWidth, r.internalHeight}};
    vkCmdSetViewport(cmd, 0, 1, &vp);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
    vkCmdBindIndexBuffer(cmd, vkBuffer(gpu, r.sceneIndices), 0, VK_INDEX_TYPE_UINT32);
    bind(gpu, cmd, t.shading);
    pushConstants(gpu, cmd, ShadingPush{frame, 0, slot(gpu, t.backgroundRead).value, t.levels});
    for (uint32_t i : t.draws) {
        setDrawSide(cmd, t.drawSide[i]);
        const gpu::GpuMesh& mesh = t.meshes[t.instanceMesh[i]];
        vkCmdDrawIndexed(cmd, mesh.indexCount, 1, mesh.firstIndex, mesh.vertexOffset, i);
    }
    vkCmdEndRendering(cmd);
}

} // namespace

TransmissionStatePtr createTransmission(Renderer& r, const GpuScene& scene) {
    TransmissionStatePtr state(new TransmissionState());
    TransmissionState& t = *state;
    for (uint32_t i = 0; i < scene.instanceCount; ++i) {
        uint32_t m = scene.instanceInfo[i].material;
        bool transmissive = m < scene.materialInfo.size() &&
                            (scene.materialInfo[m].flags & MATERIAL_TRANSMISSION) != 0u;
        bool doubleSided = m < scene.materialInfo.size() &&
                           (scene.materialInfo[m].flags & MATERIAL_DOUBLE_SIDED) != 0u;
        if (transmissive) t.instances.push_back(i);
        t.instanceMesh.push_back(scene.instanceInfo[i].mesh);
        t.doubleSided.push_back(doubleSided);
    }
    if (t.instances.empty()) return nullptr;
    t.meshes = scene.meshInfo;
    Gpu& gpu = *r.gpu;
    t.levels = uint32_t(std::bit_width(std::max(r.internalWidth, r.internalHeight)));
    TextureDesc desc;
    desc.name = "transmission.background";
    desc.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    desc.width = r.internalWidth;
    desc.height = r.internalHeight;
    desc.mipLevels = t.levels;
    desc.usage = VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                 VK_IMAGE_USAGE_SAMPLED_BIT;
    t.background = createTexture(gpu, desc);
    if (!t.background) throw DeviceError("out of GPU memory for the transmission background");
    t.backgroundRead = createReadView(gpu, t.background);

    GraphicsPipelineDesc p;
    p.name = "transmissionShading";
    p.vertexShader = "forward_forward.vert.spv";
    p.fragmentShader = "transmission_transmission.frag.spv";
    p.colorFormats = {VK_FORMAT_R16G16B16A16_SFLOAT};
    p.depthFormat = VK_FORMAT_D32_SFLOAT;
    p.depthWrite = true; // the nearest transmissive surface wins (they do not see each other)
    p.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    p.dynamicCulling = true;
    t.shading = createGraphicsPipeline(gpu, p);
    return state;
}

void destroyTransmission(Renderer& r, TransmissionStatePtr& s) {
    if (!s) return;
    Gpu& gpu = *r.gpu;
    destroy(gpu, s->shading);
    destroy(gpu, s->backgroundRead);
    destroy(gpu, s->background);
    s.reset();
}

void prepareTransmissionDraws(Renderer& r, const GpuScene& scene, const CameraView& camera) {
    if (!r.transmission) return;
    TransmissionState& t = *r.transmission;
    t.draws.clear();
    auto planes = frustumPlanes(camera.proj * camera.view);
    t.drawSide.resize(scene.instanceCount);
    for (uint32_t i : t.instances) {
        const gpu::GpuInstance& inst = scene.instanceInfo[i];
        t.drawSide[i] = drawSideOf(t.doubleSided[i], inst.model); // the transform may animate
        if (!boxOutside(planes, inst.worldMin, inst.worldMax)) t.draws.push_back(i);
    }
}

bool transmissionThisFrame(const Renderer& r) {
    return r.transmission && !r.transmission->draws.empty();
}

void recordTransmissionPasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    if (!transmissionThisFrame(r)) return;
    pass(rec, "transmissionBackground",
         [&r](VkCommandBuffer cmd) { recordBackgroundCopy(r, cmd); });
    pass(rec, "transmissionShading",
         [&r, frame](VkCommandBuffer cmd) { recordShading(r, cmd, frame); });
}

} // namespace shadel
