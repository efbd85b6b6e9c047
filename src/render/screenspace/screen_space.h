#pragma once
// Seed 004's screen-space passes (--screen-space on): a sky pass, screen-space reflections
// (closest-depth pyramid march, the environment for misses and rough surfaces), separable skin
// subsurface scattering at half resolution, and their composite over the lit image. With
// --tile-classification on (render/tiles) each pass runs only on the 8x8 tiles whose class
// needs it, through indirect dispatch; off, every pass covers every tile and decides per pixel
// (the same result: a test holds them to 50 dB).
#include <nlohmann/json.hpp>

#include "rhi/frame.h"
#include "screenspace/screen_space_types.h"

namespace shadel {

struct Renderer;

void createScreenSpace(Renderer& r); // sets r.screenSpace when settings.screenSpace
void destroyScreenSpace(Renderer& r);
// After the prepass (all of it: occlusion's second phase too): the thin G-buffer.
void recordThinGBufferPass(Renderer& r, FrameRecorder& rec, uint64_t frame);
// After the opaque surfaces are lit, before transparency: classification and the passes.
void recordScreenSpacePasses(Renderer& r, FrameRecorder& rec, uint64_t frame);
// After the frame: the tile class counts; into the stats as "tile_classes".
void finishScreenSpaceFrame(Renderer& r);
// The push constants of the screen-space passes, for passes outside them (render/stencil).
gpu::ScreenSpacePush screenSpacePush(Renderer& r, uint64_t frame);
void screenSpaceStats(const Renderer& r, nlohmann::json& stats);

} // namespace shadel
