// Push constants of the screen-space passes, shared by C++ (render/screenspace) and GLSL.
#ifndef SHADEL_SCREEN_SPACE_TYPES_H
#define SHADEL_SCREEN_SPACE_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

#define TILE_LIST_ALL 0xffffffffu // listOffset: dispatched over the whole tile grid
#define DEPTH_PYRAMID_LEVELS 6u   // closest-depth levels (0 = full resolution) the SSR march uses
// Roughness at which SSR starts to give way to the environment, and beyond which no pixel traces.
#define SSR_ROUGHNESS_FADE 0.2
#define SSR_MAX_ROUGHNESS 0.4

struct ScreenSpacePush {
    uint64_t frame;
    uint64_t tiles;  // the classification buffer (TileBufferHeader + lists)
    uint listOffset; // first entry of this dispatch's tile list, or TILE_LIST_ALL
    uint width;      // the internal resolution
    uint height;
    uint depthSlot;  // sampled: the scene depth
    uint normalSlot; // sampled: G-buffer normal (xyz) + roughness (w)
    uint flagsSlot;  // sampled: G-buffer flags + class (R8)
    uint hdrSlot;    // storage: the scene colour
    uint ssrSlot;    // storage: reflected radiance (rgb) + weight (a)
    uint sssSlot0;   // storage, half resolution: skin colour (rgb) + linear depth (a)
    uint sssSlot1;
    uint level;                         // depth pyramid build: the level written
    uint tilesX;                        // tiles per row (classification)
    uint pyramid[DEPTH_PYRAMID_LEVELS]; // storage R32UI: closest depth per level
    uint64_t distanceFields;            // DistanceFieldFrame (render/distance_fields), 0 when off
    uint dfSlot; // storage RGBA8: DF sun visibility, shadow-map visibility, DF AO
    // Stencil-culled effects (render/stencil): 1 when the water composite owns the water's
    // reflection (the screen-space composite then leaves it out), and the character mask.
    uint stencilEffects;
    uint characterMaskSlot; // sampled R8 (shaders/stencil/stencil_bits.h)
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
