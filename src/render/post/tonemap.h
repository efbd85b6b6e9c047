#pragma once
// Tonemapping + SSAA resolve + coverage: HDR target -> RGBA8 pixels in a readback buffer.
//
// Fused (--fuse-tonemap on, the default): when no pass after the opaque shading pass draws into
// the scene colour (no blended materials, particles, screen-space or stencil passes, points and
// lines, debug lines; --ssaa 1; the forward pass or the decoupled compute resolve), that pass
// writes the display pixels itself and the tonemap pass does not run. Forward shading writes
// display colour into an RGBA8 target, copied into the readback ("displayReadback"); the
// decoupled compute resolve writes the readback directly (shaders/shadel/resolve.comp). Same
// curve, same encoding (shaders/common/tone_curve.glsl): the images match the separate pass's
// to within one level (the scene colour's half-float rounding is skipped).
#include <glm/vec3.hpp>

#include "rhi/vk.h"

namespace shadel {
struct Renderer;
void createTonemapPipeline(Renderer& r);
void recordTonemap(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// The scene colour and depth from attachments into the layouts compute passes sample them in
// (the tonemap, or the TAA resolve before it, which leaves them there for the tonemap).
void recordSceneTargetsForComputeReads(Renderer& r, VkCommandBuffer cmd);

// Whether this frame's tonemap is fused (see above): after the frame's draws are prepared.
bool tonemapFusedThisFrame(const Renderer& r);
// Forward frames may fuse it: they get the display target and its pipelines.
bool forwardMayFuseTonemap(const Renderer& r);
// Forward, fused: the display target forward shading wrote, copied into the readback.
void recordDisplayReadback(Renderer& r, VkCommandBuffer cmd);
} // namespace shadel
