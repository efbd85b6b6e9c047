#version 460
// Work queue setup: lays the hashed counters' sections end to end (their prefix sum is each
// section's first storage slot) and writes the indirect arguments of the fill and shading
// passes. The queue is indexed by storage slot, so it needs no per-object segments: one
// dispatch shades every allocated chunk.
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
    // Slots at or past capacity are never written; a block straddling the end writes skip
    // entries for its slots below it, so every queue entry below `total` is written once.
    uint total = min(running, s.capacityChunks);
    // 2-D dispatch: x stays under every device's maxComputeWorkGroupCount[0].
    uint x = min(total, 32768u);
    counters.c.shadeDispatch = uvec4(x, total == 0u ? 0u : (total + 32767u) / 32768u, 1u, total);
    uint blocks = min(counters.c.markedBlocks, s.markedCapacity);
    counters.c.fillDispatch = uvec4((blocks + 63u) / 64u, 1u, 1u, blocks);
}
