#pragma once
// Projected box decals in stages (an AO-only kind makes a character's contact shadow): base
// colour, normal, roughness and ambient-occlusion decals applied to the material before
// lighting, in the material code both paths share (shaders/decals/decals.glsl).
//
// One culling pass builds every stage's list at once (one frustum cull, each
// decal that passes copied into the list of every stage it takes part in): the CPU keeps
// the decals meeting the camera frustum, then one compute pass gives each 16x16 screen tile
// (forward shading, and the shadel path's forward fallbacks) its lists, one per stage, in decal
// order, and, in decoupled mode, each instance the decals meeting its world bounds. Shadel
// shading narrows its object's list to each shadel's point (per-stage bit masks in registers,
// shaders/decals/decals.glsl useShadelDecalList) and applies it, so a decal is evaluated once
// per shadel and reused with the shadel; shadels of objects no decal meets test nothing.
//
// Why not a list per queued chunk: the pass doing it rebuilt every chunk's 64 shadel positions
// (ID map, indices, vertices) and reduced them to a box with shared atomics and barriers, only
// for shading to rebuild the same positions right after; at 1280x720 on builtin:decals it cost
// about two thirds of shadelShading itself. Every prefilter sample evaluates the material at the
// shadel's one point, so the per-shadel test is exact and costs a few box tests per shadel.
#include <cstdint>
#include <memory>

#include <nlohmann/json_fwd.hpp>

#include "common/shared_types.h"
#include "rhi/frame.h"
#include "scene/decal.h"

namespace shadel {

struct Renderer;
struct GpuScene;

struct DecalState;
struct DecalStateDeleter {
    void operator()(DecalState* state) const;
};
using DecalStatePtr = std::unique_ptr<DecalState, DecalStateDeleter>;

// Null when --decals off or the scene has none (then nothing is culled or applied).
DecalStatePtr createDecals(Renderer& r, const GpuScene& scene);
void destroyDecals(Renderer& r, DecalStatePtr& state);
// The decal as the GPU sees it (box transform, orthonormal axes).
gpu::GpuDecal gpuDecal(const Decal& decal);
// This frame's DecalFrame (the decals meeting the camera frustum); its address for
// FrameConstants::decals, 0 without decals.
uint64_t prepareDecalFrame(Renderer& r, const gpu::FrameConstants& constants);
// The "decalCulling" pass: every tile's lists, then (decoupled) every instance's. Forward:
// after the depth prepass, before shading; decoupled: after the work queues, before shading.
void recordDecalCulling(Renderer& r, FrameRecorder& rec, uint64_t frame);
// After the frame: the counters (decals_visible, decal_tile_pairs, ...).
void readDecalStats(Renderer& r);
void decalStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
