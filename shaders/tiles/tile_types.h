// Tile classification layouts shared by C++ (render/tiles) and GLSL (shaders/tiles).
#ifndef SHADEL_TILE_TYPES_H
#define SHADEL_TILE_TYPES_H

#ifdef __cplusplus
#include "common/shared_types.h"
namespace shadel::gpu {
#endif

#define TILE_SIZE 8u // pixels per side; one compute workgroup of every screen-space pass

// Per-pixel flags of the thin G-buffer (bits 0..3; the surface class sits in bits 4..6).
// Classification ORs and ANDs them over each tile.
#define PIXEL_SURFACE 1u // geometry (0: sky)
#define PIXEL_SMOOTH 2u  // smooth enough for screen-space reflections
#define PIXEL_SKIN 4u    // subsurface scattering
#define PIXEL_WATER 8u   // the water composite
#define PIXEL_CLASS_SHIFT 4u

// The per-permutation tile lists. A tile is in every list whose pass it needs.
#define TILE_LIST_SKY 0u       // every pixel is sky: only the sky pass, its all-sky permutation
#define TILE_LIST_SKY_EDGE 1u  // sky and surfaces: the sky pass tests each pixel
#define TILE_LIST_SURFACE 2u   // at least one surface: the composite
#define TILE_LIST_SSR 3u       // a surface smooth enough to trace
#define TILE_LIST_SSR_CLEAR 4u // surfaces, none smooth: SSR's clear-only permutation
#define TILE_LIST_SSS 5u       // skin
#define TILE_LIST_COUNT 6u

// Bits of a tile's class (the --visualize tiles view and the stats): 1 << TILE_LIST_*.

// VkDispatchIndirectCommand: x counts the list's tiles (one workgroup each).
struct TileDispatch {
    uint x;
    uint y;
    uint z;
};

// The classification buffer: the dispatch arguments of every list, then TILE_LIST_COUNT
// lists of tileCount entries (x | y << 16), then one class mask per tile.
struct TileBufferHeader {
    TileDispatch args[TILE_LIST_COUNT];
};

#ifdef __cplusplus
} // namespace shadel::gpu
#endif
#endif
