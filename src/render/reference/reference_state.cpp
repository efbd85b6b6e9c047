// The reference path tracer's resources (render/reference/reference.h): the accumulated mean,
// the pipeline, the capture, what a frame adds and the stats.
#include <cstring>

#include <nlohmann/json.hpp>

#include "core/log.h"
#include "reference/reference_types.h"
#include "render/reference/reference.h"
#include "render/reference/reference_state.h"
#include "render/renderer.h"

namespace shadel {

void ReferenceStateDeleter::operator()(ReferenceState* state) const {
    delete state;
}

static bool hasAlphaMaterials(const GpuScene& scene) {
    for (const gpu::GpuMaterial& m : scene.materialInfo)
        if (m.flags & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) return true;
    return false;
}

ReferenceStatePtr createReference(Renderer& r, const GpuScene& scene) {
    Gpu& gpu = *r.gpu;
    ReferenceStatePtr state(new ReferenceState);
    ReferenceState& s = *state;
    TextureDesc d;
    d.name = "reference.accumulation";
    d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    d.width = r.internalWidth;
    d.height = r.internalHeight;
    d.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    s.accumulation = createTexture(gpu, d);
    if (!s.accumulation) throw DeviceError("out of GPU memory for the reference accumulation");
    s.accumulationWrite = createWriteView(gpu, s.accumulation);
    s.hdrWrite = createWriteView(gpu, r.hdr);
    s.pathTrace = createComputePipeline(gpu, "referencePathTrace", "reference_path_trace.comp.spv");
    s.alpha = hasAlphaMaterials(scene);
    // The mean of every path so far (alpha: coverage), as the frame leaves it.
    registerTextureCapture(
        r.captures, gpu, "reference",
        "the reference path tracer's accumulated mean radiance (EXR; alpha: coverage)",
        CaptureKind::Hdr, [&s] { return s.accumulation; }, VK_IMAGE_LAYOUT_GENERAL);
    return state;
}

void destroyReference(Renderer& r, ReferenceStatePtr& state) {
    if (!state) return;
    Gpu& gpu = *r.gpu;
    ReferenceState& s = *state;
    destroy(gpu, s.pathTrace);
    destroy(gpu, s.accumulationWrite);
    destroy(gpu, s.hdrWrite);
    destroy(gpu, s.accumulation);
    state.reset();
}

void prepareReferenceFrame(Renderer& r, const CameraView& camera) {
    ReferenceState& s = *r.reference;
    // A moved camera (a camera path) sees another image: its mean starts again.
    bool moved = std::memcmp(&camera.view, &s.view, sizeof(s.view)) != 0 ||
                 std::memcmp(&camera.proj, &s.proj, sizeof(s.proj)) != 0;
    if (moved && s.samplesAccumulated > 0) ++s.restarts;
    if (moved) s.samplesAccumulated = 0;
    s.view = camera.view;
    s.proj = camera.proj;
}

void referenceStats(const Renderer& r, nlohmann::json& stats) {
    const ReferenceState& s = *r.reference;
    const ReferenceSettings& settings = r.settings.reference;
    stats["reference"] = {{"spp_total", s.samplesAccumulated},
                          {"spp_per_frame", settings.samplesPerFrame},
                          {"bounces", settings.maxBounces},
                          {"roulette_start", settings.rouletteStart},
                          {"seed", settings.seed},
                          {"alpha_tested_rays", s.alpha},
                          {"restarts", s.restarts}};
}

} // namespace shadel
