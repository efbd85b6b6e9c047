#version 460
// Indirect arguments of the shading and carry-over passes, from the queue lengths the fill
// pass counted. Run again after the near-change pass (near_change.comp), which appends to the
// class lists. 2-D dispatches keep x under every device's maxComputeWorkGroupCount[0]
// (common/dispatch_2d.h).
#include "shadel/shadel.glsl"
#include "common/dispatch_2d.h"

layout(local_size_x = 1) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

uvec4 chunkDispatch(uint n) {
    return uvec4(dispatch2d(n), 1u, n);
}

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    counters.c.shadeDispatch = chunkDispatch(counters.c.shadeCount);
    for (uint c = 0u; c < SHADE_CLASSES; ++c)
        counters.c.classDispatch[c] = chunkDispatch(counters.c.classCount[c]);
    counters.c.invocationDispatch = chunkDispatch((counters.c.shadeCount + 63u) / 64u);
    counters.c.invocationDispatch.w = counters.c.shadeCount;
    counters.c.nearChangeDispatch = chunkDispatch((counters.c.nearChangeCount + 63u) / 64u);
    counters.c.nearChangeDispatch.w = counters.c.nearChangeCount;
    // Carry-over copies 8 chunks per workgroup (carry_over.comp).
    uint copyGroups = (counters.c.copyCount + 7u) / 8u;
    counters.c.copyDispatch = chunkDispatch(copyGroups);
    counters.c.copyDispatch.w = counters.c.copyCount;
}
