#version 460
// Allocation (seed: "Allocation Pass/Collection"): every marked block takes storage for its
// marked chunks from one of 16 counters picked by hashing the block, so the atomics of
// different blocks rarely meet. Blocks that do not fit are counted and left unallocated;
// reconstruction then shades those samples forward, so nothing is corrupted.
#include "shadel/shadel.glsl"
#include "shadel/rects.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uint t = gl_GlobalInvocationID.x;
    if (t >= s.rectBlockCount) return;
    GpuShadelRect rect;
    uint block = rectBlock(s, t, rect);
    uint64_t mask = Uint64Buffer(s.occupancy).v[block];
    if (mask == 0ul) return;
    uint n = bitCount(uint(mask)) + bitCount(uint(mask >> 32));
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    atomicAdd(counters.c.chunksRequested, n);
    uint counter = (block * 2654435761u >> 7) % SHADEL_COUNTERS;
    uint base = atomicAdd(counters.c.hashed[counter], n);
    uint listIndex = atomicAdd(counters.c.markedBlocks, 1u);
    Uvec4Buffer list = Uvec4Buffer(s.markedBlocks);
    if (base + n > s.chunksPerCounter) {
        atomicAdd(counters.c.chunksOverflowed, n);
        list.v[listIndex] = uvec4(SHADEL_INVALID);
        return;
    }
    atomicAdd(counters.c.chunksAllocated, n);
    UintBuffer(s.offsetMap).v[block] = counter * s.chunksPerCounter + base;
    uint objectLocal = atomicAdd(UintBuffer(s.objectChunks).v[rect.object], n);
    list.v[listIndex] = uvec4(block, objectLocal, rect.object, rect.mip);
}
