#pragma once
// 3-D debug lines (GPU-side debugging): shaders append world-space segments
// to one buffer (shaders/debug/debug_lines.glsl: debugLine, debugBox, debugSphere, ...) and this
// pass draws them over the frame, depth-tested, before tonemapping. `--debug-lines KIND,...`:
//   lights    light ranges, spot cones, tube segments (debugLinesEmit, one invocation per light)
//   blockers  blocker rectangles, their portals, and each listing light's shadow frustum
//   chunks    the world box of every shadel chunk shaded this frame (emitted by shadelShading)
// The buffer holds a fixed number of segments; what does not fit is counted and reported
// (stats `debug_lines`), never written.
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "rhi/frame.h"
#include "rhi/vk.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct DebugLinesState;
struct DebugLinesStateDeleter {
    void operator()(DebugLinesState* state) const;
};
using DebugLinesStatePtr = std::unique_ptr<DebugLinesState, DebugLinesStateDeleter>;

// "none" or a comma list of lights, blockers, chunks -> DEBUG_LINES_* bits (InputError else).
uint32_t parseDebugLines(const std::string& list);

// Null when RenderSettings::debugLines is 0.
DebugLinesStatePtr createDebugLines(Renderer& r);
void destroyDebugLines(Renderer& r, DebugLinesStatePtr& state);

// FrameConstants::debugLines: the line buffer's address, 0 when off.
uint64_t debugLinesAddress(const Renderer& r);
// First pass of the frame: empties the buffer (shaders may emit from any later pass).
void recordDebugLinesClear(Renderer& r, VkCommandBuffer cmd);
// Before tonemapping: `debugLinesEmit` (lights, blockers) and `debugLines` (the draw).
void recordDebugLinePasses(Renderer& r, FrameRecorder& rec, uint64_t frame, const GpuScene& scene,
                           uint32_t lightCount);
// After the frame: `debug_lines` {segments, dropped, capacity}.
void debugLinesStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
