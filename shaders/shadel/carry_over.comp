#version 460
// Carry-over (preserved layers): copies every layer's shadels of each queued chunk from where
// last frame stored it to where this frame stores it. Lean on purpose, a carried chunk should
// cost a fraction of a shaded one: the storage is chunk-linear (shadel.glsl storageIndex), so
// a chunk row is contiguous in each layer and each thread copies one row as whole uvec4s, the
// packed words as they are (carryChunkRow); a workgroup copies eight chunks (per-workgroup
// overhead dominates a copy on CPU devices).
#include "shadel/shadel.glsl"
#include "common/dispatch_2d.h"

#define CHUNKS_PER_GROUP 8u
layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrame s = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel).s;
    uint group = dispatch2dGroup();
    uint workIndex = group * CHUNKS_PER_GROUP + gl_LocalInvocationIndex / SHADEL_CHUNK;
    uint row = gl_LocalInvocationIndex % SHADEL_CHUNK;
    if (workIndex >= ShadelCountersRef(s.counters).c.copyCount) return;
    GpuShadelWork work = ShadelWorkBuffer(s.copyQueue).w[workIndex]; // chunk = last frame's slot
    carryChunkRow(s, work.chunk, work.slot, row);
    if (row == 0u) carryChunkRecord(s, work.chunk, work.slot);
}
