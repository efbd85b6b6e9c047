#pragma once
// glTF points and lines primitives, drawn forward in both modes: they have no
// surface to parametrize, so the decoupled path never sees them. One pass after the opaque
// surfaces and the screen-space passes, before transparency: one-pixel points and lines
// (at the internal resolution), depth tested and written, unlit (glTF defines no lighting
// for them without normals): the material's base colour factor times COLOR_0. Their world
// positions are fixed at load (animated playback does not move them).
#include <memory>

#include "rhi/frame.h"
#include "scene/scene.h"

namespace shadel {

struct Renderer;

struct PointsLinesState;
struct PointsLinesStateDeleter {
    void operator()(PointsLinesState* s) const;
};
using PointsLinesStatePtr = std::unique_ptr<PointsLinesState, PointsLinesStateDeleter>;

// Null when the scene has no points or lines.
PointsLinesStatePtr createPointsLines(Renderer& r, const Scene& scene);
void destroyPointsLines(Renderer& r, PointsLinesState& s);
// The `pointsLines` pass (nothing without points or lines).
void recordPointsLines(Renderer& r, FrameRecorder& rec, uint64_t frame);
uint32_t pointsLinesVertexCount(const PointsLinesState& s);

} // namespace shadel
