#version 460
// Work queue fill: each marked block writes one entry {chunk, storage slot, object, MIP} per
// marked chunk into its object's segment of the queue.
#include "shadel/shadel.glsl"

layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    uint t = gl_GlobalInvocationID.x;
    if (t >= counters.c.markedBlocks) return;
    uvec4 entry = Uvec4Buffer(s.markedBlocks).v[t];
    if (entry.x == SHADEL_INVALID) return;
    uint block = entry.x;
    uint64_t mask = Uint64Buffer(s.occupancy).v[block];
    uint base = UintBuffer(s.offsetMap).v[block];
    uint queueIndex = Uvec4Buffer(s.objectDispatch).v[entry.z].w + entry.y;
    uvec2 blockXy = uvec2(block % s.sheetBlocks, block / s.sheetBlocks);
    uint k = 0u;
    ShadelWorkBuffer queue = ShadelWorkBuffer(s.queue);
    for (uint bit = 0u; bit < 64u; ++bit) {
        if ((mask & (1ul << bit)) == 0ul) continue;
        uvec2 chunk = blockXy * 8u + uvec2(bit % 8u, bit / 8u);
        GpuShadelWork w;
        w.chunk = chunk.x | (chunk.y << 16);
        w.slot = base + k;
        w.object = entry.z;
        w.mip = entry.w;
        SHADEL_ASSERT(f, w.slot < s.capacityChunks, ASSERT_SHADEL_SLOT, w.slot, s.capacityChunks);
        queue.w[queueIndex + k] = w;
        ++k;
    }
}
