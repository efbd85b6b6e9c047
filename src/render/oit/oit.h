#pragma once
// Transparency: weighted blended order-independent transparency with an
// additiveness channel (--oit wboit, the default), or a CPU-sorted back-to-front reference
// (--oit sorted) for tests. Transparent surfaces are the instances of blended materials; the
// CPU lists the visible ones each frame (in scene order, shuffled with --shuffle-draws, or
// sorted), and the passes below draw them after the opaque scene, before tonemapping.
#include <cstdint>
#include <vector>

#include "render/renderer.h"
#include "rhi/frame.h"

namespace shadel {

struct GpuScene;
struct CameraView;

// Null when the scene has no blended material (no targets, no passes).
OitStatePtr createOit(Renderer& r, const GpuScene& scene);
void destroyOit(Renderer& r, OitStatePtr& state);

// The frame's transparent draws: blended instances inside the camera frustum, in the order
// the mode needs (see above).
void prepareTransparentDraws(Renderer& r, const GpuScene& scene, const CameraView& camera);
// The order prepareTransparentDraws chose, as instance ids (tests, stats).
const std::vector<uint32_t>& transparentDrawOrder(const Renderer& r);

// Blended instances shaded in shadel space this frame (decoupled mode with wboit).
uint32_t decoupledTransparentDraws(const Renderer& r);

// wboit: `oitAccumulate` (two targets) then `oitComposite` over the scene colour; sorted:
// `sortedTransparency`. Nothing when the frame has no transparent draw (transparencyThisFrame
// false: after prepareTransparentDraws).
bool transparencyThisFrame(const Renderer& r);
void recordTransparencyPasses(Renderer& r, FrameRecorder& rec, uint64_t frame);

// The WBOIT targets as colour attachments over the opaque depth (cleared, or loaded to keep
// accumulating: the particle sprites of render/particles), and the blend states that
// accumulate into them.
void beginWboitTargets(Renderer& r, VkCommandBuffer cmd, bool clear);
std::vector<VkPipelineColorBlendAttachmentState> wboitAttachmentBlends();
// One WBOIT target (RGBA16F, attachment + sampled): accumulation or revealage/additiveness.
TextureHandle createWboitTarget(Gpu& gpu, const char* name, uint32_t width, uint32_t height);

// Deterministic permutation of [0, n) for --shuffle-draws (splitmix64 Fisher-Yates, identical on
// every standard library).
std::vector<uint32_t> shuffledOrder(uint32_t n, uint64_t seed);

} // namespace shadel
