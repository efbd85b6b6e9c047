#include "render/taa/taa.h"

#include <algorithm>
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/log.h"
#include "render/camera.h"
#include "render/post/tonemap.h"
#include "render/renderer.h"
#include "taa/taa_types.h"

namespace shadel {

// The blend's weight of the current frame once the history is long (about ten frames' memory).
constexpr float kCurrentWeight = 0.1f;
constexpr uint32_t kJitterPhases = 16;

struct TaaState {
    // Resolved colour (rgb) + inverse linear depth (a), one written per frame, the other read.
    TextureHandle history[2];
    TextureReadView historyRead[2];
    TextureWriteView historyWrite[2];
    TextureHandle sharpened; // --taa-sharpen above 0: what is displayed
    TextureReadView sharpenedRead;
    TextureWriteView sharpenedWrite;
    Pipeline resolve, sharpen;
    BufferHandle counters; // uint[TAA_COUNTER_COUNT], read back
    uint32_t written = 1;  // the history image the last frame wrote
    bool layoutsReady = false;
    // This frame's and the last frame's camera.
    uint64_t frameIndex = 0;
    glm::vec2 jitter{0.0f}, prevJitter{0.0f};
    glm::mat4 viewProj{1.0f}, prevViewProj{1.0f};
    uint32_t accumulated = 0; // frames in the history (0: none)
    // The last finished frame's counters.
    uint32_t rejected = 0, clipped = 0;
};

void TaaStateDeleter::operator()(TaaState* s) const {
    delete s;
}

bool taaEnabled(const RenderSettings& settings) {
    return settings.aa == AntiAliasing::Taa;
}

glm::vec2 taaJitter(uint64_t index) {
    return subpixelJitter(uint32_t(index % kJitterPhases));
}

glm::mat4 jitteredProjection(const glm::mat4& proj, glm::vec2 jitter, uint32_t width,
                             uint32_t height) {
    glm::mat4 p = proj;
    p[2][0] += jitter.x * 2.0f / float(width);
    p[2][1] += jitter.y * 2.0f / float(height);
    return p;
}

namespace {
TextureHandle createColourImage(Gpu& gpu, const char* name, uint32_t width, uint32_t height) {
    TextureDesc d;
    d.name = name;
    d.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    d.width = width;
    d.height = height;
    d.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
              VK_IMAGE_USAGE_TRANSFER_SRC_BIT; // --capture
    TextureHandle t = createTexture(gpu, d);
    if (!t) throw DeviceError(format("out of GPU memory for %s", name));
    return t;
}
} // namespace

TaaStatePtr createTaa(Renderer& r) {
    if (!taaEnabled(r.settings)) return nullptr;
    if (r.settings.ssaa != 1)
        throw InputError(format("--aa taa with --ssaa %u: TAA resolves one sample per pixel; use "
                                "one of them",
                                r.settings.ssaa));
    Gpu& gpu = *r.gpu;
    TaaStatePtr s(new TaaState);
    const char* names[2] = {"taa.history0", "taa.history1"};
    for (int i = 0; i < 2; ++i) {
        s->history[i] = createColourImage(gpu, names[i], r.internalWidth, r.internalHeight);
        s->historyRead[i] = createReadView(gpu, s->history[i]);
        s->historyWrite[i] = createWriteView(gpu, s->history[i]);
    }
    if (r.settings.taaSharpen > 0.0f) {
        s->sharpened = createColourImage(gpu, "taa.sharpened", r.internalWidth, r.internalHeight);
        s->sharpenedRead = createReadView(gpu, s->sharpened);
        s->sharpenedWrite = createWriteView(gpu, s->sharpened);
        s->sharpen = createComputePipeline(gpu, "taaSharpen", "taa_sharpen.comp.spv");
    }
    s->resolve = createComputePipeline(gpu, "taaResolve", "taa_resolve.comp.spv");
    s->counters = createBuffer(gpu, {"taa.counters", TAA_COUNTER_COUNT * sizeof(uint32_t),
                                     VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback});
    if (!s->counters) throw DeviceError("out of GPU memory for the TAA counters");
    TaaState* state = s.get();
    registerTextureCapture(
        r.captures, gpu, "taa", "the TAA resolve: colour (rgb) + inverse depth (a) (EXR)",
        CaptureKind::Hdr, [state] { return state->history[state->written]; },
        VK_IMAGE_LAYOUT_GENERAL);
    return s;
}

void destroyTaa(Renderer& r, TaaStatePtr& s) {
    if (!s) return;
    Gpu& gpu = *r.gpu;
    for (int i = 0; i < 2; ++i) {
        destroy(gpu, s->historyRead[i]);
        destroy(gpu, s->historyWrite[i]);
        destroy(gpu, s->history[i]);
    }
    if (s->sharpened) {
        destroy(gpu, s->sharpenedRead);
        destroy(gpu, s->sharpenedWrite);
        destroy(gpu, s->sharpened);
        destroy(gpu, s->sharpen);
    }
    destroy(gpu, s->resolve);
    destroy(gpu, s->counters);
    s.reset();
}

CameraView prepareTaaFrame(Renderer& r, const CameraView& camera) {
    TaaState& s = *r.taa;
    s.prevViewProj = s.viewProj;
    s.viewProj = camera.proj * camera.view;
    s.prevJitter = s.jitter;
    s.jitter = taaJitter(s.frameIndex++);
    CameraView jittered = camera;
    jittered.proj = jitteredProjection(camera.proj, s.jitter, r.internalWidth, r.internalHeight);
    return jittered;
}

CameraView taaNextFrameView(const Renderer& r, const CameraView& camera) {
    CameraView jittered = camera;
    jittered.proj = jitteredProjection(camera.proj, taaJitter(r.taa->frameIndex), r.internalWidth,
                                       r.internalHeight);
    return jittered;
}

namespace {
// The scene colour and depth into the layouts the tonemap reads them in (it does not move them
// with TAA on), the history images into GENERAL once.
void taaBarriersBefore(Renderer& r, TaaState& s, VkCommandBuffer cmd) {
    Gpu& gpu = *r.gpu;
    recordSceneTargetsForComputeReads(r, cmd);
    if (!s.layoutsReady) {
        for (TextureHandle t : {s.history[0], s.history[1], s.sharpened})
            if (t)
                imageBarrier(cmd, vkImage(gpu, t), VK_IMAGE_ASPECT_COLOR_BIT,
                             VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL,
                             VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                             VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        s.layoutsReady = true;
    }
    vkCmdFillBuffer(cmd, vkBuffer(gpu, s.counters), 0, VK_WHOLE_SIZE, 0);
    // Last frame's history writes, the tonemap's reads of them, the counters' clear.
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_READ_BIT |
                      VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
}

void recordResolve(Renderer& r, TaaState& s, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    taaBarriersBefore(r, s, cmd);
    uint32_t write = 1 - s.written;
    gpu::TaaResolvePush push{};
    push.prevViewProj = s.prevViewProj;
    push.frame = frame;
    push.counters = address(gpu, s.counters);
    push.jitter = s.jitter;
    push.prevJitter = s.prevJitter;
    push.width = r.internalWidth;
    push.height = r.internalHeight;
    push.hdrSlot = slot(gpu, r.hdrRead).value;
    push.depthSlot = slot(gpu, r.depthRead).value;
    push.historySlot = slot(gpu, s.historyRead[s.written]).value;
    push.outputSlot = slot(gpu, s.historyWrite[write]).value;
    // A running mean while the history is short (a still converges in as many frames as it
    // has), then the exponential blend.
    push.currentWeight = std::max(kCurrentWeight, 1.0f / float(s.accumulated + 1));
    push.flags = s.accumulated > 0 ? TAA_HISTORY_VALID : 0u;
    bind(gpu, cmd, s.resolve);
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, (r.internalWidth + TAA_GROUP_X - 1) / TAA_GROUP_X,
                  (r.internalHeight + TAA_GROUP_Y - 1) / TAA_GROUP_Y, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_2_HOST_BIT,
                  VK_ACCESS_2_SHADER_SAMPLED_READ_BIT | VK_ACCESS_2_HOST_READ_BIT);
}

void recordSharpen(Renderer& r, TaaState& s, VkCommandBuffer cmd, uint64_t frame) {
    Gpu& gpu = *r.gpu;
    gpu::TaaSharpenPush push{};
    push.frame = frame;
    push.width = r.internalWidth;
    push.height = r.internalHeight;
    push.inputSlot = slot(gpu, s.historyRead[1 - s.written]).value;
    push.outputSlot = slot(gpu, s.sharpenedWrite).value;
    push.amount = r.settings.taaSharpen;
    bind(gpu, cmd, s.sharpen);
    pushConstants(gpu, cmd, push);
    vkCmdDispatch(cmd, (r.internalWidth + TAA_GROUP_X - 1) / TAA_GROUP_X,
                  (r.internalHeight + TAA_GROUP_Y - 1) / TAA_GROUP_Y, 1);
    memoryBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                  VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
}
} // namespace

void recordTaaPasses(Renderer& r, FrameRecorder& rec, uint64_t frame) {
    TaaState& s = *r.taa;
    pass(rec, "taaResolve",
         [&r, &s, frame](VkCommandBuffer cmd) { recordResolve(r, s, cmd, frame); });
    if (s.sharpened)
        pass(rec, "taaSharpen",
             [&r, &s, frame](VkCommandBuffer cmd) { recordSharpen(r, s, cmd, frame); });
}

uint32_t taaDisplaySlot(const Renderer& r) {
    const TaaState& s = *r.taa;
    if (s.sharpened) return slot(*r.gpu, s.sharpenedRead).value;
    return slot(*r.gpu, s.historyRead[1 - s.written]).value; // (before finishTaaFrame)
}

void finishTaaFrame(Renderer& r) {
    TaaState& s = *r.taa;
    const uint32_t* counters = static_cast<const uint32_t*>(mapped(*r.gpu, s.counters));
    s.rejected = counters[TAA_COUNTER_REJECTED];
    s.clipped = counters[TAA_COUNTER_CLIPPED];
    s.written = 1 - s.written;
    s.accumulated++;
}

void resetTaaHistory(Renderer& r) {
    if (r.taa) r.taa->accumulated = 0;
}

void taaStats(const Renderer& r, nlohmann::json& stats) {
    if (!r.taa) {
        stats["taa"] = {{"enabled", false}};
        return;
    }
    const TaaState& s = *r.taa;
    double pixels = double(r.internalWidth) * r.internalHeight;
    stats["taa"] = {{"enabled", true},
                    {"sharpen", r.settings.taaSharpen},
                    {"jitter_phases", kJitterPhases},
                    {"current_weight", kCurrentWeight},
                    {"frames_accumulated", s.accumulated},
                    // The last frame's pixels whose history was rejected (disocclusion, off
                    // screen; every pixel of the first frame) or clipped to the neighbourhood.
                    {"rejected_share", s.rejected / pixels},
                    {"clipped_share", s.clipped / pixels}};
}

} // namespace shadel
