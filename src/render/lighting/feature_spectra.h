#pragma once
// Feature spectra (seed 001, "Lighting Compute Optimization"): a shader with every lighting
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
//   --spectra single: the same pass with one all-features mode (the baseline the seed's
//                     spectra are measured against);
//   --spectra off:    the raster forward shading (the default).
//
// Decoupled mode ("the same for chunk queues"): shading is per 8x8-shadel chunk of the shading
// queue, culled against the chunk's world box (shaders/shadel/shade.comp). With --spectra
// on|single a classify permutation of the shadel shading runs over the queue first (carry-over
// decision, chunk light culling, the chunk's features, append to its mode's bin), then each
// mode's permutation of the same shader shades its bin by indirect dispatch
// (shaders/lighting/chunk_spectra.glsl). Stats "spectra" then count chunks, not tiles.
// Cost: the classify phase rebuilds every queued shadel's position and culls its chunk's lights,
// which the plain shading (--spectra off) does once, inside the shading. On lavapipe that mostly
// costs more than the permutations save: builtin:lights at 1280x720, decoupled frame with
// spectra 1.08x and 1.17x the frame without in two benches, 0.84x in a third (bench --spectra
// compare, 3 rounds each; 6 rounds later: on 558, single 635, off 492 ms, on / single 0.876).
// Where classify's 105-150 ms go (same place, variants swapped in, alternating runs; each
// figure moved 10-20% between runs):
//  - not the positions: chunk boxes baked per mesh and level (object space, transformed per
//    instance; tried, not kept) took it from 124-148 to 110-132 ms;
//  - 29 ms is the 64-invocation workgroup per queued chunk itself (~16,000 a frame: a variant
//    that bins each chunk with an empty list), ~30 more the grid query in every invocation, the
//    bit set's clear and compaction and their barriers (a variant that tests no candidate);
//  - the blocker tests of the kept lights, walked by one invocation, ~20-25 ms (a variant
//    without them: 86-92 against 105-117 ms); the light tests ~25 ms, and testing a third
//    fewer candidates (spots culled by their cone's sphere, light_cull.glsl) did not move it.
// Also measured: a barrier costs ~1.5 ms a frame there (16,000 chunks; the bare workgroup that
// only bins, 13-17 ms), and the blocker tests one kept light per invocation (two barriers more)
// gave the same lists and no measurable gain (classify 114-125 against 117-139 ms; tried, not
// kept). A classify on baked boxes needs no invocation per shadel (a workgroup of 8 chunks;
// not built). Both on and single pay classify, so on / single moves little: with classify
// free, (558 - 120) / (635 - 120) = 0.85.
// Where the permutations' gain comes from (same place, builtin:lights 1280x720, reuse off, the
// light lists emptied after classify as a measure only): shadelShading on 318 / single 383 ms
// with the lights, 87 / 141 ms without them. The light loops cost about the same in both
// (231 / 242 ms); the gain is the material and feature code outside the loop that the
// all-features permutation runs for every shadel. Modes added for the bins with superfluous
// area lights and PCSS (blocked tiles and chunks under shadowed spots, 18 modes) changed
// nothing measurable: tileShading 267-283 / 271-274 ms, shadelShading 312 / 316 ms.
#include <memory>

#include <nlohmann/json.hpp>

#include "rhi/vk.h"

namespace shadel {

struct Renderer;

enum class Spectra { Off, On, Single };

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
// "shadelChunkSpectra" (decoupled, before shadelShading): the classify permutation over the
// shading queue, then the bins' dispatch sizes.
void recordChunkSpectraClassify(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// Inside "shadelShading": every mode's shadel shading permutation over its bin (indirect).
void recordChunkSpectraShading(Renderer& r, VkCommandBuffer cmd, uint64_t frame);
// After the frame: tiles per spectrum, superfluous features, tiles per feature.
void readFeatureSpectraStats(Renderer& r);
void featureSpectraStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
