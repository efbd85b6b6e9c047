#pragma once
// Feature spectra: a shader with every lighting
// feature compiled in pays for all of them everywhere (registers, occupancy, code). The tile
// pass (shaders/lighting/tile_cull.comp) records the features each 16x16 tile needs (light
// kinds, darks, clip planes, per-pixel blockers, portals, shadows, and whether any of its
// pixels' materials uses textures, procedurals, clear coat or sheen) and bins the tile into the
// first of a few shading modes, cheapest first, whose features cover them; each mode is a
// permutation of the tile shading compute (shaders/lighting/tile_shade.comp) compiled with only
// its features (specialization constants), run over its bin by an indirect dispatch.
//
// Forward mode only. The forward path shades in a raster pass, where a permutation cannot be
// chosen per screen tile without drawing the scene once per mode; so with --spectra on|single
// the forward frame becomes deferred-style per tile: the visibility prepass (instance,
// triangle per pixel, render/shadel/visibility.h) replaces the depth prepass, and the tile
// shading rebuilds each pixel's surface from it exactly as the raster varyings and
// derivatives give it, then runs the same evaluateMaterial + shadeSurface.
//   --spectra on:     the modes of kSpectrumModes, each tile in the cheapest covering one;
//   --spectra single: the same pass with one all-features mode (the baseline spectra
//                     are measured against);
//   --spectra off:    the raster forward shading (the default).
//
// Decoupled mode (the same idea over the chunk queue): shading is per 8x8-shadel chunk of the
// shading queue, culled against the chunk's world box (shaders/shadel/shade.comp). With --spectra
// on|single a classify pass runs over the queue first, one invocation per chunk
// (shaders/lighting/chunk_classify.comp: carry-over decision, the chunk's box from its 64
// positions, light culling, the chunk's features, append to its mode's bin, its list kept for
// the shading), then each mode's permutation of the shadel shading shades its bin by indirect
// dispatch, reading that list (shaders/lighting/chunk_spectra.glsl). Stats "spectra" then count
// chunks, not tiles.
// Classify runs one invocation per chunk, not a workgroup: each walks its chunk's 64 positions,
// its grid candidates (a light listed in several cells kept once, by a sorted insert) and its
// kept lights' blockers, so it pays no shared memory, barrier or per-workgroup cost. Chunks that
// keep more than 64 lights (coarse levels' large chunks) get their lists from
// chunk_long_lists.comp. The permutations carry no barrier either: they read their chunk's list
// from the pool (no copy to shared memory), never cull again (a list that overflows the pool
// takes every light) and leave out the optional parts the renderer lacks; on lavapipe a shader
// with any barrier runs its SIMD groups as coroutines. Their gain is the material and feature
// code outside the light loop that the all-features permutation runs for every shadel. The off
// path (the shading's own chunk culling in shared memory) costs more than on in decoupled frames
// with many lights, which is why --spectra auto turns spectra on in decoupled frames with more
// than 64 lights. docs/lighting/README.md has the measurements behind each of these choices.
#include <memory>

#include <nlohmann/json.hpp>

#include "rhi/vk.h"

namespace shadel {

struct Renderer;

// Auto (the default) is resolved when the renderer is made (renderer.cpp resolveSettings): On
// for decoupled
// frames that cull lights per chunk (tiled culling, more lights than per-subgroup lists take),
// where the classify pass and the permutations cost less than the shading's own chunk culling
// (builtin:lights 1280x720, lavapipe: frame 0.80-0.88 of spectra off); Off everywhere else
// (the raster forward pass; few lights, culled per subgroup).
enum class Spectra { Off, On, Single, Auto };

struct SpectraState;
struct SpectraStateDeleter {
    void operator()(SpectraState* state) const;
};
using SpectraStatePtr = std::unique_ptr<SpectraState, SpectraStateDeleter>;

// Whether the frame shades forward tiles by spectra (forward mode, --spectra on|single).
bool usesTileShading(const Renderer& r);
// Whether shadel chunks are shaded by spectra (decoupled mode, --spectra on|single).
bool usesChunkSpectra(const Renderer& r);

// After the light culling state and the visibility buffer (forward) or the decoupled state
// (its shading queue) exist: the mode permutations.
SpectraStatePtr createFeatureSpectra(Renderer& r);
void destroyFeatureSpectra(Renderer& r, SpectraStatePtr& state);

// This frame's SpectraFrame address (LightingFrame::spectra, or ::chunkSpectra when
// usesChunkSpectra), 0 without spectra.
uint64_t prepareFeatureSpectra(Renderer& r, uint32_t tilesX, uint32_t tilesY);
// Empties the bins before the tile pass fills them (recorded with the light culling clears).
void recordSpectraReset(Renderer& r, VkCommandBuffer cmd);
// "tileShading": every mode's permutation over its bin (indirect), into the HDR target.
void recordTileShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// "shadelChunkSpectra" (decoupled, before shadelShading): the classify pass over the shading
// queue (an invocation per chunk), then the bins' dispatch sizes.
void recordChunkSpectraClassify(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// Inside "shadelShading": every mode's shadel shading permutation over its bin (indirect).
void recordChunkSpectraShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// After the frame: tiles per spectrum, superfluous features, tiles per feature.
void readFeatureSpectraStats(Renderer& r);
void featureSpectraStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
