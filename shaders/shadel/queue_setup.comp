#version 460
// Work queue setup: lays the hashed counters' sections end to end (their prefix sum is each
// section's first storage slot) and writes the indirect arguments of the fill pass.
#include "shadel/shadel.glsl"

layout(local_size_x = 1) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    uint running = 0u;
    for (uint i = 0u; i < SHADEL_COUNTERS; ++i) {
        counters.c.sectionBase[i] = running;
        running += counters.c.hashed[i];
    }
    uint blocks = min(counters.c.markedBlocks, s.markedCapacity);
    counters.c.fillDispatch = uvec4((blocks + 63u) / 64u, 1u, 1u, blocks);
}
