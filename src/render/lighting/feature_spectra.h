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
// Decoupled mode (the same idea over the chunk queue): shading is per 8x8-shadel chunk of the shading
// queue, culled against the chunk's world box (shaders/shadel/shade.comp). With --spectra
// on|single a classify pass runs over the queue first, one invocation per chunk
// (shaders/lighting/chunk_classify.comp: carry-over decision, the chunk's box from its 64
// positions, light culling, the chunk's features, append to its mode's bin, its list kept for
// the shading), then each mode's permutation of the shadel shading shades its bin by indirect
// dispatch, reading that list (shaders/lighting/chunk_spectra.glsl). Stats "spectra" then count
// chunks, not tiles.
// Classify was first a permutation of the shading itself: an 8x8 workgroup per chunk whose 64
// invocations each rebuilt a position and shared the culling through shared memory and
// barriers. On builtin:lights at 1280x720 (lavapipe) that took 105-150 ms of a ~600 ms frame,
// and variants showed where: not the positions (chunk boxes baked per mesh and level took it to
// 110-132 ms), but ~29 ms for the bare workgroup per chunk (~16,000 a frame), ~30 the grid's
// shared bit set, its compaction and their barriers (a barrier there cost ~1.5 ms a frame),
// ~20-25 the blocker tests walked by one invocation, ~25 the light tests. One invocation per
// chunk pays none of the workgroup's costs: each walks its chunk's 64 positions, its ~100 grid
// candidates (a light listed in several cells kept once, by a sorted insert) and its ~14 kept
// lights' blockers beside 63 other chunks. Alternating runs against the workgroup classify
// (same command, reuse off, spectra on): classify 31.4 / 33.0 ms against 93.3 / 88.7, the same
// (light, chunk) pairs (220,533) and image; 42 of the 16,174 chunks keep more than 64 lights
// (coarse levels' large chunks; their lists now come from chunk_long_lists.comp). bench --spectra
// compare (1280x720, 4 frames, timing submit), the old build's 3 rounds then this one's 6, the
// host in the same state: decoupled frame on 397.9 -> 340.6 ms, single 428.2 -> 382.2, off
// 364.4 / 375.6; on / single 0.930 -> 0.896, on / off 1.092 -> 0.907 (spectra now cost less
// than no spectra). The permutations' own gain is what is left: 37 ms of shading.
// Tried, not kept: the lists with the lights that read no texture first and a permutation
// looping over those without that code (kSpectrumLightSplit, as forward tiles): shadelShading
// 236-237 ms against 236-243 without (alternating runs), no gain.
// Where the permutations' gain comes from (same place, builtin:lights 1280x720, reuse off, the
// light lists emptied after classify as a measure only): shadelShading on 318 / single 383 ms
// with the lights, 87 / 141 ms without them. The light loops cost about the same in both
// (231 / 242 ms); the gain is the material and feature code outside the loop that the
// all-features permutation runs for every shadel. Modes added for the bins with superfluous
// area lights and PCSS (blocked tiles and chunks under shadowed spots, 18 modes) changed
// nothing measurable: tileShading 267-283 / 271-274 ms, shadelShading 312 / 316 ms.
// The permutations carry no barrier: they read their chunk's list from the pool (no copy to
// shared memory), never cull again (long lists have their own pass; a list that overflows the
// pool takes every light), and leave out the optional parts the renderer lacks. On lavapipe a
// shader with any barrier runs its SIMD groups as coroutines: alternating with the build that
// copied the list, builtin:lights 1280x720 spectra on frame 354-358 -> 301-312 ms,
// shadelShading 247-252 -> 193-202 ms, same pairs and image. bench --spectra compare, 6 rounds:
// decoupled on / single 0.898, on / off 0.755 (on 304.5, single 340.2, off 403.4 ms); forward
// on / single 0.813. The off path (the shading's own chunk culling in shared memory) costing
// 1.3x on is why --spectra auto turns them on in decoupled frames with more than 64 lights.
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
