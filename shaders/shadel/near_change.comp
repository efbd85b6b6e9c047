#version 460
// Near-change carry-over (preserved layers, --reuse, without spectra): the chunks that could be
// carried over but lie on an object a changed region meets (a light or a caster that changed:
// render/shadel/reuse_invalidation.h), listed by fill_queue.comp, which cannot tell which of
// their shadels the change reaches. One invocation per chunk rebuilds the positions its shadels
// are lit at: none in a changed region, it is carried over (as carry_over.comp, one invocation
// for the chunk); else it goes to its shading class's list. The spectra's classify takes the
// same decision for its queue (lighting/chunk_classify.comp).
// The check is a pass of its own rather than part of the shading: sharing its answer across a
// chunk's workgroup would need a barrier, and a barrier makes every shading pipeline run as
// coroutines on lavapipe, near change or not.
#include "shadel/shade_chunk.glsl"
#include "common/dispatch_2d.h"
#include "materials/program_types.h"

layout(local_size_x = 64) in;
// As fill_queue.comp's: the material program lists (0: none loaded).
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t programHeader;
    uint64_t programQueues;
} pc;

void main() {
    FrameConstants f = FrameConstantsRef(pc.frame).f;
    ShadelFrame s = ShadelFrameRef(f.shadel).s;
    ShadelCountersRef counters = ShadelCountersRef(s.counters);
    uint index = dispatch2dGroup() * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
    if (index >= counters.c.nearChangeDispatch.w) return;
    uint queued = UintBuffer(s.classQueues).v[SHADE_NEAR_CHANGE_LIST * s.capacityChunks + index];
    GpuShadelWork work = ShadelWorkBuffer(s.queue).w[queued];
    ShadelObjectRef o = shadelObject(s, work.object);
    // The fill pass found where last frame stored it; the same function says where.
    int carrySlot = carrySource(s, o, work, f.cameraPosition);
    if (carrySlot >= 0 && !chunkTouchesChangedRegion(f, s, work)) {
        for (uint row = 0u; row < SHADEL_CHUNK; ++row)
            carryChunkRow(s, uint(carrySlot), work.slot, row);
        carryChunkRecord(s, uint(carrySlot), work.slot);
        return;
    }
    if (appendToProgramList(pc.programHeader, pc.programQueues, s.capacityChunks, o.v.flags, queued))
        return;
    uint shadeClass = shadeClassOf(o);
    uint place = atomicAdd(counters.c.classCount[shadeClass], 1u);
    UintBuffer(s.classQueues).v[shadeClass * s.capacityChunks + place] = queued;
}
