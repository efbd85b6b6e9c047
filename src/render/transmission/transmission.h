#pragma once
// Transmissive surfaces (KHR_materials_transmission, KHR_materials_volume): instances of lit,
// unblended materials with a transmission factor above 0 (MATERIAL_TRANSMISSION) are in none
// of the opaque passes' camera lists. After every opaque surface, `transmissionBackground`
// copies the scene colour into a mipmapped target and `transmissionShading` draws them
// forward in both modes, depth tested and written, each pixel reading the copy where its
// refracted ray leaves the volume (shaders/transmission, shaders/common/transmission.glsl).
// Transmissive surfaces therefore do not see each other through the copy.
#include <cstdint>
#include <memory>

#include "rhi/frame.h"

namespace shadel {

struct Renderer;
struct GpuScene;
struct CameraView;

struct TransmissionState;
struct TransmissionStateDeleter {
    void operator()(TransmissionState* s) const;
};
using TransmissionStatePtr = std::unique_ptr<TransmissionState, TransmissionStateDeleter>;

// Null when the scene has no transmissive instance.
TransmissionStatePtr createTransmission(Renderer& r, const GpuScene& scene);
void destroyTransmission(Renderer& r, TransmissionStatePtr& s);

// The frame's transmissive draws: those inside the camera frustum, in scene order.
void prepareTransmissionDraws(Renderer& r, const GpuScene& scene, const CameraView& camera);
// Whether the frame has transmissive draws (false before prepareTransmissionDraws).
bool transmissionThisFrame(const Renderer& r);

// `transmissionBackground` then `transmissionShading` (nothing without transmissive draws).
void recordTransmissionPasses(Renderer& r, FrameRecorder& rec, uint64_t frame);

} // namespace shadel
