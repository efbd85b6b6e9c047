#include "render/shadel/decoupled.h"

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "render/renderer.h"

namespace shadel {

struct DecoupledState {};

void DecoupledStateDeleter::operator()(DecoupledState* state) const { delete state; }

DecoupledStatePtr createDecoupled(Renderer&, const GpuScene&) {
    throw InputError("--mode decoupled: not available yet (the decoupled path is being built; "
                     "use --mode forward)");
}
void destroyDecoupled(Renderer&, DecoupledStatePtr& state) { state.reset(); }
void prepareDecoupledFrame(Renderer&, const GpuScene&, const CameraView&, gpu::FrameConstants&) {}
void recordDecoupledPasses(Renderer&, FrameRecorder&, uint64_t, const GpuScene&) {}
void finishDecoupledFrame(Renderer&) {}
void decoupledStats(const Renderer&, nlohmann::json&) {}

} // namespace shadel
