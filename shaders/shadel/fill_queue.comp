#version 460
// Work queue fill: each marked block gets its storage offset (its counter's section base + its
// place in the counter), publishes it in the offset map, and writes one entry {chunk, storage
// slot, object, MIP} per marked chunk at the queue index equal to that slot.
#include "shadel/shadel.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    uint t = gl_GlobalInvocationID.x;
    if (t >= counters.c.fillDispatch.w) return;
    uvec4 entry = Uvec4Buffer(s.markedBlocks).v[t];
    uint block = entry.x;
    uint counter = entry.w >> 8;
    uint mip = entry.w & 0xFFu;
    uint64_t mask = Uint64Buffer(s.occupancy).v[block];
    uint n = bitCount(uint(mask)) + bitCount(uint(mask >> 32));
    uint base = counters.c.sectionBase[counter] + entry.y;
    ShadelWorkBuffer queue = ShadelWorkBuffer(s.queue);
    bool fits = base + n <= s.capacityChunks;
    if (fits) {
        UintBuffer(s.offsetMap).v[block] = base;
        atomicAdd(counters.c.chunksAllocated, n);
        atomicAdd(counters.c.chunksPerMip[mip], n);
    } else {
        atomicAdd(counters.c.chunksOverflowed, n);
    }
    uvec2 blockXy = uvec2(block % s.sheetBlocks, block / s.sheetBlocks);
    uint k = 0u;
    for (uint bit = 0u; bit < 64u; ++bit) {
        if ((mask & (1ul << bit)) == 0ul) continue;
        uint slot = base + k;
        ++k;
        if (slot >= s.capacityChunks) break;
        uvec2 chunk = blockXy * 8u + uvec2(bit % 8u, bit / 8u);
        GpuShadelWork w;
        w.chunk = chunk.x | (chunk.y << 16);
        w.slot = fits ? slot : SHADEL_INVALID; // a straddling block: skip entries
        w.object = entry.z;
        w.mip = mip;
        queue.w[slot] = w;
    }
}
