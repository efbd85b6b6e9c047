// Which 8x8 tile a workgroup of a screen-space pass works on: the list entry of its index
// (indirect dispatch over a classified list), or its place in the grid (classification off).
#ifndef SHADEL_TILE_LIST_GLSL
#define SHADEL_TILE_LIST_GLSL
#include "common/bindless.glsl"
#include "tiles/tile_types.h"

layout(buffer_reference, scalar) buffer TileBuffer {
    TileBufferHeader header;
    uint entries[]; // TILE_LIST_COUNT lists of tileCount entries, then a class mask per tile
};

uint packTile(uvec2 tile) { return tile.x | (tile.y << 16); }
uvec2 unpackTile(uint packed) { return uvec2(packed & 0xffffu, packed >> 16); }

// Compute stages only (the screen-space helpers are included by fragment shaders too:
// render/stencil; they define SCREEN_SPACE_FRAGMENT).
#ifndef SCREEN_SPACE_FRAGMENT
uvec2 currentTile(uint64_t tiles, uint listOffset) {
    if (listOffset == 0xffffffffu) return gl_WorkGroupID.xy;
    return unpackTile(TileBuffer(tiles).entries[listOffset + gl_WorkGroupID.x]);
}
#endif
#endif
