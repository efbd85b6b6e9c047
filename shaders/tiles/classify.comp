#version 460
// Tile classification: each subgroup classifies one 8x8 tile. Its lanes read the
// thin G-buffer's pixel flags (a lane takes 64 / subgroup size pixels), subgroupOr /
// subgroupAnd merge them, and one lane appends the tile to the list of every permutation it
// needs; each list's count is the x of its indirect dispatch arguments. No shared memory and
// no barrier: on a CPU device a barrier costs more than the whole classification.
// Without subgroup arithmetic (USE_SUBGROUPS 0) each invocation classifies a tile alone.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "screenspace/screen_space.glsl"

layout(local_size_x = 64) in;
layout(constant_id = 0) const uint USE_SUBGROUPS = 1u;

void main() {
    uint tilesY = (pc.height + TILE_SIZE - 1u) / TILE_SIZE;
    uint tileCount = pc.tilesX * tilesY;
    uint tileIndex, lane, lanes;
    if (USE_SUBGROUPS != 0u) {
        tileIndex = gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID;
        lane = gl_SubgroupInvocationID;
        lanes = gl_SubgroupSize;
    } else {
        tileIndex = gl_WorkGroupID.x * 64u + gl_LocalInvocationIndex;
        lane = 0u;
        lanes = 1u;
    }
    if (tileIndex >= tileCount) return; // the whole subgroup: it shares the tile
    uvec2 tile = uvec2(tileIndex % pc.tilesX, tileIndex / pc.tilesX);
    uint anyFlags = 0u, allFlags = 0xffffffffu; // pixels past the screen's edge constrain neither
    for (uint i = lane; i < TILE_SIZE * TILE_SIZE; i += lanes) {
        ivec2 p = ivec2(tile * TILE_SIZE + uvec2(i % TILE_SIZE, i / TILE_SIZE));
        if (p.x >= int(pc.width) || p.y >= int(pc.height)) continue;
        uint flags = pixelFlagsAt(p) & 15u;
        anyFlags |= flags;
        allFlags &= flags;
    }
    if (USE_SUBGROUPS != 0u) {
        anyFlags = subgroupOr(anyFlags);
        allFlags = subgroupAnd(allFlags);
        if (!subgroupElect()) return;
    }

    uint mask = 0u;
    if ((anyFlags & PIXEL_SURFACE) == 0u) mask |= 1u << TILE_LIST_SKY;
    else {
        mask |= 1u << TILE_LIST_SURFACE;
        if ((allFlags & PIXEL_SURFACE) == 0u) mask |= 1u << TILE_LIST_SKY_EDGE;
        mask |= (anyFlags & PIXEL_SMOOTH) != 0u ? 1u << TILE_LIST_SSR : 1u << TILE_LIST_SSR_CLEAR;
        if ((anyFlags & PIXEL_SKIN) != 0u) mask |= 1u << TILE_LIST_SSS;
    }
    TileBuffer tb = TileBuffer(pc.tiles);
    for (uint list = 0u; list < TILE_LIST_COUNT; ++list) {
        if ((mask & (1u << list)) == 0u) continue;
        uint index = atomicAdd(tb.header.args[list].x, 1u);
        tb.entries[list * tileCount + index] = packTile(tile);
    }
    tb.entries[TILE_LIST_COUNT * tileCount + tileIndex] = mask;
}
