#version 460
// Carry-over (preserved layers): copies every layer's shadels of each queued chunk from where
// last frame stored it to where this frame stores it. Lean on purpose, a carried chunk should
// cost a fraction of a shaded one: the storage is chunk-linear (shadel.glsl storageIndex), so
// a chunk row is contiguous in each layer and each thread copies one row as whole uvec4s, the
// packed words as they are (radiance: 8 shadels x 8 bytes = 4 uvec4s; material: 8 x 4 bytes =
// 2 uvec4s); a workgroup copies eight chunks (per-workgroup overhead dominates a copy on CPU
// devices).
#include "shadel/shadel.glsl"
#include "common/dispatch_2d.h"

#define CHUNKS_PER_GROUP 8u
#define RADIANCE_ROW_UVEC4S 4u // SHADEL_CHUNK shadels x uvec2
#define MATERIAL_ROW_UVEC4S 2u // SHADEL_CHUNK shadels x uint
layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrameRef frame = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel);
    ShadelCountersRef counters = ShadelCountersRef(frame.s.counters);
    uint group = dispatch2dGroup();
    uint workIndex = group * CHUNKS_PER_GROUP + gl_LocalInvocationIndex / SHADEL_CHUNK;
    uint row = gl_LocalInvocationIndex % SHADEL_CHUNK;
    if (workIndex >= counters.c.copyCount) return;
    GpuShadelWork work = ShadelWorkBuffer(frame.s.copyQueue).w[workIndex];
    // Rows of a chunk are SHADEL_CHUNK rows of these many uvec4s.
    uint from = work.chunk * SHADEL_CHUNK + row, to = work.slot * SHADEL_CHUNK + row;
    Uvec4Buffer radianceIn = Uvec4Buffer(frame.s.prevLayers[SHADEL_LAYER_RADIANCE]);
    Uvec4Buffer radianceOut = Uvec4Buffer(frame.s.layers[SHADEL_LAYER_RADIANCE]);
    for (uint i = 0u; i < RADIANCE_ROW_UVEC4S; ++i)
        radianceOut.v[to * RADIANCE_ROW_UVEC4S + i] = radianceIn.v[from * RADIANCE_ROW_UVEC4S + i];
    Uvec4Buffer materialIn = Uvec4Buffer(frame.s.prevLayers[SHADEL_LAYER_MATERIAL]);
    Uvec4Buffer materialOut = Uvec4Buffer(frame.s.layers[SHADEL_LAYER_MATERIAL]);
    for (uint i = 0u; i < MATERIAL_ROW_UVEC4S; ++i)
        materialOut.v[to * MATERIAL_ROW_UVEC4S + i] = materialIn.v[from * MATERIAL_ROW_UVEC4S + i];
    if (row == 0u) { // where it was seen from when shaded travels with it
        Uvec4Buffer(frame.s.chunkViews).v[work.slot] = Uvec4Buffer(frame.s.prevChunkViews).v[work.chunk];
        atomicAdd(counters.c.chunksReused, 1u);
    }
}
