#pragma once
// Seed 004's stencil-culled effects (--stencil-effects on, with --screen-space on): a water
// composite (screen-space reflection + refraction tint) and a character outline with an
// occlusion tint (characters stay visible through walls), each a full-screen triangle that the
// early stencil test limits to its pixels. The stencil bits are written by `stencilMark` into a
// depth-stencil copy of the prepass depth (the scene depth is D32_SFLOAT, shared by every raster
// pipeline): the water instances where they are the visible surface, the character instances
// where they are seen and, with the depth test inverted, where they are hidden. The full-screen
// version (--stencil-effects fullscreen) runs the same shaders on every pixel without the
// stencil test, branching per pixel: the same image, the baseline of `bench --stencil-compare`.
// The culled effects draw only over their instances' screen rects (render/stencil/screen_rects).
#include <memory>

#include <glm/glm.hpp>

#include "rhi/frame.h"

namespace shadel {

struct Renderer;
struct Scene;
struct GpuScene;
struct StencilEffectsState;

struct StencilEffectsStateDeleter {
    void operator()(StencilEffectsState* s) const;
};
using StencilEffectsStatePtr = std::unique_ptr<StencilEffectsState, StencilEffectsStateDeleter>;

// On: the effects' triangles are scissored to disjoint rects covering their instances' projected
// boxes, so the stencil is tested only near them. OnUnbounded (--stencil-effects on-unbounded):
// one triangle over the whole target, the stencil test alone culling (the same image; the
// reference of the bounded draw in tests and benchmarks).
enum class StencilEffects : uint32_t { Off, On, FullScreen, OnUnbounded };

// Water instances by their material class, characters by Instance::character.
StencilEffectsStatePtr createStencilEffects(Renderer& r, const Scene& scene,
                                            const GpuScene& gpuScene, StencilEffects mode);
void destroyStencilEffects(Renderer& r, StencilEffectsState& s);
// After the screen-space passes, before transparency: stencilMark, waterComposite,
// characterOutline.
// `viewProj`: the camera's, for the screen rect the effects' instances can cover.
void recordStencilEffects(Renderer& r, FrameRecorder& rec, uint64_t frame,
                          const glm::mat4& viewProj);
// For the screen-space push constants: the character mask's sampled slot.
uint32_t characterMaskSlot(const Renderer& r, const StencilEffectsState& s);

} // namespace shadel
