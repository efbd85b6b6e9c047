#version 460
// Carry-over (preserved layers): copies every layer's shadels of each queued chunk from where
// last frame stored it to where this frame stores it. Lean on purpose, a carried chunk should
// cost a fraction of a shaded one: each thread copies one 8-shadel row, a workgroup copies
// eight chunks (per-workgroup overhead dominates a copy on CPU devices).
#include "shadel/shadel.glsl"

#define CHUNKS_PER_GROUP 8u
layout(local_size_x = 64) in;
layout(push_constant, scalar) uniform Push { uint64_t frame; } pc;

void main() {
    ShadelFrameRef frame = ShadelFrameRef(FrameConstantsRef(pc.frame).f.shadel);
    ShadelCountersRef counters = ShadelCountersRef(frame.s.counters);
    uint group = gl_WorkGroupID.y * 32768u + gl_WorkGroupID.x;
    uint workIndex = group * CHUNKS_PER_GROUP + gl_LocalInvocationIndex / SHADEL_CHUNK;
    uint row = gl_LocalInvocationIndex % SHADEL_CHUNK;
    if (workIndex >= counters.c.copyCount) return;
    GpuShadelWork work = ShadelWorkBuffer(frame.s.copyQueue).w[workIndex];
    uint chunksPerRow = frame.s.storageChunksPerRow;
    ivec2 from = ivec2(uvec2(work.chunk % chunksPerRow, work.chunk / chunksPerRow) * SHADEL_CHUNK) + ivec2(0, row);
    ivec2 to = ivec2(uvec2(work.slot % chunksPerRow, work.slot / chunksPerRow) * SHADEL_CHUNK) + ivec2(0, row);
    uint radianceIn = frame.s.prevLayerReadSlot[SHADEL_LAYER_RADIANCE];
    uint materialIn = frame.s.prevLayerReadSlot[SHADEL_LAYER_MATERIAL];
    uint radianceOut = frame.s.layerWriteSlot[SHADEL_LAYER_RADIANCE];
    uint materialOut = frame.s.layerWriteSlot[SHADEL_LAYER_MATERIAL];
    for (int x = 0; x < int(SHADEL_CHUNK); ++x) {
        imageStore(gImagesRgba16f[radianceOut], to + ivec2(x, 0),
                   fetchTextureUniform(radianceIn, from + ivec2(x, 0), 0));
        imageStore(gImagesRgba8[materialOut], to + ivec2(x, 0),
                   fetchTextureUniform(materialIn, from + ivec2(x, 0), 0));
    }
    if (row == 0u) { // where it was seen from when shaded travels with it
        Uvec4Buffer(frame.s.chunkViews).v[work.slot] = Uvec4Buffer(frame.s.prevChunkViews).v[work.chunk];
        atomicAdd(counters.c.chunksReused, 1u);
    }
}
