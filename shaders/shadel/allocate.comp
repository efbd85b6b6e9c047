#version 460
// Allocation: every marked block reserves room for its marked chunks through one of 16 counters
// picked by hashing the block, so the atomics of different blocks rarely meet. This pass only
// records the block's place within its counter; queue setup lays the counters' sections end to end
// and the fill pass turns place + section base into the block's storage offset. Storage is thereby
// shared by all counters: a block overflows only when storage as a whole is full. Overflowed blocks
// are counted and left unallocated; reconstruction then shades those samples forward, so nothing is
// corrupted.
#include "shadel/shadel.glsl"
#include "shadel/rects.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uint t = gl_GlobalInvocationID.x;
    if (t >= s.rectBlockCount) return;
    GpuShadelRect rect;
    uint rectIndex;
    uint block = rectBlock(s, t, rect, rectIndex);
    uint64_t mask = Uint64Buffer(s.occupancy).v[block];
    if (mask == 0ul) return;
    // Level windows: the level block this is, into the rect's wanted box (read back).
    uvec2 inRect = uvec2(block % s.sheetBlocks, block / s.sheetBlocks) - rect.rect.xy;
    uvec2 levelBlock = inRect + windowOrigin(shadelObject(s, rect.object), rect.mip) / SHADEL_BLOCK;
    Uvec4Buffer wants = Uvec4Buffer(s.levelWants);
    atomicMax(wants.v[rectIndex].x, 0xFFFFu - levelBlock.x);
    atomicMax(wants.v[rectIndex].y, 0xFFFFu - levelBlock.y);
    atomicMax(wants.v[rectIndex].z, levelBlock.x + 1u);
    atomicMax(wants.v[rectIndex].w, levelBlock.y + 1u);
    uint n = bitCount(uint(mask)) + bitCount(uint(mask >> 32));
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    atomicAdd(counters.c.chunksRequested, n);
    uint listIndex = atomicAdd(counters.c.markedBlocks, 1u);
    // Every listed block needs >= 1 chunk, so a list as long as storage has chunks can only
    // run out when storage has too.
    if (listIndex >= s.markedCapacity) {
        atomicAdd(counters.c.chunksOverflowed, n);
        return;
    }
    uint counter = ((block * 2654435761u) >> 7) % s.allocationCounters;
    uint place = atomicAdd(counters.c.hashed[counter], n);
    Uvec4Buffer(s.markedBlocks).v[listIndex] = uvec4(block, place, rect.object, rect.mip | (counter << 8));
}
