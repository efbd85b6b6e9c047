#version 460
// Work queue fill: each marked block gets its storage offset (its counter's section base + its
// place in the counter) and publishes it in the offset map. Each of its marked chunks then goes
// to one of two queues: carried over from last frame's storage (preserved layers: the object's
// level is unchanged, last frame stored the chunk, it is not the chunk's turn to be refreshed,
// and the view did not turn past what its specular tolerates) or shaded, in the list of its
// shading class (the pipeline that shades it, shade.comp). Chunks that could be carried over but
// lie on an object a changed region meets (a light or a caster that changed) go to the
// near-change list, whose pass checks their shadels against the regions and carries them over
// or appends them to their class's list (near_change.comp). With ray-traced
// terms, a chunk is also reshaded when the RT cache under it gained a factor of sqrt 2 in rays
// (raytracing/rt_history.glsl).
#include "shadel/shadel.glsl"
#include "raytracing/rt_history.glsl"
#include "materials/program_types.h"

layout(local_size_x = 64) in;
// programHeader, programQueues: the material program lists (0: none loaded).
layout(push_constant, scalar) uniform Push {
    uint64_t frame;
    uint64_t programHeader;
    uint64_t programQueues;
} pc;

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
    if (base + n > s.capacityChunks) { // storage is full: counted, never written
        atomicAdd(counters.c.chunksOverflowed, n);
        return;
    }
    UintBuffer(s.offsetMap).v[block] = base;
    atomicAdd(counters.c.chunksAllocated, n);
    atomicAdd(counters.c.chunksPerMip[mip], n);

    ShadelObjectRef o = shadelObject(s, entry.z);
    bool levelReusable = s.reuse != 0u && ((o.v.reuseLevels >> mip) & 1u) != 0u;
    bool nearChange = (o.v.flags & SHADEL_OBJECT_NEAR_CHANGE) != 0u;
    uint prevBlock = levelReusable ? prevBlockIndex(s, o, mip, block) : SHADEL_INVALID;
    uint64_t prevMask = prevBlock != SHADEL_INVALID ? Uint64Buffer(s.prevOccupancy).v[prevBlock] : 0ul;
    uint prevBase = prevBlock != SHADEL_INVALID ? UintBuffer(s.prevOffsetMap).v[prevBlock] : SHADEL_INVALID;
    uvec2 blockXy = uvec2(block % s.sheetBlocks, block / s.sheetBlocks);
    uint k = 0u;
    uint shadedBecause[SHADEL_SHADED_REASONS]; // summed here: one atomic per reason and block
    for (uint reason = 0u; reason < SHADEL_SHADED_REASONS; ++reason) shadedBecause[reason] = 0u;
    for (uint bit = 0u; bit < 64u; ++bit) {
        if ((mask & (1ul << bit)) == 0ul) continue;
        uvec2 chunk = blockXy * 8u + uvec2(bit % 8u, bit / 8u);
        GpuShadelWork w;
        w.chunk = chunk.x | (chunk.y << 16);
        w.slot = base + k;
        w.object = entry.z;
        w.mip = mip;
        ++k;
        bool stored = (prevMask & (1ul << bit)) != 0ul && prevBase != SHADEL_INVALID;
        uint prevSlot = stored ? chunkSlot(prevMask, prevBase, bit) : SHADEL_INVALID;
        bool refresh = stored && shadelRefreshDue(s, w.chunk);
        bool viewTurned = stored && !refresh && chunkViewTurned(s, o, prevSlot, f.cameraPosition);
        bool rtHistory = false;
        if (stored && !refresh && !viewTurned && f.rt != 0ul) {
            uvec2 size = levelSize(o, mip);
            vec2 uvs[4];
            for (int q = 0; q < 4; ++q) { // the centres of the chunk's four quarters
                uvec2 quarter = uvec2(2 + 4 * (q & 1), 2 + 4 * (q >> 1));
                uvs[q] = vec2(levelShadel(o, mip, chunk * SHADEL_CHUNK + quarter)) / vec2(size);
            }
            rtHistory = rtHistoryStepped(f, entry.z, uvs, w.chunk);
        }
        bool carryable = stored && !refresh && !viewTurned && !rtHistory &&
                         (o.v.flags & SHADEL_OBJECT_PROGRAM_EVERY_FRAME) == 0u;
        if (carryable && !nearChange) {
            w.chunk = prevSlot; // where last frame stored it
            ShadelWorkBuffer(s.copyQueue).w[atomicAdd(counters.c.copyCount, 1u)] = w;
            continue;
        }
        uint queued = atomicAdd(counters.c.shadeCount, 1u);
        ShadelWorkBuffer(s.queue).w[queued] = w;
        // A material program's chunk goes to its program's list (materials/program_types.h).
        if (carryable || !appendToProgramList(pc.programHeader, pc.programQueues,
                                              s.capacityChunks, o.v.flags, queued)) {
            uint list = carryable ? SHADE_NEAR_CHANGE_LIST : shadeClassOf(o);
            uint place = carryable ? atomicAdd(counters.c.nearChangeCount, 1u)
                                   : atomicAdd(counters.c.classCount[list], 1u);
            UintBuffer(s.classQueues).v[list * s.capacityChunks + place] = queued;
        }
        uint reason = !levelReusable ? SHADEL_SHADED_NOT_REUSABLE
                      : nearChange   ? SHADEL_SHADED_NEAR_CHANGE
                      : refresh      ? SHADEL_SHADED_REFRESH
                      : viewTurned   ? SHADEL_SHADED_VIEW
                      : rtHistory    ? SHADEL_SHADED_RT_HISTORY
                                     : SHADEL_SHADED_NEW;
        shadedBecause[reason]++;
        // (a near-change chunk's carry-over, if its check allows it, writes over this)
        if (s.chunkReasons != 0ul) UintBuffer(s.chunkReasons).v[w.slot] = reason;
    }
    for (uint reason = 0u; reason < SHADEL_SHADED_REASONS; ++reason)
        if (shadedBecause[reason] != 0u) atomicAdd(counters.c.shadedBecause[reason], shadedBecause[reason]);
}
