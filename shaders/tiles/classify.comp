#version 460
// Tile classification (seed 004): one workgroup per 8x8 tile reads the thin G-buffer's pixel
// flags once, merges them with subgroup OR / AND (then across subgroups in shared memory), and
// appends the tile to the list of every permutation it needs; each list's count is the x of its
// indirect dispatch arguments. Later passes run only on their lists.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "screenspace/screen_space.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
// 0: the device lacks subgroup arithmetic in compute; every invocation goes to shared memory.
layout(constant_id = 0) const uint USE_SUBGROUPS = 1u;

shared uint tileOr;
shared uint tileAnd;

void main() {
    if (gl_LocalInvocationIndex == 0u) {
        tileOr = 0u;
        tileAnd = 0xffffffffu;
    }
    barrier();
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    bool inside = p.x < int(pc.width) && p.y < int(pc.height);
    uint flags = inside ? pixelFlagsAt(p) & 15u : 0u;
    uint orBits = flags;
    uint andBits = inside ? flags : 0xffffffffu; // pixels past the edge do not constrain AND
    if (USE_SUBGROUPS != 0u) {
        orBits = subgroupOr(orBits);
        andBits = subgroupAnd(andBits);
        if (subgroupElect()) {
            atomicOr(tileOr, orBits);
            atomicAnd(tileAnd, andBits);
        }
    } else {
        atomicOr(tileOr, orBits);
        atomicAnd(tileAnd, andBits);
    }
    barrier();
    if (gl_LocalInvocationIndex != 0u) return;

    uint anyFlags = tileOr, allFlags = tileAnd;
    uint mask = 0u;
    if ((anyFlags & PIXEL_SURFACE) == 0u) mask |= 1u << TILE_LIST_SKY;
    else {
        mask |= 1u << TILE_LIST_SURFACE;
        if ((allFlags & PIXEL_SURFACE) == 0u) mask |= 1u << TILE_LIST_SKY_EDGE;
        mask |= (anyFlags & PIXEL_SMOOTH) != 0u ? 1u << TILE_LIST_SSR : 1u << TILE_LIST_SSR_CLEAR;
        if ((anyFlags & PIXEL_SKIN) != 0u) mask |= 1u << TILE_LIST_SSS;
    }
    TileBuffer tb = TileBuffer(pc.tiles);
    uvec2 tile = gl_WorkGroupID.xy;
    uint tileCount = gl_NumWorkGroups.x * gl_NumWorkGroups.y;
    for (uint list = 0u; list < TILE_LIST_COUNT; ++list) {
        if ((mask & (1u << list)) == 0u) continue;
        uint index = atomicAdd(tb.header.args[list].x, 1u);
        tb.entries[list * tileCount + index] = packTile(tile);
    }
    tb.entries[TILE_LIST_COUNT * tileCount + tile.y * pc.tilesX + tile.x] = mask;
}
